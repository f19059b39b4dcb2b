//! A PROFINET controller's encoders for `pn_seq`: DCE/RPC requests (in
//! fragments when the body is long), the NDR request header, the CM blocks
//! of Connect (AR, IOCR, AlarmCR, ExpectedSubmodule), Control and
//! Release, IODRead/IODWrite headers (single and multiple), cyclic output
//! frames, RTA PDUs and DCP Set requests. Every field is what a controller
//! would send unless the input asks for something else; the input chooses
//! through [`Unstructured`].
#![allow(dead_code)]

use libfuzzer_sys::arbitrary::Unstructured;
use profinet::cm::connect::block_type as cb;
use profinet::cm::control::{block_type as ctl, command};
use profinet::model::{self, DataModule, Direction};
use profinet::rpc::{flags1, uuid, Drep, Header, PacketType, Uuid};
use profinet::testing::{CONTROLLER_MAC, DEVICE_MAC};

/// A second controller: another MAC and IP on the same subnet.
pub const OTHER_MAC: [u8; 6] = [0x02, 0, 0, 0, 0, 0xC1];
pub const OTHER_IP: [u8; 4] = [192, 168, 0, 11];

/// Fragment body size of long requests (a PDU of 80 + 1300 bytes).
const FRAG_BODY: usize = 1300;

/// Big-endian writer of a growing buffer.
#[derive(Default)]
pub struct W(pub Vec<u8>);

impl W {
    pub fn u8(&mut self, v: u8) -> &mut Self {
        self.0.push(v);
        self
    }
    pub fn u16(&mut self, v: u16) -> &mut Self {
        self.0.extend_from_slice(&v.to_be_bytes());
        self
    }
    pub fn u32(&mut self, v: u32) -> &mut Self {
        self.0.extend_from_slice(&v.to_be_bytes());
        self
    }
    pub fn bytes(&mut self, b: &[u8]) -> &mut Self {
        self.0.extend_from_slice(b);
        self
    }
    /// A block: type, length (version and body), version 1.0 and `body`.
    pub fn block(&mut self, t: u16, body: &[u8]) -> &mut Self {
        self.u16(t).u16((body.len() + 2) as u16).u8(1).u8(0).bytes(body)
    }
}

/// A value in `lo..=hi` (a controller's choice) or, one time in `odd`, any.
pub fn around(u: &mut Unstructured<'_>, lo: u32, hi: u32, odd: u8) -> u32 {
    let pick: u8 = u.arbitrary().unwrap_or(1);
    if odd != 0 && pick % odd == 0 {
        return u.arbitrary().unwrap_or(lo);
    }
    u.int_in_range(lo..=hi).unwrap_or(lo)
}

fn byte(u: &mut Unstructured<'_>) -> u8 {
    u.arbitrary().unwrap_or(0)
}

/// One expected submodule as the controller configures it.
#[derive(Clone, Copy, Debug)]
pub struct Sub {
    pub slot: u16,
    pub subslot: u16,
    pub module: u32,
    pub submodule: u32,
    /// Input (drive → controller) and output data lengths (None: that direction is absent).
    pub input: Option<u16>,
    pub output: Option<u16>,
}

/// The DAP's four subslots (no I/O data).
fn dap(u: &mut Unstructured<'_>) -> Vec<Sub> {
    let mut v = Vec::new();
    for subslot in model::DAP_SUBSLOTS {
        let submodule = match subslot {
            1 => model::DAP_SUBMODULE_IDENT,
            0x8000 => model::INTERFACE_SUBMODULE_IDENT,
            p => model::port_submodule_ident(p - 0x8000),
        };
        // now and then one is left out or named wrongly
        match byte(u) % 16 {
            0 => continue,
            1 => v.push(Sub {
                slot: 0,
                subslot,
                module: model::DAP_MODULE_IDENT,
                submodule: submodule ^ 0x10,
                input: Some(0),
                output: None,
            }),
            _ => v.push(Sub {
                slot: 0,
                subslot,
                module: model::DAP_MODULE_IDENT,
                submodule,
                input: Some(0),
                output: None,
            }),
        }
    }
    v
}

/// Data modules in slots around the GSDML's 1…2: catalogue modules of 2…19
/// words mostly, sometimes a length or slot outside.
fn data_modules(u: &mut Unstructured<'_>) -> Vec<Sub> {
    let n = byte(u) % 4;
    let mut v = Vec::new();
    for i in 0..n {
        let sel = byte(u);
        let slot = match sel % 8 {
            0 => around(u, 0, 5, 2) as u16,
            _ => u16::from(i) + 1,
        };
        let words = around(
            u,
            u32::from(*model::MODULE_WORDS.start()),
            u32::from(*model::MODULE_WORDS.end()),
            8,
        );
        let dir = if sel & 0x10 != 0 {
            Direction::ToDrive
        } else {
            Direction::FromDrive
        };
        let m = DataModule {
            direction: dir,
            words: (words & 0xFF) as u8,
        };
        let bytes = m.bytes() as u16;
        // a data description of the module's length, or another one
        let len = if sel & 0x20 != 0 && sel & 0x40 != 0 {
            around(u, 0, 80, 2) as u16
        } else {
            bytes
        };
        let (input, output) = match (dir, sel >> 7) {
            (Direction::FromDrive, 0) => (Some(len), None),
            (Direction::ToDrive, 0) => (None, Some(len)),
            _ => (Some(len), Some(len)),
        };
        v.push(Sub {
            slot,
            subslot: if byte(u) % 16 == 0 { 2 } else { 1 },
            module: if sel & 0x08 != 0 && sel & 0x04 != 0 {
                u.arbitrary().unwrap_or(0)
            } else {
                m.ident()
            },
            submodule: model::DATA_SUBMODULE_IDENT,
            input,
            output,
        });
    }
    v
}

/// The ExpectedSubmoduleBlockReq for `subs` (one API, a module per slot).
fn expected_block(w: &mut W, subs: &[Sub]) {
    let mut slots: Vec<u16> = subs.iter().map(|s| s.slot).collect();
    slots.dedup();
    let mut body = W::default();
    body.u16(slots.len() as u16);
    for slot in slots {
        let mine: Vec<&Sub> = subs.iter().filter(|s| s.slot == slot).collect();
        body.u32(0)
            .u16(slot)
            .u32(mine[0].module)
            .u16(0)
            .u16(mine.len() as u16);
        for s in mine {
            let props = match (s.input, s.output) {
                (Some(_), Some(_)) => 3u16,
                (None, Some(_)) => 2,
                (Some(n), None) if n > 0 || s.slot != 0 => 1,
                _ => 0,
            };
            body.u16(s.subslot).u32(s.submodule).u16(props);
            if props == 0 {
                body.u16(1).u16(0).u8(1).u8(1);
            }
            if let (Some(n), true) = (s.input, props & 1 != 0) {
                body.u16(1).u16(n).u8(1).u8(1);
            }
            if let (Some(n), true) = (s.output, props & 2 != 0) {
                body.u16(2).u16(n).u8(1).u8(1);
            }
        }
    }
    w.block(cb::EXPECTED_SUBMODULE_REQ, &body.0);
}

/// What a Connect asked for, for the oracles.
#[derive(Clone, Debug)]
pub struct ConnectReq {
    pub ar_uuid: Uuid,
    pub session_key: u16,
    pub ar_type: u16,
    pub controller: [u8; 6],
    /// RTClass of the IOCRs (1…3) and whether startup is advanced.
    pub rt_class: u8,
    pub advanced: bool,
}

/// The IOCR block for `subs`: input (type 1, drive → controller) or output
/// (type 2), objects laid out one after another, a data length that holds
/// them (at least 40), the cycle and factors around the GSDML's.
fn iocr_block(u: &mut Unstructured<'_>, w: &mut W, ty: u16, reference: u16, props: u32, subs: &[Sub]) {
    let input = ty == 1;
    let mut data = Vec::new();
    let mut iocs = Vec::new();
    let mut at = 0u16;
    for s in subs {
        let mine = if input { s.input } else { s.output };
        let other = if input { s.output } else { s.input };
        if let Some(n) = mine {
            data.push((s.slot, s.subslot, at));
            at = at.saturating_add(n).saturating_add(1);
        }
        if other.is_some() || (!input && mine.is_none()) {
            iocs.push((s.slot, s.subslot, 0u16));
        }
    }
    for c in iocs.iter_mut() {
        c.2 = at;
        at = at.saturating_add(1);
    }
    let sel = byte(u);
    let data_length = if sel % 8 == 0 {
        around(u, 0, 1500, 1) as u16
    } else {
        at.max(40)
    };
    let frame_id = match sel % 16 {
        1 => around(u, 0x8000, 0xFBFF, 3) as u16,
        _ => 0xFFFF,
    };
    let send_clock = match byte(u) % 8 {
        0 => 64,
        1 => 128,
        2 => u.arbitrary().unwrap_or(0),
        _ => model::SEND_CLOCK_FACTOR,
    };
    let rr = match byte(u) % 16 {
        0 => u.arbitrary().unwrap_or(1),
        k => model::REDUCTION_RATIOS[usize::from(k) % model::REDUCTION_RATIOS.len()],
    };
    let phase = if byte(u) % 8 == 0 {
        u.arbitrary().unwrap_or(1)
    } else {
        1
    };
    let wd = around(u, 3, 10, 6) as u16;
    let dh = if byte(u) % 8 == 0 {
        around(u, 1, 20, 4) as u16
    } else {
        wd
    };
    let mut b = W::default();
    b.u16(ty)
        .u16(reference)
        .u16(0x8892)
        .u32(props)
        .u16(data_length)
        .u16(frame_id)
        .u16(send_clock)
        .u16(rr)
        .u16(phase)
        .u16(0)
        .u32(0xFFFF_FFFF)
        .u16(wd)
        .u16(dh)
        .u16(if byte(u) % 16 == 0 {
            u.arbitrary().unwrap_or(0)
        } else {
            0xC000
        })
        .bytes(&[0; 6])
        .u16(1)
        .u32(0)
        .u16(data.len() as u16);
    for (slot, subslot, off) in &data {
        b.u16(*slot).u16(*subslot).u16(*off);
    }
    b.u16(iocs.len() as u16);
    for (slot, subslot, off) in &iocs {
        b.u16(*slot).u16(*subslot).u16(*off);
    }
    w.block(cb::IOCR_REQ, &b.0);
}

/// A whole Connect's NDR args and what it asked for.
pub fn connect(u: &mut Unstructured<'_>, controller: [u8; 6], ar_uuid: Uuid) -> (Vec<u8>, ConnectReq) {
    let sel = byte(u);
    let ar_type: u16 = match sel % 16 {
        0 => 6,
        1 => u.arbitrary().unwrap_or(0),
        _ => 1,
    };
    let session_key: u16 = u.arbitrary().unwrap_or(1);
    let advanced = sel & 0x10 != 0;
    // RTClass 1 mostly, 2 (advanced startup accepts it in newer devices), 3, or any
    let rt_class = match byte(u) % 8 {
        0 | 1 => 2,
        2 => 3,
        3 => byte(u) & 0x0F,
        _ => 1,
    };
    let mut props: u32 = 1 | if advanced { 1 << 30 } else { 0 } | if ar_type == 6 { 0x100 } else { 0 };
    if byte(u) % 16 == 0 {
        props ^= 1 << (byte(u) % 32);
    }
    let mut w = W::default();
    let name: &[u8] = match byte(u) % 8 {
        0 => b"",
        1 => &[b'x'; 241],
        _ => b"controller-1",
    };
    let mut ar = W::default();
    ar.u16(ar_type)
        .bytes(&ar_uuid.0)
        .u16(session_key)
        .bytes(&controller)
        .bytes(&uuid::pnio_object(1, 0x0002, 0x002A).0)
        .u32(props)
        .u16(around(u, 1, 1000, 8) as u16)
        .u16(0x8892)
        .u16(name.len() as u16)
        .bytes(name);
    w.block(cb::AR_REQ, &ar.0);
    let mut subs = dap(u);
    subs.extend(data_modules(u));
    if ar_type != 6 {
        let crs = match byte(u) % 16 {
            0 => 1,
            1 => 3,
            _ => 2,
        };
        let iocr_props = u32::from(rt_class);
        for i in 0..crs {
            let ty = if i % 2 == 0 { 1 } else { 2 };
            let reference = if byte(u) % 16 == 0 { 1 } else { i + 1 };
            iocr_block(u, &mut w, ty, reference, iocr_props, &subs);
        }
        let alarms = match byte(u) % 16 {
            0 => 0,
            1 => 2,
            _ => 1,
        };
        for _ in 0..alarms {
            let mut a = W::default();
            a.u16(1)
                .u16(0x8892)
                .u32(u32::from(byte(u) % 8 == 0))
                .u16(around(u, 1, 100, 8) as u16)
                .u16(around(u, 3, 15, 8) as u16)
                .u16(1)
                .u16(around(u, 200, 1432, 8) as u16)
                .u16(0xC000)
                .u16(0xA000);
            w.block(cb::ALARM_CR_REQ, &a.0);
        }
        // one ExpectedSubmodule block, or the slots split over two
        if byte(u) % 4 == 0 && subs.len() > 1 {
            let cut = subs.len() / 2;
            expected_block(&mut w, &subs[..cut]);
            expected_block(&mut w, &subs[cut..]);
        } else {
            expected_block(&mut w, &subs);
        }
    }
    (
        w.0,
        ConnectReq {
            ar_uuid,
            session_key,
            ar_type,
            controller,
            rt_class,
            advanced,
        },
    )
}

/// A control block (PrmEnd, Release) as `block_type`.
pub fn control(block_type: u16, ar_uuid: Uuid, session_key: u16, cmd: u16, props: u16) -> Vec<u8> {
    let mut b = W::default();
    b.u16(0)
        .bytes(&ar_uuid.0)
        .u16(session_key)
        .u16(0)
        .u16(cmd)
        .u16(props);
    let mut w = W::default();
    w.block(block_type, &b.0);
    w.0
}

pub fn prm_end(ar_uuid: Uuid, session_key: u16, cmd: u16, props: u16) -> Vec<u8> {
    control(ctl::PRM_END_REQ, ar_uuid, session_key, cmd, props)
}

pub fn release(ar_uuid: Uuid, session_key: u16, cmd: u16) -> Vec<u8> {
    control(ctl::RELEASE_REQ, ar_uuid, session_key, cmd, 0)
}

/// The ApplicationReady response block (command Done).
pub fn app_ready_res(ar_uuid: Uuid, session_key: u16, cmd: u16) -> Vec<u8> {
    control(ctl::APP_READY_RES, ar_uuid, session_key, cmd, 0)
}

pub const DONE: u16 = command::DONE;
pub const PRM_END: u16 = command::PRM_END;
pub const RELEASE: u16 = command::RELEASE;

/// Record address.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rec {
    pub slot: u16,
    pub subslot: u16,
    pub index: u16,
}

/// What a read and a write request header share: SeqNumber, ARUUID, API 0,
/// the address, RecordDataLength.
fn rw_head(seq: u16, ar: Uuid, r: Rec, len: u32) -> W {
    let mut b = W::default();
    b.u16(seq)
        .bytes(&ar.0)
        .u32(0)
        .u16(r.slot)
        .u16(r.subslot)
        .u16(0)
        .u16(r.index)
        .u32(len);
    b
}

/// An IODWriteReqHeader (64 bytes) for `len` bytes of record data.
pub fn write_header(w: &mut W, seq: u16, ar: Uuid, r: Rec, len: u32) {
    let mut b = rw_head(seq, ar, r, len);
    b.bytes(&[0; 24]);
    w.block(0x0008, &b.0);
}

/// An IODReadReqHeader (64 bytes) asking for at most `len` bytes.
pub fn read_header(seq: u16, ar: Uuid, r: Rec, len: u32) -> Vec<u8> {
    let mut b = rw_head(seq, ar, r, len);
    b.bytes(&Uuid::NIL.0).bytes(&[0; 8]);
    let mut w = W::default();
    w.block(0x0009, &b.0);
    w.0
}

/// The NDR request header around `args`.
pub fn ndr(args_maximum: u32, args: &[u8], little: bool) -> Vec<u8> {
    let n = args.len() as u32;
    let mut v = Vec::with_capacity(20 + args.len());
    for x in [args_maximum, n, args_maximum.max(n), 0, n] {
        v.extend_from_slice(&if little { x.to_le_bytes() } else { x.to_be_bytes() });
    }
    v.extend_from_slice(args);
    v
}

/// The datagrams of one RPC request (one, or fragments of [`FRAG_BODY`]).
pub fn rpc_request(
    activity: Uuid,
    seq: u32,
    opnum: u16,
    body: &[u8],
    little: bool,
    nofack: bool,
) -> Vec<Vec<u8>> {
    let chunks: Vec<&[u8]> = if body.len() <= FRAG_BODY + 84 {
        vec![body]
    } else {
        body.chunks(FRAG_BODY).collect()
    };
    let frag = chunks.len() > 1;
    let mut out = Vec::new();
    for (i, c) in chunks.iter().enumerate() {
        let last = i + 1 == chunks.len();
        let mut f1 = flags1::IDEMPOTENT;
        if frag {
            f1 |= flags1::FRAG;
            if last {
                f1 |= flags1::LASTFRAG;
            }
            if nofack {
                f1 |= flags1::NOFACK;
            }
        }
        let h = Header {
            ptype: PacketType::Request,
            flags1: f1,
            flags2: 0,
            drep: if little { Drep::LITTLE } else { Drep::BIG },
            serial: i as u16,
            object: uuid::pnio_object(1, model::DEVICE_ID, model::VENDOR_ID),
            interface: uuid::PNIO_DEVICE_INTERFACE,
            activity,
            boot_time: 0,
            if_version: 1,
            seq,
            opnum,
            if_hint: 0xFFFF,
            act_hint: 0xFFFF,
            body_len: c.len() as u16,
            frag_num: i as u16,
            auth_proto: 0,
        };
        let mut d = vec![0u8; 80];
        let _ = h.emit(&mut d);
        d.extend_from_slice(c);
        out.push(d);
    }
    out
}

/// The controller's Response to the device's request `req` (header as received).
pub fn rpc_response(req: &Header, body: &[u8]) -> Vec<u8> {
    let h = Header {
        ptype: PacketType::Response,
        flags1: 0,
        flags2: 0,
        drep: Drep::BIG,
        body_len: body.len() as u16,
        frag_num: 0,
        ..*req
    };
    let mut d = vec![0u8; 80];
    let _ = h.emit(&mut d);
    d.extend_from_slice(body);
    d
}

/// A UDP frame from the second controller: [`profinet::testing::udp_to_device`]
/// with another source MAC and IP (IPv4 checksum redone, UDP checksum off).
pub fn from_other(mut f: Vec<u8>) -> Vec<u8> {
    if f.len() < 42 {
        return f;
    }
    f[6..12].copy_from_slice(&OTHER_MAC);
    f[26..30].copy_from_slice(&OTHER_IP);
    f[24] = 0;
    f[25] = 0;
    let mut sum = 0u32;
    for c in f[14..34].chunks(2) {
        sum += u32::from(u16::from_be_bytes([c[0], c[1]]));
    }
    while sum > 0xFFFF {
        sum = (sum & 0xFFFF) + (sum >> 16);
    }
    f[24..26].copy_from_slice(&(!(sum as u16)).to_be_bytes());
    f[40] = 0;
    f[41] = 0;
    f
}

/// An RTA PDU (alarm frame) from the controller: FrameID, header, var part.
pub fn rta(
    frame_id: u16,
    dst_ref: u16,
    src_ref: u16,
    pdu: u8,
    tack: bool,
    send: u16,
    ack: u16,
    var: &[u8],
) -> Vec<u8> {
    let mut w = W::default();
    w.bytes(&DEVICE_MAC.0)
        .bytes(&CONTROLLER_MAC.0)
        .u16(0x8892)
        .u16(frame_id)
        .u16(dst_ref)
        .u16(src_ref)
        .u8(0x10 | pdu)
        .u8(if tack { 0x11 } else { 0x01 })
        .u16(send)
        .u16(ack)
        .u16(var.len() as u16)
        .bytes(var);
    w.0.resize(w.0.len().max(60), 0);
    w.0
}

/// A DCP Set request to the device with one block (option, suboption, qualifier, value).
pub fn dcp_set(xid: u32, option: u8, sub: u8, qualifier: u16, value: &[u8]) -> Vec<u8> {
    let mut blk = W::default();
    blk.u8(option)
        .u8(sub)
        .u16((value.len() + 2) as u16)
        .u16(qualifier)
        .bytes(value);
    if blk.0.len() % 2 == 1 {
        blk.u8(0);
    }
    let mut w = W::default();
    w.bytes(&DEVICE_MAC.0)
        .bytes(&CONTROLLER_MAC.0)
        .u16(0x8892)
        .u16(0xFEFD)
        .u8(4)
        .u8(0)
        .u32(xid)
        .u16(0)
        .u16(blk.0.len() as u16)
        .bytes(&blk.0);
    w.0.resize(w.0.len().max(60), 0);
    w.0
}
