//! PROFINET AR sequences (issue 39): the input is a list of operations, each
//! encoded as a controller sends it (`pn_enc.rs`), so that the fuzzer gets
//! past the RPC and CM parsers into the AR state machine, the records and
//! the RT and alarm paths: Connect (AR, IOCR, AlarmCR and ExpectedSubmodule
//! blocks with counts, lengths, RTClass, startup mode, data lengths, slots
//! and subslots around the GSDML's) from this controller or a second one,
//! Write (single and multiple: I&M, PDev, 0xB02E, PROFIenergy, any index,
//! lengths up to and past 4,068 bytes, in RPC fragments), Read (explicit
//! and implicit), Control (PrmEnd, Release), the confirmation of the
//! device's ApplicationReady, cyclic frames with any IOPS/IOCS/DataStatus,
//! alarm acknowledgements, time, link down/up, DCP Set, a diagnosis the
//! application raises or clears. After encoding, an operation may carry one
//! byte change at a position the input chooses.
//!
//! Oracles (besides `pn_check.rs` on every frame the device sends): a
//! success means the effect happened (Connect: the AR is there; PrmEnd: it
//! waits for ApplicationReady; Release: it is gone; an I&M write reads back
//! as written), a refusal means nothing changed (the AR, I&M, the PDev and
//! the records behind the hooks as before); never two IO ARs and never an
//! AR of a second controller while the first one's is up.
#![no_main]

#[path = "pn_check.rs"]
mod check;
#[path = "pn_common.rs"]
mod common;
#[path = "pn_enc.rs"]
mod enc;

use check::Seen;
use drive_pn::bmp_record::WithBmp;
use enc::{Rec, W};
use libfuzzer_sys::arbitrary::Unstructured;
use libfuzzer_sys::fuzz_target;
use nanos::Nanos;
use profinet::cm::{ArState, CmEvent, PnioStatus};
use profinet::device::{Device, DeviceEvent};
use profinet::profienergy::{ProfiEnergy, WithProfiEnergy};
use profinet::rpc::Uuid;
use profinet::testing::{self, udp_to_device};

type Hook = WithBmp<common::Hook>;

/// Operations per input at most.
const OPS: usize = 24;

/// AR UUIDs the operations use (two, so a Connect can supersede one).
const AR_UUIDS: [Uuid; 2] = [Uuid([0x10; 16]), Uuid([0x20; 16])];
const ACTIVITY: Uuid = Uuid([0xA0; 16]);
const ACTIVITY_OTHER: Uuid = Uuid([0xB0; 16]);

/// Records the writes and reads address: I&M, PDev, the CM's, 0xB02E,
/// PROFIenergy, and (one time in eight) any index.
const INDICES: [u16; 12] = [
    0xAFF0, 0xAFF1, 0xAFF2, 0xAFF3, 0xAFF4, 0x802A, 0x802F, 0x8080, 0xE002, 0xE040, 0xB02E, 0x80A0,
];
const ADDRS: [(u16, u16); 6] = [(0, 1), (0, 0x8000), (0, 0x8001), (0, 0x8002), (1, 1), (2, 1)];

fn device() -> Device<Hook> {
    let hook = WithBmp {
        bmp: Default::default(),
        inner: WithProfiEnergy {
            pe: ProfiEnergy::default(),
            app: common::Energy,
            inner: profinet::cm::NoRecords,
        },
    };
    Device::new(testing::device_config(), hook)
}

/// What may change only through a write: I&M, the PDev (without its frame
/// counters, which every frame moves), the hooks' records.
fn records(d: &Device<Hook>) -> String {
    let mut pdev = d.cm().pdev().clone();
    pdev.stats = Default::default();
    format!("{:?} {:?} {:?}", d.cm().im_data(), pdev, d.hook())
}

fn ar_view(d: &Device<Hook>) -> Option<(Uuid, [u8; 6], ArState)> {
    d.cm().ar().map(|a| (a.ar_uuid, a.controller_mac.0, a.state))
}

struct Pn {
    d: Device<Hook>,
    now: Nanos,
    seq: u32,
    rw_seq: u16,
    seen: Seen,
    /// The AR and the records right after the last frames were received.
    after_rx: (Option<(Uuid, [u8; 6], ArState)>, String),
    /// Whether the next step keeps the records in `after_rx` (writes only: it costs).
    snap: bool,
}

impl Pn {
    /// Feeds `frames` (and a poll), checking every frame the device sends.
    fn feed(&mut self, frames: &[Vec<u8>], args_max: u32, connecting: bool) {
        let alive_before = self.d.cm().ar().is_some() || self.d.cm().supervisor_ar().is_some();
        let mut out: Vec<Vec<u8>> = Vec::new();
        for f in frames {
            self.d.receive(self.now, f, &mut |b: &[u8]| out.push(b.to_vec()));
        }
        // the effects of what was received, before the timers run (a
        // watchdog may end the AR in the poll below)
        let recs = if self.snap {
            records(&self.d)
        } else {
            String::new()
        };
        self.after_rx = (ar_view(&self.d), recs);
        self.d.poll(self.now, &mut |b: &[u8]| out.push(b.to_vec()));
        let alive = alive_before || connecting || self.d.cm().ar().is_some();
        let alarm_max = self
            .d
            .cm()
            .ar()
            .and_then(|a| a.alarm_cr)
            .map(|a| a.max_alarm_data_length);
        for f in &out {
            check::frame(&mut self.seen, f, alive, ACTIVITY, args_max, alarm_max);
        }
    }

    /// One RPC call of ours: its answer (if one came in this step).
    fn call(
        &mut self,
        u: &mut Unstructured<'_>,
        opnum: u16,
        args: &[u8],
        args_max: u32,
        other: bool,
    ) -> Option<check::Answer> {
        let little = u.ratio(1, 8).unwrap_or(false);
        let nofack = u.ratio(1, 2).unwrap_or(true);
        self.seq = self.seq.wrapping_add(1);
        let act = if other { ACTIVITY_OTHER } else { ACTIVITY };
        let dgs = enc::rpc_request(
            act,
            self.seq,
            opnum,
            &enc::ndr(args_max, args, little),
            little,
            nofack,
        );
        let mut frames: Vec<Vec<u8>> = dgs.iter().map(|d| udp_to_device(d).to_vec()).collect();
        if other {
            frames = frames.into_iter().map(enc::from_other).collect();
        }
        mutate(u, &mut frames, 42);
        self.seen.answers.clear();
        self.feed(&frames, args_max, opnum == 0);
        let seq = self.seq;
        self.seen.answers.iter().find(|a| a.seq == seq).cloned()
    }

    /// The CM events of the last step (the effects of what was answered, and
    /// aborts by the watchdog or alarm channel in the same step).
    fn cm_events(&mut self) -> Vec<CmEvent> {
        let mut v = Vec::new();
        while let Some(e) = self.d.take_event() {
            if let DeviceEvent::Cm(c) = e {
                v.push(c);
            }
        }
        v
    }

    fn ar_uuid(&self, u: &mut Unstructured<'_>) -> (Uuid, u16) {
        let cur = self.d.cm().ar().map(|a| (a.ar_uuid, a.session_key));
        match (u.arbitrary::<u8>().unwrap_or(0) % 8, cur) {
            (0, _) | (_, None) => (
                AR_UUIDS[usize::from(u.arbitrary::<u8>().unwrap_or(0) & 1)],
                u.arbitrary().unwrap_or(0),
            ),
            (1, Some((a, _))) => (a, u.arbitrary().unwrap_or(0)),
            (_, Some(c)) => c,
        }
    }

    fn rec(u: &mut Unstructured<'_>) -> Rec {
        let sel: u8 = u.arbitrary().unwrap_or(0);
        let (slot, subslot) = if sel & 0xE0 == 0 {
            (u.arbitrary().unwrap_or(0), u.arbitrary().unwrap_or(0))
        } else {
            ADDRS[usize::from(sel >> 5) % ADDRS.len()]
        };
        let index = if sel & 0x1F == 0x1F {
            u.arbitrary().unwrap_or(0)
        } else {
            INDICES[usize::from(sel & 0x1F) % INDICES.len()]
        };
        Rec { slot, subslot, index }
    }

    /// Record data for `r`: a well-formed I&M block (fields from the input),
    /// or any bytes of a length up to and past 4,068.
    fn data(u: &mut Unstructured<'_>, r: Rec) -> (Vec<u8>, Option<Vec<u8>>) {
        let im = match r.index {
            0xAFF1 => Some((0x21u16, 54usize)),
            0xAFF2 => Some((0x22, 16)),
            0xAFF3 => Some((0x23, 54)),
            0xAFF4 => Some((0x24, 54)),
            _ => None,
        };
        let sel: u8 = u.arbitrary().unwrap_or(0);
        if let (Some((t, n)), true) = (im, sel % 8 != 0) {
            let fields: Vec<u8> = (0..n).map(|_| u.arbitrary::<u8>().unwrap_or(b' ')).collect();
            let mut w = W::default();
            w.block(t, &fields);
            return (w.0, Some(fields));
        }
        let len = match sel % 8 {
            0 => 4068,
            1 => 4069,
            2 => u.int_in_range(1400..=4200).unwrap_or(0),
            _ => u.int_in_range(0..=64).unwrap_or(0),
        };
        let mut v: Vec<u8> = (0..len.min(u.len()))
            .map(|_| u.arbitrary::<u8>().unwrap_or(0))
            .collect();
        v.resize(len, 0);
        (v, None)
    }

    /// Reads `r` back implicitly: the record's bytes, or the refusal.
    fn read_back(&mut self, r: Rec) -> Result<Vec<u8>, PnioStatus> {
        self.seq = self.seq.wrapping_add(1);
        let args = enc::read_header(0, Uuid::NIL, r, 4096);
        let dgs = enc::rpc_request(ACTIVITY, self.seq, 5, &enc::ndr(4096, &args, false), false, true);
        let frames: Vec<Vec<u8>> = dgs.iter().map(|d| udp_to_device(d).to_vec()).collect();
        self.seen.answers.clear();
        self.feed(&frames, 4096, false);
        let seq = self.seq;
        let a = self
            .seen
            .answers
            .iter()
            .find(|a| a.seq == seq)
            .cloned()
            .expect("an implicit read is answered");
        match a.status {
            Some(s) if s.is_ok() => Ok(a.args[64..].to_vec()),
            Some(s) => Err(s),
            None => Err(PnioStatus::from_u32(1)),
        }
    }

    fn op(&mut self, u: &mut Unstructured<'_>) {
        let kind: u8 = u.arbitrary().unwrap_or(0);
        match kind % 16 {
            // Connect from us, or from a second controller
            0 | 1 | 2 => {
                let other = kind % 16 == 2;
                let ctrl = if other {
                    enc::OTHER_MAC
                } else {
                    testing::CONTROLLER_MAC.0
                };
                let (id, _) = self.ar_uuid(u);
                let (args, req) = enc::connect(u, ctrl, id);
                let before = ar_view(&self.d);
                let answer = self.call(u, 0, &args, 4096, other);
                let after = self.after_rx.0;
                let events = self.cm_events();
                if let (Some(b), Some(a)) = (before, after) {
                    assert!(
                        b.1 == a.1 || b.0 == a.0,
                        "an AR of another controller replaced the established one"
                    );
                }
                match answer.and_then(|a| a.status) {
                    Some(s) if s.is_ok() => assert!(
                        events.contains(&CmEvent::Connected(req.ar_uuid)),
                        "an accepted Connect without its AR: {events:?}"
                    ),
                    Some(_) => assert_eq!(before, after, "a refused Connect changed the AR"),
                    _ => {}
                }
            }
            // Write, single
            3 | 4 => {
                let (ar, _) = self.ar_uuid(u);
                let r = Self::rec(u);
                let (data, im) = Self::data(u, r);
                let mut w = W::default();
                self.rw_seq = self.rw_seq.wrapping_add(1);
                let declared = if u.ratio(1, 16).unwrap_or(false) {
                    u.arbitrary().unwrap_or(0)
                } else {
                    data.len() as u32
                };
                enc::write_header(&mut w, self.rw_seq, ar, r, declared);
                w.bytes(&data);
                let before = records(&self.d);
                self.snap = true;
                let answer = self.call(u, 3, &w.0, 4096, false);
                self.snap = false;
                let mutated = was_mutated();
                match answer.as_ref().and_then(|a| a.status) {
                    Some(s) if s.is_ok() => {
                        if let (Some(fields), false) = (im, mutated) {
                            let back = self.read_back(r).expect("a written I&M record reads back");
                            assert_eq!(
                                &back[back.len() - fields.len()..],
                                &fields[..],
                                "I&M read back differs from what was written"
                            );
                        }
                    }
                    _ => assert_eq!(before, self.after_rx.1, "a refused write changed a record"),
                }
            }
            // Write multiple: two to four sub-writes
            5 => {
                let (ar, _) = self.ar_uuid(u);
                let n = 2 + u.arbitrary::<u8>().unwrap_or(0) % 3;
                let mut body = W::default();
                for _ in 0..n {
                    let r = Self::rec(u);
                    let (mut data, _) = Self::data(u, r);
                    data.truncate(300);
                    self.rw_seq = self.rw_seq.wrapping_add(1);
                    enc::write_header(&mut body, self.rw_seq, ar, r, data.len() as u32);
                    body.bytes(&data);
                    while body.0.len() % 4 != 0 {
                        body.u8(0);
                    }
                }
                let mut w = W::default();
                self.rw_seq = self.rw_seq.wrapping_add(1);
                enc::write_header(
                    &mut w,
                    self.rw_seq,
                    ar,
                    Rec {
                        slot: 0,
                        subslot: 0,
                        index: 0xE040,
                    },
                    body.0.len() as u32,
                );
                w.bytes(&body.0);
                let before = records(&self.d);
                self.snap = true;
                let answer = self.call(u, 3, &w.0, 4096, false);
                self.snap = false;
                // refused as a whole, or every sub-write refused: nothing
                // changed (a sub-write's refusal makes the outer status an
                // error while the good ones stay done: look at each)
                let any_ok = answer.as_ref().is_some_and(|a| {
                    let mut b = profinet::cm::ndr::Blocks::new(&a.args);
                    let mut ok = false;
                    let mut first = true;
                    while let Some(Ok(blk)) = b.next_block() {
                        if !first && blk.body.len() >= 42 && blk.body[38..42] == [0, 0, 0, 0] {
                            ok = true;
                        }
                        first = false;
                    }
                    ok
                });
                if !any_ok {
                    assert_eq!(
                        before, self.after_rx.1,
                        "a refused multiple write changed a record"
                    );
                }
            }
            // Read, explicit or implicit, any length and ArgsMaximum
            6 | 7 => {
                let implicit = kind % 16 == 7;
                let (ar, _) = if implicit { (Uuid::NIL, 0) } else { self.ar_uuid(u) };
                let r = Self::rec(u);
                let len = enc::around(u, 0, 4200, 4);
                let max = enc::around(u, 64, 4200, 4);
                self.rw_seq = self.rw_seq.wrapping_add(1);
                let args = enc::read_header(self.rw_seq, ar, r, len);
                let _ = self.call(u, if implicit { 5 } else { 2 }, &args, max, false);
            }
            // Control: PrmEnd
            8 => {
                let (ar, key) = self.ar_uuid(u);
                let cmd = if u.ratio(1, 16).unwrap_or(false) {
                    u.arbitrary().unwrap_or(0)
                } else {
                    enc::PRM_END
                };
                let props = if u.ratio(1, 16).unwrap_or(false) { 1 } else { 0 };
                let before = ar_view(&self.d);
                let answer = self.call(u, 4, &enc::prm_end(ar, key, cmd, props), 4096, false);
                let events = self.cm_events();
                match answer.and_then(|a| a.status) {
                    Some(s) if s.is_ok() => {
                        assert!(
                            events.contains(&CmEvent::PrmEnd(ar)),
                            "PrmEnd accepted without its effect: {events:?}"
                        );
                        let st = self.after_rx.0.map(|a| a.2);
                        assert!(
                            matches!(st, Some(ArState::ApplicationReadyPending | ArState::Data)),
                            "PrmEnd accepted, AR state {st:?}, events {events:?}"
                        );
                    }
                    Some(_) => assert_eq!(before, self.after_rx.0, "a refused PrmEnd changed the AR"),
                    _ => {}
                }
            }
            // the controller's answer to the device's ApplicationReady
            9 => {
                let Some(h) = self.seen.app_ready.take() else {
                    return;
                };
                let (ar, key) = self.ar_uuid(u);
                let sel: u8 = u.arbitrary().unwrap_or(0);
                let status: u32 = if sel % 8 == 0 {
                    u.arbitrary().unwrap_or(0)
                } else {
                    0
                };
                let cmd = if sel % 16 == 1 { 0 } else { enc::DONE };
                let args = enc::app_ready_res(ar, key, cmd);
                let mut body = W::default();
                body.u32(status)
                    .u32(args.len() as u32)
                    .u32(args.len() as u32)
                    .u32(0)
                    .u32(args.len() as u32)
                    .bytes(&args);
                let mut frames = vec![udp_to_device(&enc::rpc_response(&h, &body.0)).to_vec()];
                mutate(u, &mut frames, 42);
                self.feed(&frames, 4096, false);
            }
            // Release
            10 => {
                let (ar, key) = self.ar_uuid(u);
                let cmd = if u.ratio(1, 16).unwrap_or(false) {
                    u.arbitrary().unwrap_or(0)
                } else {
                    enc::RELEASE
                };
                let before = ar_view(&self.d);
                let answer = self.call(u, 1, &enc::release(ar, key, cmd), 4096, false);
                let events = self.cm_events();
                match answer.and_then(|a| a.status) {
                    Some(s) if s.is_ok() => {
                        assert!(
                            events.contains(&CmEvent::Released(ar)),
                            "a Release answered with success: {events:?}"
                        );
                        assert!(
                            self.after_rx.0.is_none_or(|a| a.0 != ar),
                            "a Release answered with success left its AR"
                        );
                    }
                    Some(_) => assert_eq!(before, self.after_rx.0, "a refused Release changed the AR"),
                    _ => {}
                }
            }
            // a cyclic frame for the output CR: any IOPS/IOCS/DataStatus
            11 => {
                let Some(ar) = self.d.cm().ar().cloned() else {
                    return;
                };
                let Some(cr) = ar.output_cr.as_ref() else { return };
                let counter: u16 = u.arbitrary().unwrap_or(0);
                let fill: u8 = u.arbitrary().unwrap_or(0);
                let mut f = testing::output_frame(&ar, counter, fill).to_vec();
                let n = f.len();
                if n >= 4 {
                    let ds: u8 = if u.ratio(1, 2).unwrap_or(true) {
                        0x35
                    } else {
                        u.arbitrary().unwrap_or(0)
                    };
                    f[n - 2] = ds;
                    if u.ratio(1, 4).unwrap_or(false) {
                        // IOPS/IOCS bad or any
                        for o in cr.data.iter().chain(cr.iocs.iter()) {
                            let at = 16 + usize::from(o.frame_offset) + usize::from(o.data_len);
                            if let Some(b) = f.get_mut(at) {
                                *b = u.arbitrary().unwrap_or(0);
                            }
                        }
                    }
                }
                let mut frames = vec![f];
                mutate(u, &mut frames, 16);
                self.feed(&frames, 4096, false);
            }
            // an alarm acknowledgement: ACK-RTA, or DATA-RTA with the AlarmAck
            12 => {
                let Some(acr) = self.d.cm().ar().and_then(|a| a.alarm_cr) else {
                    return;
                };
                let sel: u8 = u.arbitrary().unwrap_or(0);
                let p = usize::from(sel & 1);
                let id = if p == 0 { 0xFC01 } else { 0xFE01 };
                let ch = self.seen.alarms[p];
                let Some(last) = ch.last else { return };
                let f = if sel & 2 == 0 {
                    enc::rta(
                        id,
                        acr.device_ref,
                        acr.controller_ref,
                        3,
                        false,
                        ch.ctrl_send,
                        last,
                        &[],
                    )
                } else {
                    // DATA-RTA with the AlarmAck (type, API, slot, subslot, specifier, status OK)
                    let [slot, subslot, ty, spec, _, _] = ch.pending.unwrap_or_default();
                    let mut b = W::default();
                    let mut body = W::default();
                    body.u16(ty as u16)
                        .u32(0)
                        .u16(slot as u16)
                        .u16(subslot as u16)
                        .u16(spec as u16)
                        .u32(0);
                    b.u16(if p == 0 { 0x8001 } else { 0x8002 })
                        .u16(18)
                        .u8(1)
                        .u8(0)
                        .bytes(&body.0);
                    let send = profinet::alarm::rta::next_seq(ch.ctrl_send);
                    self.seen.alarms[p].ctrl_send = send;
                    enc::rta(id, acr.device_ref, acr.controller_ref, 1, true, send, last, &b.0)
                };
                self.seen.alarms[p].acked = true;
                let mut frames = vec![f];
                mutate(u, &mut frames, 16);
                if was_mutated() {
                    // a changed frame may not acknowledge
                    self.seen.alarms[p].acked = ch.acked;
                }
                self.feed(&frames, 4096, false);
            }
            // time passes: cyclic frames, watchdogs, retries
            13 => {
                let ms: u16 = u.arbitrary().unwrap_or(0);
                self.now = self.now + Nanos::from_us(u64::from(ms) * 50);
                self.feed(&[], 4096, false);
            }
            // link down/up, a diagnosis raised or cleared by the application
            14 => {
                let sel: u8 = u.arbitrary().unwrap_or(0);
                match sel % 4 {
                    0 => self.d.set_link(false),
                    1 => self.d.set_link(true),
                    2 => {
                        let _ = self
                            .d
                            .raise_diagnosis(sel >> 4, u.arbitrary::<u8>().unwrap_or(0) % 16);
                    }
                    _ => {
                        let _ = self
                            .d
                            .clear_diagnosis(sel >> 4, u.arbitrary::<u8>().unwrap_or(0) % 16);
                    }
                }
                self.feed(&[], 4096, false);
            }
            // DCP Set during (or without) the AR
            _ => {
                let sel: u8 = u.arbitrary().unwrap_or(0);
                let (o, s, v): (u8, u8, Vec<u8>) = match sel % 6 {
                    0 => (2, 2, b"drive-2".to_vec()),
                    1 => (1, 2, vec![192, 168, 0, 51, 255, 255, 255, 0, 0, 0, 0, 0]),
                    2 => (5, 3, vec![1, 0]),
                    3 => (5, 6, vec![0, 2]),
                    4 => (5, 1, vec![]),
                    _ => (
                        u.arbitrary().unwrap_or(0),
                        u.arbitrary().unwrap_or(0),
                        vec![0; usize::from(sel >> 4)],
                    ),
                };
                let q = if sel & 0x80 != 0 { 1 } else { 0 };
                let mut frames = vec![enc::dcp_set(u.arbitrary().unwrap_or(0), o, s, q, &v)];
                mutate(u, &mut frames, 16);
                self.feed(&frames, 4096, false);
            }
        }
    }
}

thread_local! {
    static MUTATED: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// One byte change (XOR with a non-zero value) at a position the input
/// chooses, at or after `from` in one of `frames`, one time in four.
fn mutate(u: &mut Unstructured<'_>, frames: &mut [Vec<u8>], from: usize) {
    let sel: u8 = u.arbitrary().unwrap_or(0);
    let on = sel & 3 == 0 && !frames.is_empty();
    MUTATED.with(|m| m.set(on));
    if !on {
        return;
    }
    let i = usize::from(sel >> 2) % frames.len();
    let f = &mut frames[i];
    if f.len() <= from {
        return;
    }
    let at = from + usize::from(u.arbitrary::<u16>().unwrap_or(0)) % (f.len() - from);
    f[at] ^= u.arbitrary::<u8>().unwrap_or(1).max(1);
}

fn was_mutated() -> bool {
    MUTATED.with(|m| m.get())
}

fuzz_target!(|data: &[u8]| {
    let mut u = Unstructured::new(data);
    let mut pn = Pn {
        d: device(),
        now: Nanos::from_ms(1),
        seq: 0,
        rw_seq: 0,
        seen: Seen::new(),
        after_rx: (None, String::new()),
        snap: false,
    };
    for _ in 0..OPS {
        if u.is_empty() {
            break;
        }
        pn.op(&mut u);
        // never more than one IO AR, never an AR without a state
        let io = pn.d.cm().ar();
        let sv = pn.d.cm().supervisor_ar();
        assert!(io.is_none_or(|a| a.ar_type == profinet::cm::ArType::IoCarSingle));
        assert!(sv.is_none_or(|a| a.ar_type == profinet::cm::ArType::IoSar));
        while pn.d.take_event().is_some() {}
    }
});
