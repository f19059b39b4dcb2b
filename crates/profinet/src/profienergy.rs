//! PROFIenergy (P-016): the service protocol of record index 0x80A0, as the
//! PROFIenergy profile defines it. The controller writes a service request
//! to the record and reads the response from it; this module checks the
//! request, answers it and keeps the energy-saving state. What pausing means
//! for the product (and whether it may pause now) is the application's
//! ([`PeApplication`]): the PROFINET crate stays drive neutral.
//!
//! Request (record write): BlockHeader (type 0x0800, version 1.0),
//! Service_Request_ID, Request_Reference (1…255), Modifier,
//! Data_Structure_Identifier_RQ, service data. Response (record read):
//! BlockHeader (type 0x0801, 1.0), Service_Request_ID and Request_Reference
//! echoed, Status (1 ready, 2 ready with error), Data_Structure_Identifier_RS,
//! response data; an error carries DSI_RS 0xFF, Error_Code and a reserved
//! octet.
//!
//! | service | ID, modifier | response |
//! |---|---|---|
//! | Start_Pause | 0x01, 0x00; Pause_Time (UINT32 ms) | PE_Mode_ID of the mode entered |
//! | End_Pause | 0x02, 0x00 | Time_to_operate (ms) |
//! | Query_Modes, List_Energy_Saving_Modes | 0x03, 0x01 | number of modes, their IDs |
//! | Query_Modes, Get_Mode | 0x03, 0x02; PE_Mode_ID | the mode's attributes, times and energies |
//! | PEM_Status | 0x04, 0x00 | source and destination mode, times, power and energies |
//! | PE_Identify | 0x05, 0x00 | the service IDs offered (1…5) |
//! | any other (Query_Version, Query_Measurement, …) | | error 0x01 "invalid Service_Request_ID" |
//!
//! The device has one energy-saving mode, [`PAUSE_MODE`] (the application
//! decides what it is), and PE_ready_to_operate ([`READY_TO_OPERATE`]).
//! Start_Pause enters it when the pause time is at least the mode's
//! Time_min_Pause and [`PeApplication::may_pause`] says so (else error 0x53
//! "no switch to energy saving mode because of state operate", or 0x50 "no
//! suitable energy-saving mode" for a short pause); End_Pause, the end of the
//! AR (the controller that paused is gone) and switching PROFIenergy off end
//! the pause. A request that does not parse as a PROFIenergy request gets
//! the profile's errors (0x08 block header, 0x02 request reference, 0x03
//! modifier, 0x04 data structure identifier) in the response; a record
//! shorter than the request header is refused with the PNIO status "write
//! length error" and changes nothing. A read before any request is "state
//! conflict". The response stays readable until the next request.

use heapless::Vec;

use crate::cm::ndr::emit_block;
use crate::cm::{RecordAddr, RecordError, RecordHook};
use crate::rpc::cursor::{Endian, Reader, Writer};

/// The PROFIenergy record index.
pub const INDEX: u16 = 0x80A0;
/// Block type of a service request.
pub const BLOCK_REQUEST: u16 = 0x0800;
/// Block type of a service response.
pub const BLOCK_RESPONSE: u16 = 0x0801;
/// PE_Mode_ID PE_ready_to_operate.
pub const READY_TO_OPERATE: u8 = 0xFF;
/// PE_Mode_ID of the device's one energy-saving mode.
pub const PAUSE_MODE: u8 = 0x01;
/// Where the PE entity is: the DAP's subslot 1 (slot 0).
pub const ENTITY: (u16, u16) = (0, 1);

/// Service_Request_IDs.
pub mod service {
    /// Start_Pause.
    pub const START_PAUSE: u8 = 0x01;
    /// End_Pause.
    pub const END_PAUSE: u8 = 0x02;
    /// Query_Modes.
    pub const QUERY_MODES: u8 = 0x03;
    /// PEM_Status.
    pub const PEM_STATUS: u8 = 0x04;
    /// PE_Identify.
    pub const PE_IDENTIFY: u8 = 0x05;
    /// The services offered (PE_Identify's list).
    pub const OFFERED: [u8; 5] = [START_PAUSE, END_PAUSE, QUERY_MODES, PEM_STATUS, PE_IDENTIFY];
}

/// Error_Codes of a response with Status 2.
pub mod error {
    /// Invalid Service_Request_ID.
    pub const SERVICE: u8 = 0x01;
    /// Bad Request_Reference.
    pub const REFERENCE: u8 = 0x02;
    /// Invalid Modifier.
    pub const MODIFIER: u8 = 0x03;
    /// Invalid Data_Structure_Identifier_RQ.
    pub const DSI_RQ: u8 = 0x04;
    /// Invalid block header.
    pub const BLOCK_HEADER: u8 = 0x08;
    /// No suitable energy-saving mode available.
    pub const NO_SUITABLE_MODE: u8 = 0x50;
    /// Impermissible PE_Mode_ID.
    pub const MODE_ID: u8 = 0x52;
    /// No switch to energy saving mode because of state operate.
    pub const STATE_OPERATE: u8 = 0x53;
}

/// Response Status ready.
const READY: u8 = 0x01;
/// Response Status ready with error.
const READY_WITH_ERROR: u8 = 0x02;
/// Largest response (Get_Mode: 40 bytes after the block's type and length).
pub const MAX_RESPONSE: usize = 48;

/// The times of the energy-saving mode, in ms ([`PeApplication::mode`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ModeTimes {
    /// Time_min_Pause: the shortest pause the mode is worth it for.
    pub min_pause: u32,
    /// Time_to_Pause: from operate to the mode.
    pub to_pause: u32,
    /// Regular_Time_to_operate: from the mode back to operate.
    pub to_operate: u32,
    /// Time_min_length_of_stay.
    pub min_stay: u32,
    /// Time_max_length_of_stay (0xFFFF_FFFF: unlimited).
    pub max_stay: u32,
}

/// What the product decides (the drive personality implements it).
pub trait PeApplication {
    /// PROFIenergy is switched on (the product's parameter). Off: record
    /// 0x80A0 is refused with "invalid index" and a pause ends.
    fn enabled(&self) -> bool;
    /// Whether the product may enter the energy-saving mode now.
    fn may_pause(&self) -> bool;
    /// The times of [`PAUSE_MODE`].
    fn mode(&self) -> ModeTimes;
}

/// The PROFIenergy entity: the pause state and the pending response.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ProfiEnergy {
    paused: bool,
    response: Option<Vec<u8, MAX_RESPONSE>>,
}

/// A service request's fixed header.
struct Request<'a> {
    service: u8,
    reference: u8,
    modifier: u8,
    dsi: u8,
    data: &'a [u8],
}

/// The outcome of one service: response data (DSI_RS and data) or an error code.
type Answer = Result<(u8, Vec<u8, MAX_RESPONSE>), u8>;

fn data(parts: &[&[u8]]) -> Vec<u8, MAX_RESPONSE> {
    let mut v = Vec::new();
    for p in parts {
        // every response fits MAX_RESPONSE
        let _ = v.extend_from_slice(p);
    }
    v
}

impl ProfiEnergy {
    /// Whether the energy-saving mode is in force.
    pub fn paused(&self) -> bool {
        self.paused
    }

    /// Ends a pause (the AR ended, PROFIenergy switched off); `true` if one
    /// ended.
    pub fn end_pause(&mut self) -> bool {
        core::mem::replace(&mut self.paused, false)
    }

    /// Forgets the pending response (a new AR starts afresh).
    pub fn clear_response(&mut self) {
        self.response = None;
    }

    fn check_addr(addr: RecordAddr, app: &impl PeApplication) -> Result<(), RecordError> {
        if addr.index != INDEX || !app.enabled() {
            return Err(RecordError::InvalidIndex);
        }
        if (addr.slot, addr.subslot) == ENTITY {
            Ok(())
        } else if crate::cm::connect::exists(addr.slot, addr.subslot) {
            Err(RecordError::InvalidIndex)
        } else {
            Err(RecordError::InvalidSlotSubslot)
        }
    }

    /// A record write of 0x80A0: the service request. The response waits
    /// for the next read.
    pub fn write(
        &mut self,
        addr: RecordAddr,
        req: &[u8],
        app: &impl PeApplication,
    ) -> Result<(), RecordError> {
        Self::check_addr(addr, app)?;
        let mut r = Reader::new(req, Endian::Big);
        let header = (|| Some((r.u16()?, r.u16()?, r.u8()?, r.u8()?)))();
        let fields = (|| Some((r.u8()?, r.u8()?, r.u8()?, r.u8()?)))();
        let (Some((ty, len, vh, vl)), Some((service, reference, modifier, dsi))) = (header, fields) else {
            return Err(RecordError::WriteLength);
        };
        let request = Request {
            service,
            reference,
            modifier,
            dsi,
            data: r.rest(),
        };
        let answer =
            if ty != BLOCK_REQUEST || (vh, vl) != (1, 0) || usize::from(len) != req.len().saturating_sub(4) {
                Err(error::BLOCK_HEADER)
            } else if reference == 0 {
                Err(error::REFERENCE)
            } else {
                self.serve(&request, app)
            };
        self.response = emit_response(&request, answer);
        Ok(())
    }

    /// A record read of 0x80A0: the response to the last request.
    pub fn read(
        &self,
        addr: RecordAddr,
        out: &mut [u8],
        app: &impl PeApplication,
    ) -> Result<usize, RecordError> {
        Self::check_addr(addr, app)?;
        let resp = self.response.as_ref().ok_or(RecordError::StateConflict)?;
        let dst = out.get_mut(..resp.len()).ok_or(RecordError::ReadError)?;
        dst.copy_from_slice(resp);
        Ok(resp.len())
    }

    fn serve(&mut self, q: &Request<'_>, app: &impl PeApplication) -> Answer {
        let times = app.mode();
        let known = service::OFFERED.contains(&q.service);
        if !known {
            return Err(error::SERVICE);
        }
        let modifier_ok = match q.service {
            service::QUERY_MODES => matches!(q.modifier, 1 | 2),
            _ => q.modifier == 0,
        };
        if !modifier_ok {
            return Err(error::MODIFIER);
        }
        // DSI_RQ and the data length each service carries
        let (dsi, len) = match (q.service, q.modifier) {
            (service::START_PAUSE, _) => (1, 4),
            (service::QUERY_MODES, 2) => (1, 2),
            _ => (0, 0),
        };
        if q.dsi != dsi || q.data.len() != len {
            return Err(error::DSI_RQ);
        }
        let mut r = Reader::new(q.data, Endian::Big);
        match (q.service, q.modifier) {
            (service::START_PAUSE, _) => {
                let pause_time = r.u32().ok_or(error::DSI_RQ)?;
                if !self.paused {
                    if pause_time < times.min_pause {
                        return Err(error::NO_SUITABLE_MODE);
                    }
                    if !app.may_pause() {
                        return Err(error::STATE_OPERATE);
                    }
                    self.paused = true;
                }
                Ok((1, data(&[&[PAUSE_MODE, 0]])))
            }
            (service::END_PAUSE, _) => {
                let t = if self.end_pause() { times.to_operate } else { 0 };
                Ok((1, data(&[&t.to_be_bytes()])))
            }
            (service::QUERY_MODES, 1) => Ok((1, data(&[&[1, PAUSE_MODE]]))),
            (service::QUERY_MODES, _) => {
                if r.u8() != Some(PAUSE_MODE) {
                    return Err(error::MODE_ID);
                }
                let zero = 0f32.to_be_bytes();
                Ok((
                    1,
                    data(&[
                        // PE_Mode_Attributes 0: static times and energies
                        &[PAUSE_MODE, 0],
                        &times.min_pause.to_be_bytes(),
                        &times.to_pause.to_be_bytes(),
                        &times.to_operate.to_be_bytes(),
                        &times.min_stay.to_be_bytes(),
                        &times.max_stay.to_be_bytes(),
                        // power and energies not measured: 0.0
                        &zero,
                        &zero,
                        &zero,
                    ]),
                ))
            }
            (service::PEM_STATUS, _) => {
                let mode = if self.paused { PAUSE_MODE } else { READY_TO_OPERATE };
                let to_operate = if self.paused { times.to_operate } else { 0 };
                let zero = 0f32.to_be_bytes();
                Ok((
                    1,
                    data(&[
                        &[mode, mode],
                        &to_operate.to_be_bytes(),
                        &0u32.to_be_bytes(),
                        &zero,
                        &zero,
                        &zero,
                    ]),
                ))
            }
            _ => {
                let mut d = data(&[&[service::OFFERED.len() as u8]]);
                let _ = d.extend_from_slice(&service::OFFERED);
                Ok((1, d))
            }
        }
    }
}

fn emit_response(q: &Request<'_>, answer: Answer) -> Option<Vec<u8, MAX_RESPONSE>> {
    let mut buf = [0u8; MAX_RESPONSE];
    let mut w = Writer::new(&mut buf, Endian::Big);
    emit_block(&mut w, BLOCK_RESPONSE, |w| {
        w.u8(q.service)?;
        w.u8(q.reference)?;
        match &answer {
            Ok((dsi, d)) => {
                w.u8(READY)?;
                w.u8(*dsi)?;
                w.bytes(d)
            }
            Err(code) => {
                w.u8(READY_WITH_ERROR)?;
                w.u8(0xFF)?;
                w.u8(*code)?;
                w.u8(0)
            }
        }
    })?;
    let n = w.pos();
    Vec::from_slice(buf.get(..n)?).ok()
}

/// A [`RecordHook`] that serves PROFIenergy (record 0x80A0) for the
/// application `A` and hands every other record to `inner`.
#[derive(Debug, Default)]
pub struct WithProfiEnergy<A: PeApplication, H: RecordHook> {
    /// The PROFIenergy entity.
    pub pe: ProfiEnergy,
    /// The product's side.
    pub app: A,
    /// The other records.
    pub inner: H,
}

impl<A: PeApplication, H: RecordHook> RecordHook for WithProfiEnergy<A, H> {
    fn read(&mut self, addr: RecordAddr, out: &mut [u8]) -> Result<usize, RecordError> {
        if addr.index == INDEX {
            self.pe.read(addr, out, &self.app)
        } else {
            self.inner.read(addr, out)
        }
    }

    fn write(&mut self, addr: RecordAddr, data: &[u8]) -> Result<(), RecordError> {
        if addr.index == INDEX {
            self.pe.write(addr, data, &self.app)
        } else {
            self.inner.write(addr, data)
        }
    }
}

#[cfg(test)]
#[path = "profienergy_tests.rs"]
mod tests;
