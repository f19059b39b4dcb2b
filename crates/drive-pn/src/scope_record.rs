//! The drive's scope on PROFINET (group T, issue 35): the recorder of
//! [`drive_core::scope`] in the drive's records.
//!
//! - Configured, armed and watched through the parameter access, as every
//!   other object: T00…T10 by PKW or record 0xB02E, PNU = the object's index
//!   (T00 = 4600h … T10 = 460Ah). T11, the trace in 4 KiB elements, is
//!   beyond what a parameter value carries (PKW: 4 bytes, 0xB02E: 240) and
//!   is refused there.
//! - Read out through records [`SCOPE_RECORD`]…[`SCOPE_RECORD`] + 63 (at
//!   any slot and subslot of the AR, like 0xB02E): record `SCOPE_RECORD + k`
//!   holds bytes k · [`PIECE_BYTES`]… of the complete trace, sample by
//!   sample, channel by channel, 32 bits little-endian each (T11's layout),
//!   the last piece as long as the rest of the trace. 64 pieces of 1 KiB
//!   read the 64 KiB T11 holds. A piece's response fits one UDP datagram
//!   on a 1500-byte Ethernet (80 bytes of RPC header, 64 of the read
//!   response's), so a controller that does not reassemble RPC fragments
//!   (profinet-py) reads it as well as one that does.
//! - Bad input: a read before the trace is complete answers "state
//!   conflict" (0xB5), never the last trace's samples as new ones; a piece
//!   beyond the trace's end "invalid range" (0xB7); a write "access
//!   denied" (0xB6). In normal mode reading the last piece arms the next
//!   trace, as reading T11's last element does on EtherCAT.
//!
//! The recorder lives in the record hook ([`WithScope`]) so that a record
//! read is answered in its own RPC response; [`crate::PnDrive`] samples it
//! after each control cycle and hands it to the parameter access as the
//! provider of group T ([`drive_core::LiveValues`]). Without a buffer
//! ([`crate::PnDrive::attach_scope`] not called) group T answers "not in
//! this state" and the records "invalid index", as on a drive without one.

use crate::PnDrive;
use drive_core::axis::AxisIo;
use drive_core::scope::Recorder;
use drive_core::LiveValues;
use od::SdoAbort;
use profinet::cm::{RecordAddr, RecordError, RecordHook};
use store::Flash;

/// The scope as the drive holds it: the recorder over a buffer handed over
/// once (a RAM bank of its own on the board, leaked memory in the
/// simulator).
pub type Scope = Recorder<&'static mut [u32]>;

/// The first trace record (user-specific record range, 0000h…7FFFh).
pub const SCOPE_RECORD: u16 = 0x4700;
/// Trace records: `SCOPE_RECORD`…`SCOPE_RECORD + PIECES − 1`.
pub const PIECES: u16 = 64;
/// Bytes of the trace one record holds.
pub const PIECE_BYTES: usize = 1024;

/// The scope's records in front of the other records `H`.
#[derive(Debug, Default)]
pub struct WithScope<H: RecordHook> {
    /// The recorder, once the shell handed a buffer over.
    pub scope: Option<Scope>,
    /// The other records.
    pub inner: H,
}

/// Group T through the drive's scope when it has one, else answered as by
/// a drive without a recorder.
impl<H: RecordHook> LiveValues for WithScope<H> {
    fn read(&mut self, index: u16, sub: u8, buf: &mut [u8]) -> Option<Result<usize, SdoAbort>> {
        LiveValues::read(self.scope.as_mut()?, index, sub, buf)
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        match self.scope.as_mut() {
            Some(s) => LiveValues::write(s, index, sub, data),
            None => Ok(()),
        }
    }

    fn provide(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        match self.scope.as_mut() {
            Some(s) => LiveValues::provide(s, index, sub, data),
            None => Err(SdoAbort::DEVICE_STATE),
        }
    }
}

/// The piece a record index names, if it is a trace record.
fn piece(index: u16) -> Option<usize> {
    let k = index.checked_sub(SCOPE_RECORD)?;
    (k < PIECES).then_some(usize::from(k))
}

impl<H: RecordHook> RecordHook for WithScope<H> {
    fn read(&mut self, addr: RecordAddr, out: &mut [u8]) -> Result<usize, RecordError> {
        match (piece(addr.index), self.scope.as_mut()) {
            (Some(k), Some(scope)) => scope.read_piece(k, PIECE_BYTES, out).map_err(|e| match e {
                SdoAbort::DEVICE_STATE => RecordError::StateConflict,
                SdoAbort::NO_DATA => RecordError::InvalidRange,
                _ => RecordError::ReadError,
            }),
            _ => self.inner.read(addr, out),
        }
    }

    fn write(&mut self, addr: RecordAddr, data: &[u8]) -> Result<(), RecordError> {
        match (piece(addr.index), &self.scope) {
            (Some(_), Some(_)) => Err(RecordError::AccessDenied),
            _ => self.inner.write(addr, data),
        }
    }
}

impl<F: Flash, H: RecordHook> PnDrive<F, H> {
    /// Gives the drive its scope (group T, [`crate::scope_record`]) over `words`
    /// (a RAM bank of its own on the board; a trace holds at most
    /// `words.len()` 32-bit samples). Once: a second call keeps the first
    /// buffer and returns `false`.
    pub fn attach_scope(&mut self, words: &'static mut [u32]) -> bool {
        let slot = &mut self.device.hook_mut().inner.inner.scope;
        if slot.is_some() {
            return false;
        }
        *slot = Some(drive_core::scope::Recorder::new(words));
        true
    }

    /// The scope's buffer back, the scope gone (before the drive is
    /// dropped: the simulator's restart gives it to the next drive).
    pub fn detach_scope(&mut self) -> Option<&'static mut [u32]> {
        self.device
            .hook_mut()
            .inner
            .inner
            .scope
            .take()
            .map(|s| s.into_storage())
    }

    /// The scope, once attached ([`attach_scope`](Self::attach_scope)).
    pub fn scope(&self) -> Option<&Scope> {
        self.device.hook().inner.inner.scope.as_ref()
    }

    /// After the control cycle: the scope's sample of the cycle just run
    /// (the objects and both axes' internal signals on the inputs `io`);
    /// one branch while it does not record.
    pub(crate) fn sample_scope(&mut self, io: &[AxisIo; 2]) {
        if let Some(scope) = self.device.hook_mut().inner.inner.scope.as_mut() {
            let axes = &self.axes;
            scope.sample(&self.objects, || {
                let ([a, b], [ia, ib]) = (axes, io);
                let s = drive_core::scope::Signals::of;
                [s(a, ia), s(b, ib)]
            });
        }
    }
}
