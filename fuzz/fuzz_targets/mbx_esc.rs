//! The part of an ESC the slave's mailbox task sees, for the mailbox
//! targets: SM0 (master → slave, 0x1000) and SM1 (slave → master, 0x1100),
//! 256 bytes each, with their "mailbox full" status and the SM0 event in
//! the AL event request register, as ETG.1000.4 describes a mailbox
//! SyncManager:
//! - the master writes a request: SM0 is full, event SM0 is raised;
//! - the slave reads SM0's last byte: SM0 is empty, the event cleared;
//! - the slave writes SM1's last byte: SM1 is full (a read by the master
//!   empties it; while full, the slave's writes are not taken).
//!
//! The drive's firmware (slave stack, CoE, EoE, FoE, dictionary) runs
//! unchanged behind it, without the simulated line and its byte-by-byte
//! ESC model, so an input costs the firmware's work only.

use esc::regs;

/// SM0 buffer start (master → slave).
pub const SM0: u16 = 0x1000;
/// SM1 buffer start (slave → master).
pub const SM1: u16 = 0x1100;
/// Size of each mailbox buffer.
pub const LEN: usize = 256;
const FULL: u8 = esc::sm::status::MAILBOX_FULL;

/// Registers 0x0000..0x1200: the SM registers as the master set them at
/// I→P, the two buffers.
#[derive(Clone)]
pub struct MailboxEsc {
    mem: Vec<u8>,
    /// An AL control write the slave has not read yet (the AL control event).
    al_control: bool,
}

impl MailboxEsc {
    /// SM0/SM1 configured and activated as [`crate::common::build_preop_line`] does.
    pub fn new() -> Self {
        let mut mem = vec![0u8; usize::from(SM1) + LEN];
        for (n, start, control) in [(0u8, SM0, 0x26u8), (1, SM1, 0x22)] {
            let sm = esc::SyncManager {
                start,
                length: LEN as u16,
                control,
                status: 0,
                activate: 1,
                pdi_control: 0,
            };
            let at = usize::from(regs::sm(n));
            mem[at..at + 8].copy_from_slice(&sm.to_bytes());
        }
        Self { mem, al_control: false }
    }

    /// The master writes AL control (0x0120): the AL control event is
    /// raised until the slave reads the register.
    #[allow(dead_code)] // the foe target's
    pub fn master_al_control(&mut self, value: u16) {
        let at = usize::from(regs::AL_CONTROL);
        self.mem[at..at + 2].copy_from_slice(&value.to_le_bytes());
        self.al_control = true;
    }

    fn status(&mut self, n: u8) -> &mut u8 {
        &mut self.mem[usize::from(regs::sm(n)) + 5]
    }

    /// The master writes a mailbox request into SM0: `false` (working
    /// counter 0) while SM0 is still full.
    pub fn master_write(&mut self, request: &[u8; LEN]) -> bool {
        if *self.status(0) & FULL != 0 {
            return false;
        }
        let at = usize::from(SM0);
        self.mem[at..at + LEN].copy_from_slice(request);
        *self.status(0) |= FULL;
        true
    }

    /// The master reads SM1: the answer, if SM1 is full (it is empty then).
    pub fn master_read(&mut self) -> Option<[u8; LEN]> {
        if *self.status(1) & FULL == 0 {
            return None;
        }
        *self.status(1) &= !FULL;
        let at = usize::from(SM1);
        let mut out = [0u8; LEN];
        out.copy_from_slice(&self.mem[at..at + LEN]);
        Some(out)
    }
}

impl esc::Pdi for MailboxEsc {
    type Error = core::convert::Infallible;

    fn read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Self::Error> {
        let a = usize::from(addr);
        let end = a + buf.len();
        if a == usize::from(regs::AL_EVENT_REQUEST) && buf.len() <= 4 {
            let sm0 = if *self.status(0) & FULL != 0 { regs::al_event::sm(0) } else { 0 };
            let al = if self.al_control { regs::al_event::AL_CONTROL } else { 0 };
            buf.copy_from_slice(&(sm0 | al).to_le_bytes()[..buf.len()]);
            return Ok(());
        }
        if a == usize::from(regs::AL_CONTROL) {
            self.al_control = false;
        }
        for (i, b) in buf.iter_mut().enumerate() {
            *b = self.mem.get(a + i).copied().unwrap_or(0);
        }
        let last = usize::from(SM0) + LEN - 1;
        if a <= last && last < end {
            *self.status(0) &= !FULL;
        }
        Ok(())
    }

    fn write(&mut self, addr: u16, data: &[u8]) -> Result<(), Self::Error> {
        let a = usize::from(addr);
        let end = a + data.len();
        let (b0, b1) = (usize::from(SM1), usize::from(SM1) + LEN);
        if a < b1 && end > b0 && *self.status(1) & FULL != 0 {
            return Ok(()); // a full mailbox takes no writes from its writer
        }
        for (i, b) in data.iter().enumerate() {
            // the slave only writes SM1 and the PDI control bytes
            if let Some(m) = self.mem.get_mut(a + i) {
                *m = *b;
            }
        }
        if a < b1 && b1 <= end {
            *self.status(1) |= FULL;
        }
        Ok(())
    }
}
