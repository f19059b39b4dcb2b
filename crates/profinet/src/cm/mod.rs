//! Context management of the IO device: the PNIO calls (Connect, Release,
//! Read, Write, Control) on top of [`crate::rpc`], the blocks they carry, the
//! PNIO status of every refusal, and the established [`Ar`].
//!
//! - [`ndr`]: the NDR argument header and the block header.
//! - [`connect`]: Connect request blocks checked field by field, the
//!   comparison with the real model (ModuleDiffBlock), the response blocks.
//! - [`record`]: IODRead/IODWrite headers, multiple write, I&M0…4, the
//!   [`RecordHook`] for later records.
//! - [`control`]: IODControl (PrmEnd, ApplicationReady) and IODRelease blocks.
//! - [`ar`]: the AR as plain data for the rt and alarm code.
//! - [`status`]: [`PnioStatus`] and [`RecordError`].
//!
//! [`Cm`] is the [`rpc::Handler`] of the PNIO device interface. It holds at
//! most one IOCARSingle and one device-access AR (IOSAR). After the
//! controller's PrmEnd it offers the ApplicationReady call to the RPC client
//! ([`rpc::Handler::request`]); the controller's CControl response puts the
//! AR into [`ArState::Data`]. What the application must act on comes out of
//! [`Cm::poll_event`].

pub mod ar;
pub mod connect;
pub mod control;
pub mod ndr;
pub mod record;
pub mod status;
#[cfg(test)]
pub(crate) mod tests_connect;
#[cfg(test)]
mod tests_pcap;
#[cfg(test)]
mod tests_record;
#[cfg(test)]
mod tests_record_size;
#[cfg(test)]
mod tests_startup;
#[cfg(test)]
pub(crate) use crate::testing::vectors as tests_vectors;

pub use ar::{AlarmCr, Ar, ArState, ArType, Fit, IoObject, Iocr, IocrType, Submodule, SubmoduleData};
pub use record::{Im0, ImData, ImRecord, NoRecords, RecordAddr, RecordHook};
pub use status::{PnioStatus, RecordError};

use heapless::Deque;
use nanos::Nanos;

use crate::alarm::{DiagList, DiagScope};
use crate::pdev::Pdev;
use crate::rpc::cursor::{Endian, Reader, Writer};
use crate::rpc::{self, opnum, uuid::PNIO_CONTROLLER_INTERFACE, Call, CallError, ClientError, Request, Uuid};
use crate::wire::MacAddr;
use connect::{emit_connect_response, emit_module_diff, exists, parse_connect, ConnectContext};
use control::{block_type as cb, command, ControlBlock};
use ndr::{Blocks, NdrRequest, NDR_LEN};
use record::{index, RwRequest, RW_HEADER_LEN};
use status::{cmrpc, error_code as ec, error_code1};

/// What the application has to act on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CmEvent {
    /// An AR was established (Connect answered): configure rt/alarm from [`Cm::ar`].
    Connected(Uuid),
    /// The controller ended the parameterisation; ApplicationReady follows.
    PrmEnd(Uuid),
    /// The controller confirmed ApplicationReady: cyclic data is valid now.
    Ready(Uuid),
    /// The controller released the AR.
    Released(Uuid),
    /// The AR ended otherwise.
    Aborted(Uuid, AbortReason),
    /// An I&M record was written: persist [`Cm::im_data`].
    ImWritten(ImRecord),
}

/// Why an AR ended without a Release.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AbortReason {
    /// The ApplicationReady call failed at the RPC level.
    ApplicationReadyFailed(ClientError),
    /// The controller answered ApplicationReady with an error or a bad block.
    ApplicationReadyRefused(PnioStatus),
    /// A new Connect of the same controller replaced it.
    Superseded,
    /// [`Cm::abort`] (watchdog, alarm timeout, local reasons).
    Local,
}

/// Settings of the CM.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CmConfig {
    /// The interface MAC (CMResponderMacAdd).
    pub mac: MacAddr,
    /// I&M0.
    pub im0: Im0,
}

/// ArgsMaximum of the device's ApplicationReady request.
const CCONTROL_ARGS_MAXIMUM: u32 = 256;

/// The context manager.
#[derive(Debug)]
pub struct Cm<H: RecordHook = NoRecords> {
    config: CmConfig,
    im: ImData,
    hook: H,
    pdev: Pdev,
    /// The device's diagnoses (P-030, P-040): the device raises and clears
    /// them and sends their alarms; the CM serves them as the diagnosis
    /// records 0x800A…0xF00C.
    pub(crate) diag: DiagList<{ crate::device::MAX_DIAGNOSES }>,
    io_ar: Option<Ar>,
    sv_ar: Option<Ar>,
    events: Deque<CmEvent, 8>,
    app_ready_due: Option<Uuid>,
    app_ready_in_flight: Option<Uuid>,
    next_alarm_ref: u16,
}

impl<H: RecordHook> Cm<H> {
    /// A CM with `config`, the stored I&M1…4 `im` and the record `hook`.
    pub fn new(config: CmConfig, im: ImData, hook: H) -> Cm<H> {
        Cm {
            config,
            im,
            hook,
            pdev: Pdev::new(
                config.mac,
                [config.mac; crate::model::PORTS as usize],
                crate::dcp::NameOfStation::EMPTY,
                crate::dcp::IpSuite::UNSET,
            ),
            diag: DiagList::new(),
            io_ar: None,
            sv_ar: None,
            events: Deque::new(),
            app_ready_due: None,
            app_ready_in_flight: None,
            next_alarm_ref: 1,
        }
    }

    /// The IOCARSingle AR, if one is established.
    pub fn ar(&self) -> Option<&Ar> {
        self.io_ar.as_ref()
    }

    /// The device-access (IOSAR) AR, if one is established.
    pub fn supervisor_ar(&self) -> Option<&Ar> {
        self.sv_ar.as_ref()
    }

    /// I&M1…4 as stored now.
    pub fn im_data(&self) -> &ImData {
        &self.im
    }

    /// Replaces I&M1…4 (e.g. cleared by a reset to factory).
    pub fn set_im_data(&mut self, im: ImData) {
        self.im = im;
    }

    /// The record hook.
    pub fn hook(&self) -> &H {
        &self.hook
    }

    /// The record hook, mutable.
    pub fn hook_mut(&mut self) -> &mut H {
        &mut self.hook
    }

    /// The physical device the PDev records report (P-040).
    pub fn pdev(&self) -> &Pdev {
        &self.pdev
    }

    /// The physical device, mutable: the device keeps it current.
    pub fn pdev_mut(&mut self) -> &mut Pdev {
        &mut self.pdev
    }

    /// The next event.
    pub fn poll_event(&mut self) -> Option<CmEvent> {
        self.events.pop_front()
    }

    fn event(&mut self, e: CmEvent) {
        if self.events.is_full() {
            let _ = self.events.pop_front();
        }
        let _ = self.events.push_back(e);
    }

    /// Ends the AR `ar_uuid` (watchdog expiry, alarm timeout, …).
    pub fn abort(&mut self, ar_uuid: Uuid) {
        self.remove(ar_uuid, Some(AbortReason::Local));
    }

    fn remove(&mut self, ar_uuid: Uuid, reason: Option<AbortReason>) {
        let slot = if self.io_ar.as_ref().is_some_and(|a| a.ar_uuid == ar_uuid) {
            &mut self.io_ar
        } else if self.sv_ar.as_ref().is_some_and(|a| a.ar_uuid == ar_uuid) {
            &mut self.sv_ar
        } else {
            return;
        };
        *slot = None;
        if self.app_ready_due == Some(ar_uuid) {
            self.app_ready_due = None;
        }
        if self.app_ready_in_flight == Some(ar_uuid) {
            self.app_ready_in_flight = None;
        }
        self.event(match reason {
            None => CmEvent::Released(ar_uuid),
            Some(r) => CmEvent::Aborted(ar_uuid, r),
        });
    }

    fn find(&self, ar_uuid: Uuid) -> Option<&Ar> {
        [&self.io_ar, &self.sv_ar]
            .into_iter()
            .flatten()
            .find(|a| a.ar_uuid == ar_uuid)
    }

    fn connect(&mut self, call: &Call, args: &[u8], w: &mut Writer<'_>) -> PnioStatus {
        let ctx = ConnectContext {
            peer: call.peer,
            device_alarm_ref: self.next_alarm_ref,
        };
        let ar = match parse_connect(args, &ctx) {
            Ok(ar) => ar,
            Err(s) => return s,
        };
        if self.find(ar.ar_uuid).is_some() {
            return PnioStatus::cmrpc(ec::IOD_CONNECT_RES, cmrpc::STATE_CONFLICT);
        }
        let held = match ar.ar_type {
            ArType::IoCarSingle => &self.io_ar,
            ArType::IoSar => &self.sv_ar,
        };
        if let Some(old) = held {
            if old.controller_mac != ar.controller_mac {
                return PnioStatus::cmrpc(ec::IOD_CONNECT_RES, cmrpc::OUT_OF_AR_RESOURCES);
            }
            let old = old.ar_uuid;
            self.remove(old, Some(AbortReason::Superseded));
        }
        if emit_connect_response(w, &ar, self.config.mac, self.pdev.name.as_bytes()).is_none() {
            return PnioStatus::cmrpc(ec::IOD_CONNECT_RES, cmrpc::OUT_OF_RESOURCES);
        }
        self.next_alarm_ref = self.next_alarm_ref.wrapping_add(1).max(1);
        let id = ar.ar_uuid;
        match ar.ar_type {
            ArType::IoCarSingle => self.io_ar = Some(ar),
            ArType::IoSar => {
                self.sv_ar = Some(Ar {
                    state: ArState::Data,
                    ..ar
                });
            }
        }
        self.event(CmEvent::Connected(id));
        PnioStatus::OK
    }

    fn control_block(args: &[u8], code: u8, code1: u8, want: u16) -> Result<ControlBlock, PnioStatus> {
        let mut blocks = Blocks::new(args);
        let blk = match blocks.next_block() {
            Some(Ok(b)) => b,
            _ => return Err(PnioStatus::cmrpc(code, cmrpc::ARGS_LENGTH_INVALID)),
        };
        if blk.block_type != want {
            return Err(PnioStatus::cmrpc(code, cmrpc::UNKNOWN_BLOCKS));
        }
        ControlBlock::parse(&blk, code, code1)
    }

    fn check_ar(&self, c: &ControlBlock, code: u8, code1: u8) -> Result<Ar, PnioStatus> {
        let ar = self
            .find(c.ar_uuid)
            .ok_or(PnioStatus::cmrpc(code, cmrpc::AR_UUID_UNKNOWN))?;
        if c.session_key != ar.session_key {
            return Err(PnioStatus::pnio(code, code1, 6));
        }
        if c.properties != 0 {
            return Err(PnioStatus::pnio(code, code1, 9));
        }
        Ok(ar.clone())
    }

    fn release(&mut self, args: &[u8], w: &mut Writer<'_>) -> PnioStatus {
        let (code, code1) = (ec::IOD_RELEASE_RES, error_code1::RELEASE_BLOCK);
        let c = match Self::control_block(args, code, code1, cb::RELEASE_REQ) {
            Ok(c) => c,
            Err(s) => return s,
        };
        if let Err(s) = self.check_ar(&c, code, code1) {
            return s;
        }
        if c.command != command::RELEASE {
            return PnioStatus::pnio(code, code1, 8);
        }
        let res = ControlBlock {
            command: command::DONE,
            ..c
        };
        if res.emit(w, cb::RELEASE_RES).is_none() {
            return PnioStatus::cmrpc(code, cmrpc::OUT_OF_RESOURCES);
        }
        self.remove(c.ar_uuid, None);
        PnioStatus::OK
    }

    fn control(&mut self, args: &[u8], w: &mut Writer<'_>) -> PnioStatus {
        let (code, code1) = (ec::IOD_CONTROL_RES, error_code1::CONTROL_BLOCK_CONNECT);
        let c = match Self::control_block(args, code, code1, cb::PRM_END_REQ) {
            Ok(c) => c,
            Err(s) => return s,
        };
        let ar = match self.check_ar(&c, code, code1) {
            Ok(a) => a,
            Err(s) => return s,
        };
        if c.command != command::PRM_END {
            return PnioStatus::pnio(code, code1, 8);
        }
        if ar.ar_type != ArType::IoCarSingle || ar.state != ArState::Parameterising {
            return PnioStatus::cmrpc(code, cmrpc::STATE_CONFLICT);
        }
        let res = ControlBlock {
            command: command::DONE,
            ..c
        };
        if res.emit(w, cb::PRM_END_RES).is_none() {
            return PnioStatus::cmrpc(code, cmrpc::OUT_OF_RESOURCES);
        }
        if let Some(a) = &mut self.io_ar {
            a.state = ArState::ApplicationReadyPending;
        }
        self.app_ready_due = Some(c.ar_uuid);
        self.event(CmEvent::PrmEnd(c.ar_uuid));
        PnioStatus::OK
    }

    fn read_record(
        &mut self,
        ar: Option<&Ar>,
        addr: RecordAddr,
        out: &mut [u8],
    ) -> Result<usize, RecordError> {
        if addr.api != 0 {
            return Err(RecordError::InvalidApi);
        }
        if let Some((scope, filter)) = DiagScope::for_record(addr.index, addr.api, addr.slot, addr.subslot) {
            diag_scope_exists(scope, addr)?;
            return self
                .diag
                .write_record(scope, filter, out)
                .map_err(|_| RecordError::ReadError);
        }
        let mut w = Writer::new(out, Endian::Big);
        match addr.index {
            index::IM0..=index::IM4 => {
                if (addr.slot, addr.subslot) != (0, 1) {
                    return Err(if exists(addr.slot, addr.subslot) {
                        RecordError::InvalidIndex
                    } else {
                        RecordError::InvalidSlotSubslot
                    });
                }
                let ok = if addr.index == index::IM0 {
                    record::emit_im0(&mut w, &self.config.im0)
                } else {
                    record::emit_im(&mut w, addr.index, &self.im)
                };
                ok.ok_or(RecordError::ReadError)?;
                Ok(w.pos())
            }
            index::REAL_IDENTIFICATION_DATA => {
                if !exists(addr.slot, addr.subslot) {
                    return Err(RecordError::InvalidSlotSubslot);
                }
                connect::emit_real_identification(&mut w, ar).ok_or(RecordError::ReadError)?;
                Ok(w.pos())
            }
            index::IM0_FILTER_DATA => {
                // device scope: at any submodule there is
                if !exists(addr.slot, addr.subslot) {
                    return Err(RecordError::InvalidSlotSubslot);
                }
                record::emit_im0_filter(&mut w).ok_or(RecordError::ReadError)?;
                Ok(w.pos())
            }
            index::MODULE_DIFF => {
                let ar = ar.ok_or(RecordError::StateConflict)?;
                emit_module_diff(&mut w, ar).ok_or(RecordError::ReadError)?;
                Ok(w.pos())
            }
            i if Pdev::serves(i) => self.pdev.read(addr, out),
            _ => self.hook.read(addr, out),
        }
    }

    fn read(&mut self, call: &Call, args: &[u8], w: &mut Writer<'_>) -> PnioStatus {
        let code = ec::IOD_READ_RES;
        let Some((req, _)) = RwRequest::parse(args).filter(|(r, _)| !r.write) else {
            return PnioStatus::pnio(code, error_code1::RECORD, 0);
        };
        let ar = if call.opnum == opnum::READ_IMPLICIT {
            None
        } else {
            match self.find(req.ar_uuid) {
                Some(a) => Some(a.clone()),
                None => {
                    // refused with the header that names the record (an
                    // answer without blocks is malformed to Wireshark)
                    let _ = record::emit_read_res(w, &req, 0);
                    return PnioStatus::cmrpc(code, cmrpc::AR_UUID_UNKNOWN);
                }
            }
        };
        // the whole header or nothing: an answer never ends in half a block
        if w.rest_mut().len() < RW_HEADER_LEN {
            return PnioStatus::cmrpc(code, cmrpc::OUT_OF_RESOURCES);
        }
        let at = w.pos();
        if record::emit_read_res(w, &req, 0).is_none() {
            return PnioStatus::cmrpc(code, cmrpc::OUT_OF_RESOURCES);
        }
        // The record follows the header: at most RecordDataLength bytes and what
        // is left of ArgsMaximum (the writer's end).
        let limit = usize::try_from(req.record_len).unwrap_or(usize::MAX);
        let (status, n) = match self.read_record(ar.as_ref(), req.addr, w.rest_mut()) {
            Ok(n) => (PnioStatus::OK, n.min(limit)),
            Err(e) => (e.status(code), 0),
        };
        let n = w.advance(n);
        let _ = w.patch_u32(at + 36, u32::try_from(n).unwrap_or(0));
        status
    }

    fn write_one(&mut self, addr: RecordAddr, data: &[u8]) -> Result<(), RecordError> {
        if addr.api != 0 {
            return Err(RecordError::InvalidApi);
        }
        if let Some((scope, _)) = DiagScope::for_record(addr.index, addr.api, addr.slot, addr.subslot) {
            diag_scope_exists(scope, addr)?;
            return Err(RecordError::AccessDenied);
        }
        match addr.index {
            index::IM0..=index::IM4 if (addr.slot, addr.subslot) != (0, 1) => {
                Err(if exists(addr.slot, addr.subslot) {
                    RecordError::InvalidIndex
                } else {
                    RecordError::InvalidSlotSubslot
                })
            }
            index::IM0 | index::MODULE_DIFF | index::IM0_FILTER_DATA | index::REAL_IDENTIFICATION_DATA => {
                Err(RecordError::AccessDenied)
            }
            index::IM1..=index::IM4 => {
                let rec = record::write_im(addr.index, data, &mut self.im)?;
                self.event(CmEvent::ImWritten(rec));
                Ok(())
            }
            i if Pdev::serves(i) => self.pdev.write(addr, data),
            _ => self.hook.write(addr, data),
        }
    }

    /// The number of sub-writes of a multiple write as [`Cm::write_multiple`]
    /// walks them; `None` if one is malformed. Checked before any sub-write
    /// is done, so that a refused multiple write changes nothing.
    fn count_writes(data: &[u8], depth: u8) -> Option<usize> {
        let mut r = Reader::new(data, Endian::Big);
        let mut n = 0usize;
        while r.remaining() > 0 {
            let (req, sub) = next_write(&mut r)?;
            n = n.checked_add(if req.addr.index == index::WRITE_MULTIPLE && depth == 0 {
                Self::count_writes(sub, 1)?
            } else {
                1
            })?;
        }
        Some(n)
    }

    /// The sub-writes of a multiple write (`depth` 0 for the outer one). A
    /// multiple write nested inside one (as profinet-py 0.6.6 sends) is
    /// flattened once; deeper nesting is refused. Each sub-write is done on
    /// its own and answered with its own status; `failed` keeps the first
    /// refusal's status (the outer status of the IODWriteMultipleRes).
    fn write_multiple(
        &mut self,
        data: &[u8],
        w: &mut Writer<'_>,
        depth: u8,
        failed: &mut Option<PnioStatus>,
    ) -> Option<()> {
        let mut r = Reader::new(data, Endian::Big);
        while r.remaining() > 0 {
            let (req, sub) = next_write(&mut r)?;
            if req.addr.index == index::WRITE_MULTIPLE && depth == 0 {
                self.write_multiple(sub, w, 1, failed)?;
                continue;
            }
            let status = if req.addr.index == index::WRITE_MULTIPLE {
                RecordError::InvalidIndex.status(ec::IOD_WRITE_RES)
            } else if sub.len() > crate::model::MAX_RECORD_SIZE {
                RecordError::WriteLength.status(ec::IOD_WRITE_RES)
            } else {
                match self.write_one(req.addr, sub) {
                    Ok(()) => PnioStatus::OK,
                    Err(e) => e.status(ec::IOD_WRITE_RES),
                }
            };
            if !status.is_ok() && failed.is_none() {
                *failed = Some(status);
            }
            record::emit_write_res(w, &req, req.record_len, status)?;
        }
        Some(())
    }

    fn write(&mut self, args: &[u8], w: &mut Writer<'_>) -> PnioStatus {
        let code = ec::IOD_WRITE_RES;
        let Some((req, rest)) = RwRequest::parse(args).filter(|(r, _)| r.write) else {
            // the answer still carries an IODWriteResHeader (all zero: the
            // request's is unreadable), as Wireshark and controllers expect
            let s = PnioStatus::pnio(code, error_code1::RECORD, 0);
            let _ = record::emit_write_res(w, &UNKNOWN_WRITE, 0, s);
            return s;
        };
        if self.find(req.ar_uuid).is_none() {
            let s = PnioStatus::cmrpc(code, cmrpc::AR_UUID_UNKNOWN);
            let _ = record::emit_write_res(w, &req, req.record_len, s);
            return s;
        }
        // room for the answer's header (and, below, each sub-write's) before
        // anything is written: a write refused for want of room changes nothing
        if w.rest_mut().len() < RW_HEADER_LEN {
            return PnioStatus::cmrpc(code, cmrpc::OUT_OF_RESOURCES);
        }
        let len = usize::try_from(req.record_len).unwrap_or(usize::MAX);
        // A record above MaxSupportedRecordSize (a multiple write may be
        // longer by its sub-headers), or a request cut short because it did
        // not fit the RPC buffer: write length error, with the header.
        let too_long = req.addr.index != index::WRITE_MULTIPLE && len > crate::model::MAX_RECORD_SIZE;
        let Some(data) = rest.get(..len).filter(|_| rest.len() == len && !too_long) else {
            let s = RecordError::WriteLength.status(code);
            let _ = record::emit_write_res(w, &req, req.record_len, s);
            return s;
        };
        if req.addr.index == index::WRITE_MULTIPLE {
            let Some(n) = Self::count_writes(data, 0) else {
                // a sub-header that does not parse or a sub-record running
                // past the end: the outer header with "write length error"
                let s = RecordError::WriteLength.status(code);
                let _ = record::emit_write_res(w, &req, req.record_len, s);
                return s;
            };
            let room = n.checked_add(1).and_then(|k| k.checked_mul(RW_HEADER_LEN));
            if room.is_none_or(|r| w.rest_mut().len() < r) {
                return PnioStatus::cmrpc(code, cmrpc::OUT_OF_RESOURCES);
            }
            let at = w.pos();
            if record::emit_write_res(w, &req, 0, PnioStatus::OK).is_none() {
                return PnioStatus::cmrpc(code, cmrpc::OUT_OF_RESOURCES);
            }
            let body = w.pos();
            let mut failed = None;
            if self.write_multiple(data, w, 0, &mut failed).is_none() {
                return PnioStatus::pnio(code, error_code1::RECORD, 0);
            }
            let n = w.pos().saturating_sub(body);
            let _ = w.patch_u32(at + 36, u32::try_from(n).unwrap_or(0));
            // A refused sub-write makes the whole answer an error: the outer
            // header and the NDR status carry the first refusal's status
            // (its own header names it); the good sub-writes stay done with
            // status OK in theirs.
            let status = failed.unwrap_or(PnioStatus::OK);
            let _ = w.patch_u32(at + 44, u32::from_be_bytes(status.to_bytes()));
            return status;
        }
        let status = match self.write_one(req.addr, data) {
            Ok(()) => PnioStatus::OK,
            Err(e) => e.status(code),
        };
        if record::emit_write_res(w, &req, req.record_len, status).is_none() {
            return PnioStatus::cmrpc(code, cmrpc::OUT_OF_RESOURCES);
        }
        status
    }
}

/// The next sub-write of a multiple write at `r`: its header and its record
/// data; `r` moves past both and the padding to 4 bytes.
fn next_write<'a>(r: &mut Reader<'a>) -> Option<(RwRequest, &'a [u8])> {
    let (req, rest) = RwRequest::parse(r.rest()).filter(|(q, _)| q.write)?;
    let len = usize::try_from(req.record_len).ok()?;
    let sub = rest.get(..len)?;
    r.skip(RW_HEADER_LEN.checked_add(len)?)?;
    r.align(4).or(Some(()))?;
    Some((req, sub))
}

fn service(op: u16) -> u8 {
    match op {
        opnum::CONNECT => ec::IOD_CONNECT_RES,
        opnum::RELEASE => ec::IOD_RELEASE_RES,
        opnum::READ | opnum::READ_IMPLICIT => ec::IOD_READ_RES,
        opnum::WRITE => ec::IOD_WRITE_RES,
        _ => ec::IOD_CONTROL_RES,
    }
}

/// The request an IODWriteRes names when the write's own header could not
/// be read: every field zero.
const UNKNOWN_WRITE: RwRequest = RwRequest {
    write: true,
    seq: 0,
    ar_uuid: Uuid([0; 16]),
    addr: RecordAddr {
        api: 0,
        slot: 0,
        subslot: 0,
        index: 0,
    },
    record_len: 0,
    target_ar_uuid: Uuid([0; 16]),
};

/// A diagnosis record's submodule (0x800x) or slot (0xC00x) must exist
/// ("invalid slot/subslot" else); the AR's (0xE00x) and the API's (0xF00x)
/// are the device's whole list: it has one AR.
fn diag_scope_exists(scope: DiagScope, addr: RecordAddr) -> Result<(), RecordError> {
    let there = match scope {
        DiagScope::Subslot { .. } => exists(addr.slot, addr.subslot),
        // every slot there is has a subslot 1
        DiagScope::Slot { .. } => exists(addr.slot, 1),
        DiagScope::Ar | DiagScope::Api { .. } => true,
    };
    if there {
        Ok(())
    } else {
        Err(RecordError::InvalidSlotSubslot)
    }
}

impl<H: RecordHook> rpc::Handler for Cm<H> {
    fn call(&mut self, _now: Nanos, call: &Call, body: &[u8], out: &mut [u8]) -> Result<usize, CallError> {
        let too_big = CallError::Fault(rpc::nca::OUT_ARGS_TOO_BIG);
        let ndr = if call.truncated {
            NdrRequest::parse_truncated(body, call.endian)
        } else {
            NdrRequest::parse(body, call.endian)
        };
        let Some(ndr) = ndr else {
            let s = PnioStatus::cmrpc(service(call.opnum), cmrpc::ARGS_LENGTH_INVALID);
            // a write is answered with an IODWriteResHeader even when its NDR
            // header does not parse (nothing of the request known: all zero),
            // as Wireshark and controllers expect of an IODWriteRes (issue 32)
            let len = if call.opnum == opnum::WRITE {
                let args_out = out.get_mut(NDR_LEN..).ok_or(too_big)?;
                let mut w = Writer::new(args_out, Endian::Big);
                record::emit_write_res(&mut w, &UNKNOWN_WRITE, 0, s).ok_or(too_big)?;
                w.pos()
            } else {
                0
            };
            return ndr::emit_response(out, call.endian, s, 0, len).ok_or(too_big);
        };
        let (status, len) = {
            let args_out = out.get_mut(NDR_LEN..).ok_or(too_big)?;
            let max = usize::try_from(ndr.args_maximum)
                .unwrap_or(usize::MAX)
                .min(args_out.len());
            let mut w = Writer::new(args_out.get_mut(..max).ok_or(too_big)?, Endian::Big);
            let status = match call.opnum {
                opnum::CONNECT => self.connect(call, ndr.args, &mut w),
                opnum::RELEASE => self.release(ndr.args, &mut w),
                opnum::READ | opnum::READ_IMPLICIT => self.read(call, ndr.args, &mut w),
                opnum::WRITE => self.write(ndr.args, &mut w),
                opnum::CONTROL => self.control(ndr.args, &mut w),
                _ => return Err(CallError::Reject(rpc::nca::OP_RNG_ERROR)),
            };
            // Read and write answers keep their header (it names the record);
            // other refusals carry no blocks.
            // (a header cut short by a small ArgsMaximum is no header: then
            // the NDR status alone)
            let record = matches!(call.opnum, opnum::READ | opnum::READ_IMPLICIT | opnum::WRITE);
            let keep = if record {
                w.pos() >= RW_HEADER_LEN
            } else {
                status.is_ok()
            };
            (status, if keep { w.pos() } else { 0 })
        };
        ndr::emit_response(out, call.endian, status, ndr.maximum_count, len).ok_or(too_big)
    }

    fn request(&mut self, _now: Nanos, body: &mut [u8]) -> Option<Request> {
        let id = self.app_ready_due?;
        let ar = self
            .io_ar
            .as_ref()
            .filter(|a| a.ar_uuid == id && a.state == ArState::ApplicationReadyPending)?;
        let e = rpc::Server::<0>::CLIENT_ENDIAN;
        let n = {
            let mut w = Writer::new(body.get_mut(NDR_LEN..)?, Endian::Big);
            let c = ControlBlock {
                ar_uuid: ar.ar_uuid,
                session_key: ar.session_key,
                command: command::APPLICATION_READY,
                properties: 0,
            };
            c.emit(&mut w, cb::APP_READY_REQ)?;
            if ar.has_diff() {
                emit_module_diff(&mut w, ar)?;
            }
            w.pos()
        };
        let len = ndr::emit_request(body, e, CCONTROL_ARGS_MAXIMUM, n)?;
        let req = Request {
            peer: ar.controller_rpc,
            object: ar.controller_object,
            interface: PNIO_CONTROLLER_INTERFACE,
            opnum: opnum::CONTROL,
            body_len: len,
        };
        self.app_ready_due = None;
        self.app_ready_in_flight = Some(id);
        Some(req)
    }

    fn response(&mut self, _now: Nanos, result: Result<(Endian, &[u8]), ClientError>) {
        let Some(id) = self.app_ready_in_flight.take() else {
            return;
        };
        let body = match result {
            Ok(b) => b,
            Err(e) => return self.remove(id, Some(AbortReason::ApplicationReadyFailed(e))),
        };
        let refused = |s| Some(AbortReason::ApplicationReadyRefused(s));
        let mut r = Reader::new(body.1, body.0);
        let status = r.u32().map(PnioStatus::from_u32);
        let bad = PnioStatus::cmrpc(ec::IOD_CONTROL_RES, cmrpc::ARGS_LENGTH_INVALID);
        match status {
            Some(s) if s.is_ok() => {}
            Some(s) => return self.remove(id, refused(s)),
            None => return self.remove(id, refused(bad)),
        }
        let args = body.1.get(NDR_LEN..).unwrap_or(&[]);
        let c = Self::control_block(
            args,
            ec::IOD_CONTROL_RES,
            error_code1::CONTROL_BLOCK_CONNECT,
            cb::APP_READY_RES,
        );
        match c {
            Ok(c) if c.ar_uuid == id && c.command & command::DONE != 0 => {
                if let Some(a) = self.io_ar.as_mut().filter(|a| a.ar_uuid == id) {
                    a.state = ArState::Data;
                    self.event(CmEvent::Ready(id));
                }
            }
            Ok(_) => self.remove(id, refused(bad)),
            Err(s) => self.remove(id, refused(s)),
        }
    }
}
