//! The EtherCAT state machine (issue 39): the input is a list of
//! operations a master performs on the simulated line's drive, each sent as
//! real EtherCAT datagrams: AL control writes (any state, the acknowledge
//! bit, the device-identification request), SyncManager and FMMU
//! configuration writes (valid and not, in each state), mailbox requests
//! (any type), process-data writes and time passing (past the watchdog and
//! the 200 ms S→O wait). After each operation the AL status and AL status
//! code are read back and checked against [`Model`], a small model of
//! ETG.1000.6's state machine (the transition table, the error indication
//! and its acknowledge, ETG.1000.6 Table 11's codes), written from the
//! standard and /work/shared/spec/ethercat.md §3–4, not from the stack.
//!
//! Where the model cannot know the outcome (a P→S check on a mapping it
//! does not track, an S→O wait, a watchdog in Op) it allows the standard's
//! set of outcomes and then follows the device.
#![no_main]

#[path = "common.rs"]
mod common;

use common::{frame, reply};
use ecat::coe::Dictionary as _;
use esc::regs;
use hil_sim::sim::Simulation;
use libfuzzer_sys::arbitrary::Unstructured;
use libfuzzer_sys::fuzz_target;
use nanos::Nanos;

// Rules of ETG.1000.6 the stack breaks today and branch `ecat33` fixes:
// each is checked only when its constant is `true`; the lead sets them to
// `true` when merging `ecat33` (every other rule is checked always).
/// A repeated Op request while S→O waits does not restart the 200 ms wait.
const ECAT33_OP_WAIT_NOT_RESTARTED: bool = true;
/// Deactivating a mailbox SM in Pre-Op (or higher) falls back to Init with
/// 0016h; deactivating SM2/SM3 in Safe-Op/Op to Pre-Op with 001Dh/001Eh.
const ECAT33_SM_DEACTIVATION_FALLS_BACK: bool = false;
/// A mailbox request of a reserved type is answered with mailbox error 0002h.
const ECAT33_RESERVED_MAILBOX_TYPE_0002: bool = true;
/// The device-identification request (AL control bit 5) is honoured.
const ECAT33_DEVICE_IDENTIFICATION: bool = true;

/// Operations per input at most.
const OPS: usize = 16;

const INIT: u8 = 1;
const PREOP: u8 = 2;
const BOOT: u8 = 3;
const SAFEOP: u8 = 4;
const OP: u8 = 8;

/// AL status codes (ETG.1000.6 Table 11).
const INVALID_STATE_CHANGE: u16 = 0x0011;
const UNKNOWN_STATE: u16 = 0x0012;
const BOOT_NOT_SUPPORTED: u16 = 0x0013;
const INVALID_MAILBOX: u16 = 0x0016;
const INVALID_SM: u16 = 0x0017;
const WATCHDOG: u16 = 0x001B;
const INVALID_OUTPUT: u16 = 0x001D;
const INVALID_INPUT: u16 = 0x001E;
/// Codes a refused P→S may carry: SM, output, input, watchdog, free run,
/// no valid I/O, the DC configuration codes.
const PS_CODES: [u16; 10] = [
    0x0017, 0x001D, 0x001E, 0x001F, 0x0029, 0x002B, 0x0030, 0x0035, 0x0036, 0x0001,
];
/// Codes with which a slave may leave Op/Safe-Op on its own (watchdog,
/// synchronisation) or refuse S→O.
const RUN_CODES: [u16; 11] = [
    0x001A, 0x001B, 0x002B, 0x002C, 0x002D, 0x0032, 0x0033, 0x0034, 0x001D, 0x001E, 0x0001,
];

/// The mailbox SyncManagers as the SII's defaults give them.
const SM0: (u16, u16, u8) = (0x1000, 256, 0x26);
const SM1: (u16, u16, u8) = (0x1100, 256, 0x22);

/// What the model knows of a SyncManager's configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Cfg {
    /// As the device's description requires.
    Valid,
    /// Certainly not (disabled, no length, the other direction, overlapping).
    Invalid,
    /// Something the model does not judge.
    Unknown,
}

#[derive(Clone, Copy, Debug)]
struct Model {
    state: u8,
    error: bool,
    code: u16,
    sm: [Cfg; 4],
    /// An S→O request waiting for process data since (first request).
    op_wait: Option<Nanos>,
    /// Bootstrap is offered (the device's mailbox has FoE).
    boot: bool,
}

/// What the device may show after an operation: a list of (state, error, codes).
type Allowed = Vec<(u8, bool, Vec<u16>)>;

impl Model {
    fn one(&self) -> Allowed {
        vec![(self.state, self.error, vec![self.code])]
    }

    /// ETG.1000.6's state transition for a request of `req` (state bits)
    /// with acknowledge `ack`, at `now`.
    fn request(&self, req: u8, ack: bool, now: Nanos) -> Allowed {
        let s = self.state;
        // an error indication stays until the master acknowledges it
        if self.error && !ack {
            return self.one();
        }
        let err = |code: u16| vec![(s, true, vec![code])];
        if !matches!(req, INIT | PREOP | BOOT | SAFEOP | OP) {
            return err(UNKNOWN_STATE);
        }
        if req == s {
            // the same state: the acknowledge clears the indication; a
            // repeated Op request while S→O waits keeps waiting
            return vec![(s, false, vec![0])];
        }
        match (s, req) {
            (_, INIT) => vec![(INIT, false, vec![0])],
            (INIT, PREOP) => match (self.sm[0], self.sm[1]) {
                (Cfg::Valid, Cfg::Valid) => vec![(PREOP, false, vec![0])],
                (Cfg::Invalid, _) | (_, Cfg::Invalid) => err(INVALID_MAILBOX),
                _ => vec![(PREOP, false, vec![0]), (INIT, true, vec![INVALID_MAILBOX])],
            },
            (INIT, BOOT) if self.boot => vec![(BOOT, false, vec![0]), (INIT, true, vec![INVALID_MAILBOX])],
            (INIT, BOOT) => err(BOOT_NOT_SUPPORTED),
            (BOOT, _) => err(INVALID_STATE_CHANGE),
            (_, BOOT) => err(INVALID_STATE_CHANGE),
            (PREOP, SAFEOP) => {
                if self.sm[2] == Cfg::Invalid || self.sm[3] == Cfg::Invalid {
                    vec![(PREOP, true, PS_CODES.to_vec())]
                } else {
                    vec![(SAFEOP, false, vec![0]), (PREOP, true, PS_CODES.to_vec())]
                }
            }
            (SAFEOP, OP) => {
                // E-033: up to 200 ms of Safe-Op without error, then Op or a refusal
                let _ = now;
                vec![
                    (OP, false, vec![0]),
                    (SAFEOP, false, vec![0]),
                    (SAFEOP, true, RUN_CODES.to_vec()),
                ]
            }
            (SAFEOP | OP, PREOP) | (OP, SAFEOP) => vec![(req, false, vec![0])],
            // I→S, I→O, P→O: not in the table
            _ => err(INVALID_STATE_CHANGE),
        }
    }

    /// What may happen on its own while time passes or process data comes:
    /// nothing, or (in Safe-Op/Op) a fall to a lower state with an error.
    fn autonomous(&self) -> Allowed {
        let mut v = self.one();
        if self.op_wait.is_some() && self.state == SAFEOP && !self.error {
            v.push((OP, false, vec![0]));
            v.push((SAFEOP, true, RUN_CODES.to_vec()));
        }
        if self.state == OP {
            v.push((SAFEOP, true, RUN_CODES.to_vec()));
            v.push((PREOP, true, RUN_CODES.to_vec()));
        }
        if self.state == SAFEOP && !self.error {
            v.push((SAFEOP, true, RUN_CODES.to_vec()));
            v.push((PREOP, true, RUN_CODES.to_vec()));
        }
        v
    }

    fn check(&mut self, allowed: &Allowed, got: (u8, bool, u16, bool), what: &str) {
        let (state, error, code, _id) = got;
        let ok = allowed.iter().any(|(s, e, codes)| {
            *s == state && *e == error && (codes.contains(&code) || (!error && code == 0))
        });
        assert!(
            ok,
            "{what}: AL status {state:#x} error {error} code {code:#06x}; the model allows {allowed:x?} (from {self:x?})"
        );
        // Op reached, another state, or the request refused: no longer waiting
        if self.state != state || error {
            self.op_wait = None;
        }
        static SEEN: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
        let bit = 1u32 << (state & 0xF) << if error { 16 } else { 0 };
        if SEEN.fetch_or(bit, std::sync::atomic::Ordering::Relaxed) & bit == 0 {
            eprintln!("STATE {state:#x} error {error} code {code:#06x} after {what}");
        }
        self.state = state;
        self.error = error;
        self.code = code;
    }
}

struct Line {
    sim: Simulation,
    model: Model,
    /// The drive's RxPDO and TxPDO lengths (its mapping at power-on).
    pd_bytes: (usize, usize),
    /// The last AL control value written.
    last_control: u16,
}

thread_local! {
    /// A line with one drive in Init (station address set), once per process.
    static LINE: Simulation = {
        let mut sim = Simulation::new(1);
        common::apwr(&mut sim, regs::STATION_ADDRESS, &0x1000u16.to_le_bytes());
        sim.advance_to(sim.now() + Nanos::from_ms(1));
        sim
    };
}

impl Line {
    fn write(&mut self, ado: u16, data: &[u8]) {
        common::apwr(&mut self.sim, ado, data);
    }

    fn read(&mut self, ado: u16, len: usize) -> Vec<u8> {
        let mut f = frame(1, 0, ado, &vec![0; len]);
        self.sim.exchange(&mut f);
        reply(&f).0.to_vec()
    }

    /// Lets the drive run for `d`.
    fn wait(&mut self, d: Nanos) {
        let t = self.sim.now() + d;
        self.sim.advance_to(t);
    }

    /// AL status (state, error, ID loaded) and AL status code.
    fn status(&mut self) -> (u8, bool, u16, bool) {
        let b = self.read(regs::AL_STATUS, 6);
        let st = u16::from_le_bytes([b[0], b[1]]);
        let code = u16::from_le_bytes([b[4], b[5]]);
        ((st & 0x0F) as u8, st & 0x10 != 0, code, st & 0x20 != 0)
    }

    fn sm_write(&mut self, n: u8, start: u16, len: u16, control: u8, enable: bool) {
        let sm = esc::SyncManager {
            start,
            length: len,
            control,
            status: 0,
            activate: u8::from(enable),
            pdi_control: 0,
        };
        self.write(regs::sm(n), &sm.to_bytes());
    }
}

/// Writes AL control `value` (requested state, acknowledge 0x10, device
/// identification 0x20), reads the AL status back and checks it against the
/// model; keeps the model's S→O wait (E-033): started by the first Op
/// request from Safe-Op, kept by a repeated one, ended by any other
/// processed request, a state change or an error.
fn al_control(line: &mut Line, value: u16) {
    let now = line.sim.now();
    let req = (value & 0x0F) as u8;
    let ack = value & 0x10 != 0;
    let id = value & 0x20 != 0;
    let allowed = line.model.request(req, ack, now);
    let processed = !(line.model.error && !ack);
    let repeat_op = req == OP && line.model.state == SAFEOP && line.model.op_wait.is_some();
    line.write(regs::AL_CONTROL, &value.to_le_bytes());
    line.wait(Nanos::from_ms(1));
    let got = line.status();
    // ETG.1000.6: a processed request with bit 5 loads the ID (shown
    // while no error is indicated); one without it unloads it; a
    // request ignored (error shown, no acknowledge) changes nothing
    if ECAT33_DEVICE_IDENTIFICATION && processed {
        let (_, error, _, loaded) = got;
        assert!(
            loaded == (id && !error),
            "device identification {}requested: AL status {} ID loaded (error {error})",
            if id { "" } else { "not " },
            if loaded { "with" } else { "without" }
        );
    }
    // with the ID loaded the code register holds the identification value
    let mut checked = got;
    if got.3 {
        checked.2 = 0;
    }
    line.model
        .check(&allowed, checked, &format!("AL control {value:#06x}"));
    line.last_control = value;
    if !processed {
        return;
    }
    if req == OP && line.model.state == SAFEOP && !line.model.error {
        if !(repeat_op && ECAT33_OP_WAIT_NOT_RESTARTED) || line.model.op_wait.is_none() {
            line.model.op_wait = Some(now);
        }
    } else {
        // any other processed request replaces the waiting one
        line.model.op_wait = None;
    }
}

/// E-033: no Op request waits longer than 200 ms (plus the polling slack)
/// from the first request: by then the device is in Op or refused it.
fn e033_wait_ended(line: &Line) {
    if let Some(t) = line.model.op_wait {
        assert!(
            line.sim.now() <= t + Nanos::from_ms(260) || line.model.state != SAFEOP || line.model.error,
            "S→O still waiting {} ms after the Op request",
            (line.sim.now() - t).as_ns() / 1_000_000
        );
    }
}

fn op(line: &mut Line, u: &mut Unstructured<'_>) {
    let kind: u8 = u.arbitrary().unwrap_or(0);
    match kind % 8 {
        // AL control: a state (mostly a defined one), acknowledge, device identification
        0 | 1 | 2 => {
            let sel: u8 = u.arbitrary().unwrap_or(0);
            let req = match sel % 16 {
                0 => sel >> 4,
                k => [INIT, PREOP, SAFEOP, OP, BOOT, PREOP, SAFEOP, OP][usize::from(k) % 8],
            };
            let ack = sel & 0x40 != 0 || !line.model.error && sel & 0x20 != 0;
            let id = u.ratio(1, 8).unwrap_or(false);
            let value = u16::from(req) | if ack { 0x10 } else { 0 } | if id { 0x20 } else { 0 };
            al_control(line, value);
        }
        // SyncManager configuration: valid, certainly not, or any bytes
        3 => {
            let n = u.arbitrary::<u8>().unwrap_or(0) % 4;
            let sel: u8 = u.arbitrary().unwrap_or(0);
            // SM2/SM3: the length of the drive's PDO mapping, or any
            let (rx, tx) = line.pd_bytes;
            let mut pd = |want: usize| {
                if u.ratio(1, 4).unwrap_or(false) {
                    u.int_in_range(0..=64).unwrap_or(0)
                } else {
                    want as u16
                }
            };
            let (start, len, control) = match n {
                0 => SM0,
                1 => SM1,
                2 => (0x1200, pd(rx), 0x64),
                _ => (0x1A00, pd(tx), 0x20),
            };
            let cfg = match sel % 8 {
                0 => {
                    // disabled
                    line.sm_write(n, start, len, control, false);
                    Cfg::Invalid
                }
                1 if n < 2 => {
                    // the other mailbox direction
                    line.sm_write(n, start, len, control ^ 0x04, true);
                    Cfg::Invalid
                }
                2 => {
                    line.sm_write(n, start, 0, control, true);
                    Cfg::Invalid
                }
                3 => {
                    // any bytes, at a start in the process RAM (a start in
                    // the register area would hide the AL status from the master)
                    let mut b: [u8; 8] = u.arbitrary().unwrap_or_default();
                    b[1] = 0x10 | (b[1] & 0x0F);
                    line.write(regs::sm(n), &b);
                    Cfg::Unknown
                }
                _ => {
                    line.sm_write(n, start, len, control, true);
                    if n < 2 {
                        Cfg::Valid
                    } else {
                        Cfg::Unknown
                    }
                }
            };
            let before = line.model;
            line.model.sm[usize::from(n)] = cfg;
            line.wait(Nanos::from_ms(1));
            let got = line.status();
            // a configuration change in Init does nothing; later, taking
            // away a SyncManager in use ends the state (ECAT33_SM_DEACTIVATION_FALLS_BACK checks how)
            let mailbox_gone = n < 2 && cfg == Cfg::Invalid && !matches!(before.state, INIT | BOOT);
            let pd_gone = n >= 2 && cfg == Cfg::Invalid && matches!(before.state, SAFEOP | OP);
            let allowed = if ECAT33_SM_DEACTIVATION_FALLS_BACK && mailbox_gone {
                vec![(INIT, true, vec![INVALID_MAILBOX])]
            } else if ECAT33_SM_DEACTIVATION_FALLS_BACK && pd_gone {
                vec![(
                    PREOP,
                    true,
                    vec![if n == 2 { INVALID_OUTPUT } else { INVALID_INPUT }],
                )]
            } else {
                let mut v = before.one();
                if before.state != INIT && cfg != Cfg::Valid {
                    v.push((INIT, true, vec![INVALID_MAILBOX, INVALID_SM]));
                    v.push((
                        PREOP,
                        true,
                        vec![INVALID_OUTPUT, INVALID_INPUT, INVALID_SM, WATCHDOG],
                    ));
                    v.push((SAFEOP, true, RUN_CODES.to_vec()));
                }
                if before.state != INIT {
                    v.extend(before.autonomous());
                }
                v
            };
            line.model.check(&allowed, got, &format!("SM{n} write ({cfg:?})"));
        }
        // FMMU configuration: any bytes (no rule of the ESM)
        4 => {
            let n = u.arbitrary::<u8>().unwrap_or(0) % 3;
            let b: [u8; 16] = u.arbitrary().unwrap_or_default();
            line.write(regs::fmmu(n), &b);
            line.wait(Nanos::from_ms(1));
            let got = line.status();
            let allowed = line.model.autonomous();
            line.model.check(&allowed, got, "FMMU write");
        }
        // a mailbox request of any type into SM0, the answer read from SM1
        5 => {
            let sel: u8 = u.arbitrary().unwrap_or(0);
            let ty = sel & 0x0F;
            let mut m = vec![0u8; 256];
            let len = u.int_in_range(0..=40u16).unwrap_or(10);
            m[0..2].copy_from_slice(&len.to_le_bytes());
            m[5] = ty | ((sel >> 4) & 7) << 4;
            for b in m.iter_mut().skip(6).take(usize::from(len)) {
                *b = u.arbitrary().unwrap_or(0);
            }
            if ty == 3 && sel & 0x80 != 0 {
                // a CoE SDO upload of 1000h
                m[0] = 10;
                m[6..16].copy_from_slice(&[0x00, 0x20, 0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]);
            } else if ty == 3 && sel & 0x40 != 0 {
                // a CoE SDO download of A258 (2102h, the process-data
                // monitoring time) = 100 ms: with it S→O waits for RxPDOs
                // (E-033), which random mailbox bytes almost never write
                m[0] = 10;
                m[6..16].copy_from_slice(&[0x00, 0x20, 0x2B, 0x02, 0x21, 0x00, 100, 0, 0, 0]);
            }
            // answers still waiting (in SM1 and queued behind it, to earlier
            // requests) are read out first, so the answer read below is this
            // request's
            for _ in 0..4 {
                let _ = line.read(SM1.0, 256);
                line.wait(Nanos::from_ms(1));
            }
            line.write(SM0.0, &m);
            line.wait(Nanos::from_ms(1));
            let answer = line.read(SM1.0, 256);
            let mailbox_up =
                line.model.state != INIT && line.model.sm[0] == Cfg::Valid && line.model.sm[1] == Cfg::Valid;
            // a header that is well-formed otherwise (data length above 0,
            // channel 0): the header's own errors (0006h, 0003h) come first
            if ECAT33_RESERVED_MAILBOX_TYPE_0002
                && mailbox_up
                && len > 0
                && (6..=14).contains(&ty)
                && answer[5] & 0x0F == 0
            {
                let detail = u16::from_le_bytes([answer[8], answer[9]]);
                assert_eq!(
                    detail, 0x0002,
                    "mailbox type {ty} answered with error {detail:#06x}"
                );
            }
            let got = line.status();
            let allowed = line.model.autonomous();
            line.model
                .check(&allowed, got, &format!("mailbox request type {ty}"));
        }
        // process data into SM2's area (LWR-like: the SM2 window by APWR)
        6 => {
            let n = u.int_in_range(1..=64usize).unwrap_or(1);
            let data: Vec<u8> = (0..n).map(|_| u.arbitrary::<u8>().unwrap_or(0)).collect();
            let data = if u.ratio(1, 2).unwrap_or(true) {
                vec![0u8; line.pd_bytes.0.max(1)]
            } else {
                data
            };
            for _ in 0..u.int_in_range(1..=8u8).unwrap_or(1) {
                line.write(0x1200, &data);
                line.wait(Nanos::from_ms(1));
            }
            let got = line.status();
            let allowed = line.model.autonomous();
            line.model.check(&allowed, got, "process data");
        }
        // time passes: a few ms, or past the SM watchdog's default 100 ms or
        // the 200 ms S→O wait (simulated time is what an input costs); with
        // the long waits' top bit the master rewrites its last AL control
        // request every 10 ms meanwhile, as masters that write AL control
        // cyclically do (E-033: a repeated Op request keeps the wait's start)
        _ => {
            let sel: u8 = u.arbitrary().unwrap_or(0);
            let ms = match sel % 8 {
                0 => 110,
                1 => 210,
                2 => 330,
                _ => u64::from(sel >> 3) + 1,
            };
            let repeat = sel % 8 <= 2 && sel & 0x80 != 0;
            let end = line.sim.now() + Nanos::from_ms(ms);
            if repeat {
                while line.sim.now() + Nanos::from_ms(10) <= end {
                    line.wait(Nanos::from_ms(9));
                    let got = line.status();
                    let allowed = line.model.autonomous();
                    line.model.check(&allowed, got, "time passing");
                    al_control(line, line.last_control);
                    e033_wait_ended(line);
                }
            }
            let rest = end.saturating_sub(line.sim.now());
            line.wait(rest);
            let got = line.status();
            let allowed = line.model.autonomous();
            line.model.check(&allowed, got, &format!("{ms} ms later"));
            e033_wait_ended(line);
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let mut u = Unstructured::new(data);
    let sim = LINE.with(|s| s.try_clone()).expect("the line copies");
    let boot = sim.drives()[0].drive.slave().foe_supported();
    let pd_bytes = sim.drives()[0]
        .drive
        .objects()
        .process_data_bytes()
        .unwrap_or((0, 0));
    let mut line = Line {
        sim,
        model: Model {
            state: INIT,
            error: false,
            code: 0,
            sm: [Cfg::Unknown; 4],
            op_wait: None,
            boot,
        },
        pd_bytes,
        last_control: u16::from(INIT),
    };
    let got = line.status();
    line.model.check(&vec![(INIT, false, vec![0])], got, "power-on");
    for _ in 0..OPS {
        if u.is_empty() {
            break;
        }
        op(&mut line, &mut u);
    }
});
