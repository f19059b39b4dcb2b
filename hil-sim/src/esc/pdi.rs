//! The firmware's side of the simulated ESC: [`esc::Pdi`] on the ESC itself
//! and on [`EscPdi`], the handle the drive's poll gets.

use super::*;

impl Pdi for Esc {
    type Error = Infallible;

    fn read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Infallible> {
        self.access(Side::Pdi, u32::from(addr), buf, Op::Read);
        Ok(())
    }

    fn write(&mut self, addr: u16, data: &[u8]) -> Result<(), Infallible> {
        // The core access takes a mutable buffer (it reads into it for
        // read-write operations); copy through a stack chunk so the SM
        // handshake sees the whole write at once when it fits.
        let mut chunk = [0u8; PDI_CHUNK];
        let mut off = 0usize;
        while off < data.len() {
            let n = (data.len() - off).min(PDI_CHUNK);
            let (Some(dst), Some(src)) = (chunk.get_mut(..n), data.get(off..off + n)) else {
                break;
            };
            dst.copy_from_slice(src);
            self.access(Side::Pdi, u32::from(addr) + off as u32, dst, Op::Write);
            off += n;
        }
        Ok(())
    }

    fn al_event(&mut self) -> Result<u32, Infallible> {
        self.pdi_touch();
        Ok(self.al_event_request() & self.get_u32(regs::AL_EVENT_MASK))
    }
}

/// Bytes per internal PDI write step (a write longer than this is split; the
/// SyncManager handshake still completes on the last byte).
pub(super) const PDI_CHUNK: usize = 256;

/// A PDI handle on an [`Esc`], as the slave stack holds it.
#[derive(Debug)]
pub struct EscPdi<'a> {
    pub(super) esc: &'a mut Esc,
}

impl Pdi for EscPdi<'_> {
    type Error = Infallible;

    fn read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Infallible> {
        self.esc.read(addr, buf)
    }

    fn write(&mut self, addr: u16, data: &[u8]) -> Result<(), Infallible> {
        self.esc.write(addr, data)
    }

    fn al_event(&mut self) -> Result<u32, Infallible> {
        Pdi::al_event(self.esc)
    }
}
