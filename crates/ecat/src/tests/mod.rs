//! Slave tests against a fake ESC: plain memory, AL control read clears AL event
//! bit 0, reading the last byte of SM0/SM2 clears their event bit, writing the
//! last byte of SM1 sets its MAILBOX_FULL status bit.
//!
//! Here: the test device, the fake ESC and the rig; the tests, by topic, in the submodules.

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

mod eoe;
mod esm;
mod esm_requests;
mod mailbox;
mod sync;

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
