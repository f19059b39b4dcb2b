//! Slave tests against a fake ESC: plain memory, AL control read clears AL event
//! bit 0, reading the last byte of SM0/SM2 clears their event bit, writing the
//! last byte of SM1 sets its MAILBOX_FULL status bit.

extern crate std;
use std::vec::Vec;

use crate::coe::{CommState, Dictionary, SdoAbort};
use crate::desc::*;
use crate::{Slave, StateChange};
use esc::regs::{self, al_event};
use esc::sii::mailbox_protocol;
use esc::sm::{activate, pdi_control, status};
use esc::{AlState, AlStatusCode, Pdi};
use nanos::Nanos;

static RX_ENTRIES: [PdoEntry; 2] = [
    PdoEntry::new(0x7000, 1, DataType::U16, "Out word"),
    PdoEntry::new(0x7000, 2, DataType::U8, "Out byte"),
];
static TX_ENTRIES: [PdoEntry; 1] = [PdoEntry::new(0x6000, 1, DataType::U32, "In dword")];
static RX: [Pdo; 1] = [Pdo {
    index: 0x1600,
    name: "Outputs",
    entries: &RX_ENTRIES,
}];
static TX: [Pdo; 1] = [Pdo {
    index: 0x1A00,
    name: "Inputs",
    entries: &TX_ENTRIES,
}];
pub(crate) const DEV_DESC: Device = Device {
    identity: Identity {
        vendor_id: 0xB9,
        product_code: 1,
        revision: 1,
        serial: 0,
    },
    device_type: 0x0002_0192,
    name: "Test",
    order_code: "T",
    group: "Drives",
    mailbox_out: MailboxSm {
        start: 0x1000,
        length: 128,
        control: 0x26,
    },
    mailbox_in: MailboxSm {
        start: 0x1080,
        length: 128,
        control: 0x22,
    },
    outputs: ProcessSm {
        start: 0x1100,
        control: 0x64,
    },
    inputs: ProcessSm {
        start: 0x1180,
        control: 0x20,
    },
    fmmus: &[FmmuUsage::Outputs, FmmuUsage::Inputs, FmmuUsage::MailboxStatus],
    mailbox_protocols: mailbox_protocol::COE | mailbox_protocol::EOE,
    coe_details: coe_details::SDO,
    ports: 2,
    process_ram_end: 0x3000,
    dc_modes: &[],
    rx_pdos: &RX,
    tx_pdos: &TX,
    rx_assign: &[0x1600],
    tx_assign: &[0x1A00],
};
static DEV: Device = DEV_DESC;
/// The same device with SDO Information.
static DEV_INFO: Device = Device {
    coe_details: coe_details::SDO | coe_details::SDO_INFO,
    ..DEV_DESC
};

static MANY_ENTRIES: [od::EntryInfo; 1] = [od::EntryInfo {
    sub: 0,
    name: "Many",
    data_type: DataType::U8,
    access: od::Access::RO,
    min: None,
    max: None,
    default: 0,
    unit: "",
    persistent: false,
}];
const MANY_N: usize = 150;
/// Objects 3000h..3095h, for SDO Info lists longer than one mailbox.
static MANY: [od::ObjectInfo; MANY_N] = {
    let mut a = [od::ObjectInfo {
        index: 0x3000,
        name: "Many",
        code: od::ObjectCode::Var,
        entries: od::Entries::slice(&MANY_ENTRIES),
    }; MANY_N];
    let mut i = 0;
    while i < MANY_N {
        a[i].index = 0x3000 + i as u16;
        i += 1;
    }
    a
};

struct Fake {
    mem: [u8; 0x3000],
    /// Addresses of PDI writes to AL status / AL status code, in order.
    status_writes: Vec<u16>,
}

impl Fake {
    fn new() -> Self {
        let mut f = Fake {
            mem: [0; 0x3000],
            status_writes: Vec::new(),
        };
        // the master's SII-conformant configuration
        f.set_sm(0, 0x1000, 128, 0x26);
        f.set_sm(1, 0x1080, 128, 0x22);
        f.set_sm(2, 0x1100, 3, 0x64);
        f.set_sm(3, 0x1180, 4, 0x20);
        f
    }
    fn set_sm(&mut self, n: u8, start: u16, len: u16, control: u8) {
        let a = regs::sm(n) as usize;
        self.mem[a..a + 2].copy_from_slice(&start.to_le_bytes());
        self.mem[a + 2..a + 4].copy_from_slice(&len.to_le_bytes());
        self.mem[a + 4] = control;
        self.mem[a + 6] = activate::ENABLE;
    }
    fn sm(&self, n: u8) -> (usize, usize) {
        let a = regs::sm(n) as usize;
        let start = u16::from_le_bytes([self.mem[a], self.mem[a + 1]]) as usize;
        let len = u16::from_le_bytes([self.mem[a + 2], self.mem[a + 3]]) as usize;
        (start, len)
    }
    fn u16(&self, a: u16) -> u16 {
        u16::from_le_bytes([self.mem[a as usize], self.mem[a as usize + 1]])
    }
    fn events(&self) -> u32 {
        let a = regs::AL_EVENT_REQUEST as usize;
        u32::from_le_bytes(self.mem[a..a + 4].try_into().unwrap())
    }
    fn set_events(&mut self, e: u32) {
        let a = regs::AL_EVENT_REQUEST as usize;
        self.mem[a..a + 4].copy_from_slice(&e.to_le_bytes());
    }
    fn request(&mut self, ctrl: u16) {
        let a = regs::AL_CONTROL as usize;
        self.mem[a..a + 2].copy_from_slice(&ctrl.to_le_bytes());
        self.set_events(self.events() | al_event::AL_CONTROL);
    }
    fn status(&self) -> u16 {
        self.u16(regs::AL_STATUS)
    }
    fn code(&self) -> u16 {
        self.u16(regs::AL_STATUS_CODE)
    }
    fn sm1_full(&self) -> bool {
        self.mem[regs::sm(1) as usize + 5] & status::MAILBOX_FULL != 0
    }
    /// The master writes a mailbox request into SM0.
    fn mbx_write(&mut self, req: &[u8]) {
        let (start, len) = self.sm(0);
        self.mem[start..start + len].fill(0);
        self.mem[start..start + req.len()].copy_from_slice(req);
        self.set_events(self.events() | al_event::sm(0));
    }
    /// The master reads SM1 (if full).
    fn mbx_read(&mut self) -> Option<Vec<u8>> {
        if !self.sm1_full() {
            return None;
        }
        let (start, len) = self.sm(1);
        self.mem[regs::sm(1) as usize + 5] &= !status::MAILBOX_FULL;
        Some(self.mem[start..start + len].to_vec())
    }
}

impl Pdi for Fake {
    type Error = core::convert::Infallible;
    fn read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Self::Error> {
        let (a, end) = (addr as usize, addr as usize + buf.len());
        buf.copy_from_slice(&self.mem[a..end]);
        if (a..end).contains(&(regs::AL_CONTROL as usize)) {
            self.set_events(self.events() & !al_event::AL_CONTROL);
        }
        for n in [0u8, 2] {
            let (s, l) = self.sm(n);
            if l > 0 && (a..end).contains(&(s + l - 1)) {
                self.set_events(self.events() & !al_event::sm(n));
            }
        }
        Ok(())
    }
    fn write(&mut self, addr: u16, data: &[u8]) -> Result<(), Self::Error> {
        let (a, end) = (addr as usize, addr as usize + data.len());
        self.mem[a..end].copy_from_slice(data);
        for r in [regs::AL_STATUS, regs::AL_STATUS_CODE] {
            if (a..end).contains(&(r as usize)) {
                self.status_writes.push(r);
            }
        }
        let (s, l) = self.sm(1);
        if l > 0 && (a..end).contains(&(s + l - 1)) {
            self.mem[regs::sm(1) as usize + 5] |= status::MAILBOX_FULL;
        }
        Ok(())
    }
}

/// 0x1000:0 = "Test", 0x2000:0 u16 writable.
struct App {
    value: u16,
    /// The RxPDO monitoring the application asks for (default off).
    pdo_timeout: crate::PdoTimeout,
}

impl Dictionary for App {
    fn object(&self, index: u16) -> Option<&'static od::ObjectInfo> {
        MANY.iter().find(|o| o.index == index)
    }
    fn next_object(&self, after: Option<u16>) -> Option<&'static od::ObjectInfo> {
        MANY.iter().find(|o| after.is_none_or(|a| o.index > a))
    }
    fn read(&mut self, index: u16, sub: u8, buf: &mut [u8], _: CommState) -> Result<usize, SdoAbort> {
        let v = self.value.to_le_bytes();
        let data: &[u8] = match (index, sub) {
            (0x1008, 0) => b"Test",
            (0x2000, 0) => &v,
            _ => return Err(SdoAbort::NO_OBJECT),
        };
        buf.get_mut(..data.len())
            .ok_or(SdoAbort::OUT_OF_MEMORY)?
            .copy_from_slice(data);
        Ok(data.len())
    }
    fn write(&mut self, index: u16, _: u8, data: &[u8], _: CommState) -> Result<(), SdoAbort> {
        match (index, data) {
            (0x2000, &[a, b]) => {
                self.value = u16::from_le_bytes([a, b]);
                Ok(())
            }
            _ => Err(SdoAbort::READ_ONLY),
        }
    }
}

/// The defaults but the RxPDO monitoring: a 1 ms cycle, any SYNC0 cycle.
impl crate::Application for App {
    fn pdo_timeout(&mut self) -> crate::PdoTimeout {
        self.pdo_timeout
    }
}

struct Rig {
    esc: Fake,
    slave: Slave,
    app: App,
    t: Nanos,
}

impl Rig {
    fn new() -> Self {
        Self::with(&DEV)
    }
    fn with(dev: &'static Device) -> Self {
        let mut r = Rig {
            esc: Fake::new(),
            slave: Slave::new(dev),
            app: App {
                value: 0,
                pdo_timeout: crate::PdoTimeout::Off,
            },
            t: Nanos::ZERO,
        };
        r.poll();
        r
    }
    fn poll(&mut self) -> Option<StateChange> {
        self.t += Nanos::from_ms(1);
        let Ok(c) = self.slave.poll(&mut self.esc, &mut self.app, self.t);
        c
    }
    /// Requests `ctrl` and returns (AL status, AL status code) after one poll.
    fn req(&mut self, ctrl: u16) -> (u16, u16) {
        self.esc.request(ctrl);
        self.poll();
        (self.esc.status(), self.esc.code())
    }
    fn goto(&mut self, state: AlState) {
        let path: &[u16] = match state {
            AlState::Init => &[],
            AlState::PreOp => &[2],
            AlState::SafeOp => &[2, 4],
            AlState::Op => &[2, 4, 8],
            AlState::Bootstrap => unreachable!(),
        };
        for &s in path {
            assert_eq!(self.req(s), (s, 0));
        }
        assert_eq!(self.slave.state(), state);
    }
    /// Sends an SDO upload request with `counter` and returns the response (if any).
    fn upload(&mut self, index: u16, sub: u8, counter: u8) -> Option<Vec<u8>> {
        let [i0, i1] = index.to_le_bytes();
        self.esc.mbx_write(&[
            10,
            0,
            0,
            0,
            0,
            0x03 | (counter << 4),
            0x00,
            0x20,
            0x40,
            i0,
            i1,
            sub,
            0,
            0,
            0,
            0,
        ]);
        self.poll();
        self.esc.mbx_read()
    }
}

const STATES: [AlState; 4] = [AlState::Init, AlState::PreOp, AlState::SafeOp, AlState::Op];

#[test]
fn e021_e022_e023_transition_matrix() {
    for from in STATES {
        for requested in 0u16..16 {
            let mut r = Rig::new();
            r.goto(from);
            let (status, code) = r.req(requested);
            let legal = match (from.code(), requested) {
                (f, q) if f as u16 == q => Some(q),
                (1, 2) | (2, 4) | (4, 8) => Some(requested),
                (_, 1 | 2 | 4) if (requested as u8) < from.code() => Some(requested),
                _ => None,
            };
            let want = match (legal, requested) {
                (Some(q), _) => (q, 0),
                (None, 3) => (u16::from(from.code()) | 0x10, 0x0013),
                (None, 1 | 2 | 4 | 8) => (u16::from(from.code()) | 0x10, 0x0011),
                (None, _) => (u16::from(from.code()) | 0x10, 0x0012),
            };
            assert_eq!((status, code), want, "{from:?} -> {requested}");
        }
    }
}

#[test]
fn e043_status_code_written_before_status() {
    let mut r = Rig::new();
    r.esc.status_writes.clear();
    r.req(4);
    assert_eq!(r.esc.status_writes, [regs::AL_STATUS_CODE, regs::AL_STATUS]);
}

#[test]
fn e041_error_needs_acknowledge() {
    let mut r = Rig::new();
    assert_eq!(r.req(8), (0x11, 0x0011));
    assert!(r.slave.error());
    // without ack: ignored, even a valid request
    assert_eq!(r.req(2), (0x11, 0x0011));
    assert_eq!(r.slave.state(), AlState::Init);
    // with ack: error cleared and request processed
    assert_eq!(r.req(0x12), (2, 0));
    assert_eq!(r.slave.al_status_code(), AlStatusCode::NO_ERROR);
}

#[test]
fn e021_poll_reports_state_changes() {
    let mut r = Rig::new();
    r.esc.request(2);
    let c = r.poll().unwrap();
    assert_eq!(
        (c.from, c.to, c.code),
        (AlState::Init, AlState::PreOp, AlStatusCode(0))
    );
    r.esc.request(2);
    assert_eq!(r.poll(), None);
    r.esc.request(8);
    let c = r.poll().unwrap();
    assert_eq!((c.from, c.to, c.code.0), (AlState::PreOp, AlState::PreOp, 0x11));
    assert_eq!(
        std::format!("{c}"),
        "PreOp: request 8 refused, AL status code 0x0011"
    );
}

#[test]
fn e025_invalid_mailbox_sm_stays_init() {
    let cases: [(u8, u16, u16, u8, bool); 7] = [
        (0, 0x1004, 128, 0x26, true),  // wrong start
        (0, 0x1000, 256, 0x26, true),  // longer than the SII's
        (0, 0x1000, 8, 0x26, true),    // too short
        (0, 0x1000, 128, 0x22, true),  // wrong direction
        (1, 0x1080, 128, 0x20, true),  // buffered mode
        (1, 0x1080, 128, 0x22, false), // not enabled
        (1, 0x1080, 128, 0x27, true),  // reserved direction
    ];
    for (n, start, len, control, enable) in cases {
        let mut r = Rig::new();
        r.esc.set_sm(n, start, len, control);
        if !enable {
            r.esc.mem[regs::sm(n) as usize + 6] = 0;
        }
        assert_eq!(r.req(2), (0x11, 0x0016), "SM{n} {start:#x} {len} {control:#x}");
        assert_eq!(r.slave.state(), AlState::Init);
    }
    // a shorter, still sane mailbox is accepted
    let mut r = Rig::new();
    r.esc.set_sm(1, 0x1080, 64, 0x22);
    assert_eq!(r.req(2), (2, 0));
}

#[test]
fn e028_e045_process_sm_checks() {
    let cases: [(u8, u16, u16, u8, u16); 9] = [
        (2, 0x1100, 4, 0x64, 0x001D), // RxPDO length mismatch
        (2, 0x1100, 3, 0x66, 0x001D), // mailbox mode
        (2, 0x1100, 3, 0x60, 0x001D), // MasterRead direction
        (2, 0x0F00, 3, 0x64, 0x001D), // outside process RAM
        (2, 0x2FFC, 3, 0x64, 0x001D), // 3 buffers run past the RAM end
        (3, 0x1180, 2, 0x20, 0x001E), // TxPDO length mismatch
        (3, 0x1180, 4, 0x24, 0x001E), // MasterWrite direction
        (2, 0x1100, 3, 0x65, 0x0017), // reserved mode bits
        (3, 0x1104, 4, 0x20, 0x0017), // SM3 overlaps SM2's three buffers
    ];
    for (n, start, len, control, code) in cases {
        let mut r = Rig::new();
        r.goto(AlState::PreOp);
        r.esc.set_sm(n, start, len, control);
        assert_eq!(r.req(4), (0x12, code), "SM{n} {start:#x} {len} {control:#x}");
        assert_eq!(r.slave.state(), AlState::PreOp);
    }
    // SM2 overlapping the read mailbox
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    r.esc.set_sm(2, 0x10F0, 3, 0x64);
    assert_eq!(r.req(4), (0x12, 0x0017));
    // SM2 disabled while outputs are assigned
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    r.esc.mem[regs::sm(2) as usize + 6] = 0;
    assert_eq!(r.req(4), (0x12, 0x001D));
}

#[test]
fn e032_e034_e035_process_data_by_state() {
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    r.slave.inputs_mut().copy_from_slice(&[1, 2, 3, 4]);
    r.poll();
    assert_eq!(&r.esc.mem[0x1180..0x1184], &[0, 0, 0, 0], "no inputs in Pre-Op");
    r.goto_from_preop_safeop();
    assert_eq!(&r.esc.mem[0x1180..0x1184], &[1, 2, 3, 4], "inputs in Safe-Op");
    // outputs received in Safe-Op are ignored
    r.esc.mem[0x1100..0x1103].copy_from_slice(&[9, 8, 7]);
    r.esc.set_events(al_event::sm(2));
    r.poll();
    assert_eq!(r.slave.outputs(), &[0, 0, 0]);
    assert_eq!(r.slave.outputs_received(), 1);
    assert_eq!(r.req(8), (8, 0));
    assert_eq!(r.slave.outputs(), &[0, 0, 0], "Safe-Op data not carried into Op");
    r.esc.mem[0x1100..0x1103].copy_from_slice(&[5, 6, 7]);
    r.esc.set_events(al_event::sm(2));
    r.poll();
    assert_eq!(r.slave.outputs(), &[5, 6, 7], "outputs applied in Op");
    assert_eq!(r.esc.events() & al_event::sm(2), 0, "whole SM2 area read");
    r.slave.inputs_mut()[0] = 42;
    r.poll();
    assert_eq!(r.esc.mem[0x1180], 42);
    assert_eq!(r.req(4), (4, 0));
    assert_eq!(r.slave.outputs(), &[0, 0, 0], "O->S falls back to defaults");
    assert_eq!(r.req(2), (2, 0));
    r.slave.inputs_mut()[0] = 43;
    r.poll();
    assert_eq!(r.esc.mem[0x1180], 42, "S->P stops inputs");
}

impl Rig {
    fn goto_from_preop_safeop(&mut self) {
        assert_eq!(self.req(4), (4, 0));
    }
}

#[test]
fn e027_sdo_upload_and_download_through_mailbox() {
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    let resp = r.upload(0x1008, 0, 1).unwrap();
    assert_eq!(resp.len(), 128);
    // header: length 10, CoE, counter 1
    assert_eq!(&resp[..6], &[10, 0, 0, 0, 0, 0x13]);
    assert_eq!(
        &resp[6..16],
        &[0x00, 0x30, 0x43, 0x08, 0x10, 0x00, b'T', b'e', b's', b't']
    );
    assert!(resp[16..].iter().all(|&b| b == 0));
    // expedited download 2 bytes
    r.esc.mbx_write(&[
        10, 0, 0, 0, 0, 0x23, 0x00, 0x20, 0x2B, 0x00, 0x20, 0x00, 0x34, 0x12, 0, 0,
    ]);
    r.poll();
    let resp = r.esc.mbx_read().unwrap();
    assert_eq!(
        &resp[..16],
        &[10, 0, 0, 0, 0, 0x23, 0x00, 0x30, 0x60, 0x00, 0x20, 0x00, 0, 0, 0, 0]
    );
    assert_eq!(r.app.value, 0x1234);
}

#[test]
fn e037_no_mailbox_in_init() {
    let mut r = Rig::new();
    assert!(r.upload(0x1008, 0, 1).is_none());
    assert_ne!(r.esc.events() & al_event::sm(0), 0, "SM0 not read in Init");
    // P->I drops the mailbox again
    r.goto(AlState::PreOp);
    assert!(r.upload(0x1008, 0, 2).is_some());
    assert_eq!(r.req(1), (1, 0));
    assert!(r.upload(0x1008, 0, 3).is_none());
}

#[test]
fn mailbox_counter_cycles_and_duplicates_are_dropped() {
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    let mut counters = Vec::new();
    for i in 0..9u8 {
        let resp = r.upload(0x1008, 0, i % 7 + 1).unwrap();
        counters.push(resp[5] >> 4);
    }
    assert_eq!(counters, [1, 2, 3, 4, 5, 6, 7, 1, 2]);
    // same counter again (request repeated by the master): no reply
    assert!(r.upload(0x1008, 0, 2).is_none());
    // counter 0 is never a duplicate
    assert!(r.upload(0x1008, 0, 0).is_some());
    assert!(r.upload(0x1008, 0, 0).is_some());
}

#[test]
fn mailbox_error_replies() {
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    // SoE is not handled: unsupported protocol
    r.esc.mbx_write(&[4, 0, 0, 0, 0, 0x15, 0, 0, 0, 0]);
    r.poll();
    let resp = r.esc.mbx_read().unwrap();
    assert_eq!(&resp[..10], &[4, 0, 0, 0, 0, 0x10, 0x01, 0x00, 0x02, 0x00]);
    // length beyond the mailbox: invalid size
    r.esc.mbx_write(&[200, 0, 0, 0, 0, 0x23, 0, 0, 0, 0]);
    r.poll();
    let resp = r.esc.mbx_read().unwrap();
    assert_eq!(&resp[..10], &[4, 0, 0, 0, 0, 0x20, 0x01, 0x00, 0x08, 0x00]);
    // CoE frame too short for an SDO: size too short
    r.esc.mbx_write(&[4, 0, 0, 0, 0, 0x33, 0x00, 0x20, 0x40, 0x00]);
    r.poll();
    let resp = r.esc.mbx_read().unwrap();
    assert_eq!(&resp[6..10], &[0x01, 0x00, 0x06, 0x00]);
}

#[test]
fn mailbox_waits_for_sm1_empty_and_holds_next_request() {
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    r.esc.mbx_write(&[
        10, 0, 0, 0, 0, 0x13, 0x00, 0x20, 0x40, 0x00, 0x20, 0x00, 0, 0, 0, 0,
    ]);
    r.poll();
    assert!(r.esc.sm1_full());
    // the master has not read SM1 yet: the next response stays pending
    r.esc.mbx_write(&[
        10, 0, 0, 0, 0, 0x23, 0x00, 0x20, 0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0,
    ]);
    r.poll();
    let first = r.esc.mbx_read().unwrap();
    assert_eq!(first[5] >> 4, 1);
    assert_eq!(&first[9..11], &[0x00, 0x20]);
    r.poll();
    let second = r.esc.mbx_read().unwrap();
    assert_eq!(second[5] >> 4, 2);
    assert_eq!(&second[9..11], &[0x08, 0x10]);
    // a third request held back while a response is pending is served later
    r.esc.mbx_write(&[
        10, 0, 0, 0, 0, 0x33, 0x00, 0x20, 0x40, 0x00, 0x20, 0x00, 0, 0, 0, 0,
    ]);
    r.esc.mem[regs::sm(1) as usize + 5] |= status::MAILBOX_FULL;
    r.poll(); // response pending, SM1 "full"
    r.esc.mbx_write(&[
        10, 0, 0, 0, 0, 0x43, 0x00, 0x20, 0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0,
    ]);
    r.poll();
    assert_ne!(
        r.esc.events() & al_event::sm(0),
        0,
        "SM0 left full while a response is pending"
    );
    assert_eq!(r.esc.mbx_read().unwrap()[5] >> 4, 2, "stale content");
    r.poll();
    assert_eq!(r.esc.mbx_read().unwrap()[5] >> 4, 3);
    r.poll();
    assert_eq!(r.esc.mbx_read().unwrap()[5] >> 4, 4);
}

#[test]
fn mailbox_repeat_rewrites_last_response() {
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    let first = r.upload(0x1008, 0, 1).unwrap();
    // the master lost it and toggles the repeat bit
    r.esc.mem[regs::sm(1) as usize + 6] ^= activate::REPEAT;
    r.poll();
    assert_eq!(r.esc.mbx_read().unwrap(), first);
    assert_ne!(r.esc.mem[regs::sm(1) as usize + 7] & pdi_control::REPEAT_ACK, 0);
    // no further repeat: nothing new
    r.poll();
    assert!(r.esc.mbx_read().is_none());
    // toggling back is a second repeat request
    r.esc.mem[regs::sm(1) as usize + 6] ^= activate::REPEAT;
    r.poll();
    assert_eq!(r.esc.mbx_read().unwrap(), first);
    assert_eq!(r.esc.mem[regs::sm(1) as usize + 7] & pdi_control::REPEAT_ACK, 0);
}

#[test]
fn e080_od_list_fragments_through_the_mailbox() {
    let mut r = Rig::with(&DEV_INFO);
    r.goto(AlState::PreOp);
    // Get OD List, all objects: 2 + 2 * 150 bytes, 116 per fragment (SM1 128) -> 3 fragments
    r.esc.mbx_write(&[
        8, 0, 0, 0, 0, 0x13, 0x00, 0x80, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00,
    ]);
    r.poll();
    let mut indices = Vec::new();
    let mut frames = Vec::new();
    for _ in 0..3 {
        let resp = r.esc.mbx_read().expect("a fragment");
        // the master has not read yet: nothing new is written
        frames.push(resp);
        r.poll();
    }
    for (i, f) in frames.iter().enumerate() {
        let len = u16::from_le_bytes([f[0], f[1]]) as usize;
        assert_eq!(f[5], 0x03 | ((i as u8 + 1) << 4), "CoE, counters 1, 2, 3");
        assert_eq!(&f[6..8], &[0x00, 0x80]);
        let left = 2 - i as u16;
        assert_eq!(f[8], if left > 0 { 0x82 } else { 0x02 });
        assert_eq!(u16::from_le_bytes([f[10], f[11]]), left);
        let data = &f[12..6 + len];
        let data = if i == 0 {
            assert_eq!(&data[..2], &[1, 0]);
            &data[2..]
        } else {
            data
        };
        indices.extend(data.chunks(2).map(|c| u16::from_le_bytes([c[0], c[1]])));
    }
    assert_eq!(
        indices,
        (0..MANY_N as u16).map(|i| 0x3000 + i).collect::<Vec<_>>()
    );
    assert!(r.esc.mbx_read().is_none(), "no fourth fragment");
    // the next request is served normally
    let resp = r.upload(0x1008, 0, 2).unwrap();
    assert_eq!(&resp[6..9], &[0x00, 0x30, 0x43]);
}

#[test]
fn e079_no_sdo_info_without_the_coe_detail() {
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    r.esc.mbx_write(&[
        8, 0, 0, 0, 0, 0x13, 0x00, 0x80, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00,
    ]);
    r.poll();
    let resp = r.esc.mbx_read().unwrap();
    // mailbox error: service not supported
    assert_eq!(&resp[..10], &[4, 0, 0, 0, 0, 0x10, 0x01, 0x00, 0x04, 0x00]);
}

#[test]
fn e029_e030_sync_mode_and_free_run_check() {
    use crate::esm::{check_free_run, sync_mode, SyncMode};
    assert_eq!(sync_mode(0x03, Some(0)), Ok(SyncMode::DcSync0), "0x0981 wins");
    assert_eq!(
        sync_mode(0x01, Some(0)),
        Ok(SyncMode::FreeRun),
        "cyclic unit without SYNC0"
    );
    assert_eq!(sync_mode(0, Some(1)), Ok(SyncMode::SmSync));
    assert_eq!(sync_mode(0, Some(2)), Ok(SyncMode::DcSync0));
    assert_eq!(sync_mode(0, None), Ok(SyncMode::SmSync));
    assert_eq!(sync_mode(0, Some(3)), Err(AlStatusCode::INVALID_DC_SYNC_CONFIG));
    let sm = |control| esc::SyncManager {
        start: 0x1100,
        length: 3,
        control,
        status: 0,
        activate: activate::ENABLE,
        pdi_control: 0,
    };
    assert_eq!(
        check_free_run(SyncMode::FreeRun, &sm(0x66), 3),
        Err(AlStatusCode::FREERUN_NEEDS_3BUFFER)
    );
    assert_eq!(check_free_run(SyncMode::FreeRun, &sm(0x64), 3), Ok(()));
    assert_eq!(check_free_run(SyncMode::SmSync, &sm(0x66), 3), Ok(()));
    assert_eq!(
        check_free_run(SyncMode::FreeRun, &sm(0x66), 0),
        Ok(()),
        "no outputs"
    );
}

#[test]
fn e031_e127_watchdog_check_and_pdo_monitor() {
    use crate::esm::{check_watchdog, pdo_monitor, EscWatchdog, PdoMonitor};
    use crate::PdoTimeout::{EscWatchdog as Esc, LostFrames, Ms, Off};
    let wd = EscWatchdog {
        divider: 2498,
        pd_time: 1000,
        sm2_trigger: true,
    };
    let bad = Err(AlStatusCode::INVALID_WATCHDOG_CONFIG);
    assert_eq!(wd.time(), Some(Nanos::from_ms(100)));
    assert_eq!(check_watchdog(Off, &wd, 1_000_000, 23), Ok(()));
    assert_eq!(
        check_watchdog(Off, &EscWatchdog { divider: 0, ..wd }, 1_000_000, 23),
        bad
    );
    assert_eq!(
        check_watchdog(Off, &EscWatchdog { pd_time: 0, ..wd }, 1_000_000, 23),
        Ok(())
    );
    assert_eq!(
        check_watchdog(Esc, &EscWatchdog { pd_time: 0, ..wd }, 1_000_000, 23),
        bad
    );
    let no_trigger = EscWatchdog {
        sm2_trigger: false,
        ..wd
    };
    assert_eq!(check_watchdog(Esc, &no_trigger, 1_000_000, 23), bad);
    assert_eq!(
        check_watchdog(Esc, &EscWatchdog { pd_time: 5, ..wd }, 1_000_000, 23),
        bad
    );
    assert_eq!(check_watchdog(Esc, &wd, 1_000_000, 23), Ok(()));
    assert_eq!(
        check_watchdog(Esc, &EscWatchdog { pd_time: 0, ..wd }, 1_000_000, 0),
        Ok(())
    );

    assert_eq!(pdo_monitor(Off, 1_000_000, &wd), None);
    assert_eq!(pdo_monitor(Ms(0), 1_000_000, &wd), None);
    assert_eq!(
        pdo_monitor(Ms(1), 1_000_000, &wd),
        Some(PdoMonitor::Timeout(Nanos::from_ns(1_000_000)))
    );
    assert_eq!(
        pdo_monitor(Ms(65531), 1_000_000, &wd),
        Some(PdoMonitor::Timeout(Nanos::from_ns(65_531_000_000)))
    );
    assert_eq!(
        pdo_monitor(LostFrames(1), 1_000_000, &wd),
        Some(PdoMonitor::Timeout(Nanos::from_ns(2_500_000)))
    );
    assert_eq!(
        pdo_monitor(LostFrames(3), 1_000_000, &wd),
        Some(PdoMonitor::Timeout(Nanos::from_ns(4_500_000)))
    );
    assert_eq!(
        pdo_monitor(Esc, 1_000_000, &wd),
        Some(PdoMonitor::EscWatchdog(Nanos::from_ns(100_000_000)))
    );
    assert_eq!(
        pdo_monitor(Esc, 1_000_000, &EscWatchdog { pd_time: 0, ..wd }),
        None
    );
}

#[test]
fn e038_unsolicited_change_displays() {
    let c = StateChange {
        from: AlState::Op,
        to: AlState::SafeOp,
        requested: 8,
        code: AlStatusCode::SM_WATCHDOG,
        unsolicited: true,
    };
    assert_eq!(
        std::format!("{c}"),
        "Op -> SafeOp (unsolicited, AL status code 0x001b)"
    );
}

#[test]
fn e046_e131_e038_dc_sync_state_gates_op_and_faults_in_op() {
    use crate::esm::{SyncMode, SyncState};
    let waiting = |code: u16| SyncState {
        required: true,
        ready: Err(AlStatusCode(code)),
        fault: None,
    };
    let locked = SyncState {
        required: true,
        ready: Ok(()),
        fault: None,
    };

    // SM-Sync: the sync state is not consulted
    let mut r = Rig::new();
    r.slave.set_sync_state(waiting(0x002D));
    r.goto(AlState::Op);

    // DC SYNC0 (0x0981 = 3, 1 ms = A150)
    let mut r = Rig::new();
    r.esc.mem[regs::dc::ACTIVATION as usize] = 0x03;
    let c0 = regs::dc::SYNC0_CYCLE as usize;
    r.esc.mem[c0..c0 + 4].copy_from_slice(&1_000_000u32.to_le_bytes());
    r.goto(AlState::SafeOp);
    assert_eq!(r.slave.sync_status().mode, SyncMode::DcSync0);
    // S→O waits (no error) while there is no SYNC0 / no lock …
    r.slave.set_sync_state(waiting(0x002D));
    assert_eq!(r.req(8), (4, 0));
    assert!(r.slave.op_pending());
    r.slave.set_sync_state(waiting(0x0032));
    r.poll();
    assert_eq!((r.esc.status(), r.esc.code()), (4, 0));
    // … and is granted once locked
    r.slave.set_sync_state(locked);
    let c = r.poll().expect("granted");
    assert_eq!((c.to, c.unsolicited), (AlState::Op, false));
    assert_eq!(r.esc.status(), 8);

    // a sync fault in Op: Safe-Op + error + its code, EMCY 7500h cause 7, unsolicited
    r.slave.set_sync_state(SyncState {
        required: true,
        ready: Err(AlStatusCode(0x0034)),
        fault: Some(AlStatusCode(0x0034)),
    });
    assert_eq!(r.slave.run_led(), crate::led::Pattern::On);
    assert_eq!(r.slave.err_led(), crate::led::Pattern::Off);
    assert_eq!(r.slave.take_op_loss(), None, "nothing raised in Op yet");
    let c = r.poll().expect("dropped");
    assert!(c.unsolicited);
    assert_eq!(
        (c.from, c.to, c.code),
        (AlState::Op, AlState::SafeOp, AlStatusCode(0x0034))
    );
    // the application learns the cause once (its event, EMCY and fault reaction, E-129)
    assert_eq!(r.slave.take_op_loss(), Some(crate::esm::OpLoss::Sync));
    assert_eq!(r.slave.take_op_loss(), None);
    assert_eq!(r.slave.run_led(), crate::led::Pattern::SingleFlash);
    assert_eq!(r.slave.err_led(), crate::led::Pattern::SingleFlash, "unsolicited");
    assert_eq!((r.esc.status(), r.esc.code()), (0x14, 0x0034));
    assert!(r.slave.sync_status().unsolicited);
    assert!(!r.slave.sync_status().triggered, "not a PDO timeout (A259)");
    // the event and its EMCY are the application's: the slave sends none
    r.poll();
    assert_eq!(r.esc.mbx_read(), None, "no EMCY from the slave itself");
    // no second drop while in Safe-Op; a request without acknowledge is ignored
    assert_eq!(r.poll(), None);
    assert_eq!(r.req(8), (0x14, 0x0034));
    assert!(!r.slave.take_error_ack());
    // acknowledge + Op: waits for the application to clear the fault and relock
    assert_eq!(r.req(0x18), (4, 0));
    assert!(r.slave.take_error_ack());
    assert!(!r.slave.take_error_ack(), "reported once");
    assert!(r.slave.op_pending());
    r.slave.set_sync_state(locked);
    r.poll();
    assert_eq!(r.esc.status(), 8);

    // no lock within 200 ms: refused with the sync code
    assert_eq!(r.req(4), (4, 0));
    r.slave.set_sync_state(waiting(0x0032));
    assert_eq!(r.req(8), (4, 0));
    for _ in 0..200 {
        r.poll();
    }
    assert_eq!((r.esc.status(), r.esc.code()), (4, 0), "still waiting at 200 ms");
    r.poll();
    assert_eq!(
        (r.esc.status(), r.esc.code()),
        (0x14, 0x0032),
        "refused after 200 ms"
    );
}

/// The application's Ethernet side for the EoE tests.
#[derive(Default)]
struct Port {
    received: Vec<Vec<u8>>,
    to_send: Vec<Vec<u8>>,
    ip_changes: usize,
}

impl crate::eoe::EthernetPort for Port {
    fn receive(&mut self, frame: &[u8]) {
        self.received.push(frame.to_vec());
    }
    fn transmit(&mut self, buf: &mut [u8]) -> Option<usize> {
        if self.to_send.is_empty() {
            return None;
        }
        let f = self.to_send.remove(0);
        buf[..f.len()].copy_from_slice(&f);
        Some(f.len())
    }
    fn ip_changed(&mut self, _: &crate::eoe::IpParams) {
        self.ip_changes += 1;
    }
}

impl Rig {
    fn poll_eth(&mut self, port: &mut Port) {
        self.t += Nanos::from_ms(1);
        let Ok(_) = self.slave.poll_with_eoe(
            &mut self.esc,
            &mut self.app,
            &mut crate::foe::NoFiles,
            port,
            self.t,
        );
    }
    /// Sends one EoE mailbox message (`eoe`: EoE header + data) with `counter`.
    fn eoe(&mut self, port: &mut Port, eoe: &[u8], counter: u8) -> Option<Vec<u8>> {
        let mut req = Vec::from((eoe.len() as u16).to_le_bytes());
        req.extend_from_slice(&[0, 0, 0, 0x02 | (counter << 4)]);
        req.extend_from_slice(eoe);
        self.esc.mbx_write(&req);
        self.poll_eth(port);
        self.esc.mbx_read()
    }
}

/// A test frame of `n` bytes.
fn eth_frame(n: usize) -> Vec<u8> {
    (0..n).map(|i| (i * 13 + 1) as u8).collect()
}

/// EoE fragments of `f` in `chunk`-byte pieces (EoE header + data each).
fn eoe_fragments(f: &[u8], chunk: usize, frame_no: u8) -> Vec<Vec<u8>> {
    crate::eoe::tests::fragments(f, chunk, frame_no)
        .into_iter()
        .map(|(h, c)| {
            let mut m = h.to_bytes().to_vec();
            m.extend_from_slice(&c);
            m
        })
        .collect()
}

/// A set-IP request in the fixed layout, addresses as little-endian
/// UINT32s (the first octet last), as TwinCAT sends it.
fn set_ip_request(ip: [u8; 4]) -> Vec<u8> {
    let le = |a: [u8; 4]| [a[3], a[2], a[1], a[0]];
    let mut b = Vec::from([0x02u8, 0x01, 0, 0]);
    b.extend_from_slice(&0x0Eu32.to_le_bytes()); // IP, mask, gateway
    b.extend_from_slice(&[0; 6]);
    b.extend_from_slice(&le(ip));
    b.extend_from_slice(&le([255, 255, 255, 0]));
    b.extend_from_slice(&le([10, 0, 0, 1]));
    b.extend_from_slice(&[0; 36]);
    b
}

/// A get-IP-parameter request (EoE header only): the master shows that
/// it uses EoE.
const GET_IP: [u8; 4] = [0x06, 0x01, 0x00, 0x00];

#[test]
fn e095_eoe_frames_in_preop_safeop_op_not_in_init() {
    let mut r = Rig::new();
    let mut port = Port::default();
    let f = eth_frame(300);
    // Init: no mailbox at all
    assert!(r.eoe(&mut port, &eoe_fragments(&f, 96, 1)[0], 1).is_none());
    assert_ne!(r.esc.events() & al_event::sm(0), 0, "SM0 not read in Init");
    r.esc.set_events(0);
    let mut counter = 0;
    for (k, state) in [AlState::PreOp, AlState::SafeOp, AlState::Op]
        .into_iter()
        .enumerate()
    {
        r.goto(state);
        for m in eoe_fragments(&f, 96, k as u8) {
            counter = counter % 7 + 1;
            assert!(
                r.eoe(&mut port, &m, counter).is_none(),
                "fragments have no response"
            );
        }
        assert_eq!(port.received.len(), k + 1, "{state:?}");
        assert_eq!(port.received[k], f);
        assert_eq!(r.req(1), (1, 0));
    }
    assert_eq!(r.slave.eoe().stats().frames_received, 3);
    assert_eq!(r.slave.eoe().stats().frames_dropped, 0);
}

#[test]
fn e095_eoe_out_of_order_fragment_drops_the_frame() {
    let mut r = Rig::new();
    let mut port = Port::default();
    r.goto(AlState::PreOp);
    let frags = eoe_fragments(&eth_frame(300), 96, 3);
    r.eoe(&mut port, &frags[0], 1);
    r.eoe(&mut port, &frags[2], 2);
    r.eoe(&mut port, &frags[3], 3);
    assert!(port.received.is_empty());
    assert_eq!(r.slave.eoe().stats().frames_dropped, 2);
    // the next frame arrives whole
    for (i, m) in frags.iter().enumerate() {
        r.eoe(&mut port, m, (i % 7 + 4) as u8 % 8);
    }
    assert_eq!(port.received.len(), 1);
}

#[test]
fn e095_eoe_frames_to_the_master_one_fragment_per_mailbox() {
    let mut r = Rig::new();
    let mut port = Port::default();
    r.goto(AlState::PreOp);
    let resp = r.eoe(&mut port, &GET_IP, 1).unwrap();
    assert_eq!(resp[6], 0x07, "get IP response");
    let f = eth_frame(400);
    port.to_send.push(f.clone());
    port.to_send.push(eth_frame(60));
    let mut got = crate::eoe::Reassembly::new();
    let mut frames = Vec::new();
    let mut messages = 0;
    for _ in 0..20 {
        r.poll_eth(&mut port);
        if let Some(m) = r.esc.mbx_read() {
            messages += 1;
            let len = usize::from(u16::from_le_bytes([m[0], m[1]]));
            assert_eq!(m[5] & 0x0F, 2, "EoE");
            assert!(len <= 128 - 6);
            let h = crate::eoe::EoeHeader::parse(&m[6..]).unwrap();
            if let Some(n) = got.push(&h, &m[10..6 + len]).unwrap() {
                frames.push(got.frame()[..n].to_vec());
            }
        }
    }
    // 118 data bytes per mailbox: 96 + 96 + 96 + 112, and one for the 60-byte frame
    assert_eq!(messages, 5);
    assert_eq!(frames, [f, eth_frame(60)]);
    assert_eq!(r.slave.eoe().stats().frames_sent, 2);
    // leaving for Init drops a frame in transmission
    port.to_send.push(eth_frame(400));
    r.poll_eth(&mut port);
    assert!(r.slave.eoe().sending());
    r.esc.request(1);
    r.poll_eth(&mut port);
    assert!(!r.slave.eoe().sending());
}

/// SDO upload request of 1008h with `counter`, written into SM0.
fn upload_request(counter: u8) -> [u8; 16] {
    [
        10,
        0,
        0,
        0,
        0,
        0x03 | (counter << 4),
        0x00,
        0x20,
        0x40,
        0x08,
        0x10,
        0,
        0,
        0,
        0,
        0,
    ]
}

#[test]
fn e098_no_unasked_eoe_before_the_master_uses_eoe() {
    let mut r = Rig::new();
    let mut port = Port::default();
    r.goto(AlState::PreOp);
    // the IP stack has frames to send (a DHCP DISCOVER, say) from the start
    port.to_send.extend((0..4).map(|_| eth_frame(300)));
    // a master that speaks only CoE: every answer is its SDO response
    for k in 0..2000u32 {
        let counter = (k % 7 + 1) as u8;
        r.esc.mbx_write(&upload_request(counter));
        r.poll_eth(&mut port);
        let m = r.esc.mbx_read().expect("an answer to each upload");
        assert_eq!(
            m[5],
            0x03 | (counter << 4),
            "request {k}: CoE with the request's counter"
        );
        assert_eq!(m[8] >> 5, 2, "request {k}: SDO upload response");
        // and nothing else between the requests
        r.poll_eth(&mut port);
        assert_eq!(r.esc.mbx_read(), None, "request {k}: no unasked message");
    }
    assert_eq!(port.to_send.len(), 4, "not one frame taken");
    assert!(!r.slave.eoe().master_active());
    // the master uses EoE: the frames go out
    r.eoe(&mut port, &GET_IP, 1).unwrap();
    assert!(r.slave.eoe().master_active());
    let mut eoe = 0;
    for _ in 0..40 {
        r.poll_eth(&mut port);
        if let Some(m) = r.esc.mbx_read() {
            assert_eq!(m[5] & 0x0F, 2, "EoE");
            eoe += 1;
        }
    }
    assert!(eoe >= 4, "{eoe} EoE messages");
    assert!(port.to_send.is_empty());
    // back through Init: silent again until the master uses EoE again
    assert_eq!(r.req(1), (1, 0));
    r.goto(AlState::PreOp);
    assert!(!r.slave.eoe().master_active());
    port.to_send.push(eth_frame(100));
    for _ in 0..20 {
        r.poll_eth(&mut port);
        assert_eq!(r.esc.mbx_read(), None);
    }
}

#[test]
fn e096_e097_e093_set_ip_through_the_mailbox() {
    let mut r = Rig::new();
    let mut port = Port::default();
    r.goto(AlState::PreOp);
    let resp = r.eoe(&mut port, &set_ip_request([10, 0, 0, 7]), 1).unwrap();
    // mailbox: 4 bytes EoE, set IP response, last fragment, result 0
    assert_eq!(&resp[..10], &[4, 0, 0, 0, 0, 0x12, 0x03, 0x01, 0x00, 0x00]);
    assert_eq!(r.slave.eoe().params().ip, Some([10, 0, 0, 7]));
    assert_eq!(r.slave.eoe().params().gateway, Some([10, 0, 0, 1]));
    assert_eq!(port.ip_changes, 1);
    // E-097: the last address of the subnet is refused, EMCY FFF0h/23h follows
    let resp = r.eoe(&mut port, &set_ip_request([10, 0, 0, 255]), 2).unwrap();
    assert_eq!(&resp[6..10], &[0x03, 0x01, 0x01, 0x00]);
    assert_eq!(r.slave.eoe().params().ip, Some([10, 0, 0, 7]));
    r.poll_eth(&mut port);
    let emcy = r.esc.mbx_read().unwrap();
    assert_eq!(emcy[5] & 0x0F, 3, "CoE");
    assert_eq!(&emcy[6..11], &[0x00, 0x10, 0xF0, 0xFF, 0x23]);
    // the first address too
    let resp = r.eoe(&mut port, &set_ip_request([10, 0, 0, 0]), 3).unwrap();
    assert_eq!(&resp[8..10], &[0x01, 0x00]);
    assert_eq!(port.ip_changes, 1);
}

#[test]
fn e095_eoe_unsupported_without_the_sii_protocol() {
    static NO_EOE: Device = Device {
        mailbox_protocols: mailbox_protocol::COE,
        ..DEV_DESC
    };
    let mut r = Rig::with(&NO_EOE);
    let mut port = Port::default();
    r.goto(AlState::PreOp);
    let resp = r.eoe(&mut port, &set_ip_request([10, 0, 0, 7]), 1).unwrap();
    assert_eq!(&resp[..10], &[4, 0, 0, 0, 0, 0x10, 0x01, 0x00, 0x02, 0x00]);
}

/// E-027/E-037 with the stack split over two tasks: `poll_esc` (AL control,
/// process data) never touches the mailbox, `poll_mailbox_only` serves it,
/// and together they answer like `poll`.
#[test]
fn e027_e037_mailbox_served_by_its_own_task() {
    let mut r = Rig::new();
    let split = |r: &mut Rig, mailbox: bool| {
        r.t += Nanos::from_ms(1);
        let Ok(c) = r.slave.poll_esc(&mut r.esc, &mut r.app, r.t);
        if mailbox {
            let Ok(()) = r.slave.poll_mailbox_only(
                &mut r.esc,
                &mut r.app,
                &mut crate::foe::NoFiles,
                &mut crate::eoe::NoEthernet,
                r.t,
            );
        }
        c
    };
    // AL control through the ESC part alone
    r.esc.request(2);
    let c = split(&mut r, false);
    assert_eq!(c.map(|c| c.to), Some(AlState::PreOp));
    assert_eq!(r.esc.status(), 2);
    // a request waits in SM0 while only the ESC part runs
    r.esc
        .mbx_write(&[10, 0, 0, 0, 0, 0x13, 0x00, 0x20, 0x40, 0x08, 0x10, 0, 0, 0, 0, 0]);
    for _ in 0..3 {
        split(&mut r, false);
        assert!(r.esc.mbx_read().is_none());
        assert_ne!(r.esc.events() & al_event::sm(0), 0, "SM0 read by the ESC part");
    }
    // the mailbox part answers it
    split(&mut r, true);
    let resp = r.esc.mbx_read().unwrap();
    assert_eq!(&resp[6..12], &[0x00, 0x30, 0x43, 0x08, 0x10, 0x00]);
    // back in Init the mailbox part serves nothing (E-037)
    r.esc.request(1);
    split(&mut r, true);
    r.esc
        .mbx_write(&[10, 0, 0, 0, 0, 0x23, 0x00, 0x20, 0x40, 0x08, 0x10, 0, 0, 0, 0, 0]);
    split(&mut r, true);
    assert!(r.esc.mbx_read().is_none());
}

mod esm_requests;
