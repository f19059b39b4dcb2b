//! Connect: the request blocks (ARBlockReq, IOCRBlockReq, AlarmCRBlockReq,
//! ExpectedSubmoduleBlockReq) checked field by field — a refusal names the
//! block and the field and changes nothing —, the comparison of the expected
//! submodules with the real model, and the response blocks (ARBlockRes,
//! IOCRBlockRes, AlarmCRBlockRes, ModuleDiffBlock).

use heapless::Vec;

use super::ar::*;
use super::ndr::{emit_block, emit_block_v, Block, BlockError, Blocks};
use super::status::{cmrpc, error_code, error_code1 as b, PnioStatus};
use crate::ip::Endpoint;
use crate::model::{self, DataModule, Direction};
use crate::rpc::cursor::{Endian, Reader, Writer};
use crate::rpc::Uuid;
use crate::wire::MacAddr;

/// Block types of the Connect.
pub mod block_type {
    /// ARBlockReq.
    pub const AR_REQ: u16 = 0x0101;
    /// IOCRBlockReq.
    pub const IOCR_REQ: u16 = 0x0102;
    /// AlarmCRBlockReq.
    pub const ALARM_CR_REQ: u16 = 0x0103;
    /// ExpectedSubmoduleBlockReq.
    pub const EXPECTED_SUBMODULE_REQ: u16 = 0x0104;
    /// ARBlockRes.
    pub const AR_RES: u16 = 0x8101;
    /// IOCRBlockRes.
    pub const IOCR_RES: u16 = 0x8102;
    /// AlarmCRBlockRes.
    pub const ALARM_CR_RES: u16 = 0x8103;
    /// ModuleDiffBlock.
    pub const MODULE_DIFF: u16 = 0x8104;
    /// ARServerBlockRes (advanced startup).
    pub const AR_SERVER_RES: u16 = 0x8106;
}

/// The largest alarm payload the device takes and sends.
pub const MAX_ALARM_DATA_LENGTH: u16 = 200;
/// EtherType the CRs must use (RT over Ethernet; RT over UDP is not offered).
const LT_PROFINET: u16 = 0x8892;
/// Base of the FrameIDs the device assigns (output CR: 0xC100 + reference,
/// input CR: 0xC200 + reference, low byte of the reference).
pub const ASSIGNED_FRAME_ID_BASE: u16 = 0xC100;
/// The same for RTClass 2 IOCRs (advanced startup): 0x8100 + reference
/// (output CR), 0x8200 + reference (input CR).
pub const ASSIGNED_FRAME_ID_BASE_RT_CLASS_2: u16 = 0x8100;

/// The unicast FrameIDs of an RTClass: 0xC000…0xF7FF for RTClass 1 (legacy
/// startup), 0x8000…0xBBFF for RTClass 2 (advanced startup; RT_CLASS_1
/// frames in the former RT_CLASS_2 numbering), IEC 61158-6-10.
pub fn frame_ids(rt_class: u8) -> core::ops::RangeInclusive<u16> {
    match rt_class {
        2 => 0x8000..=0xBBFF,
        _ => 0xC000..=0xF7FF,
    }
}

/// Field reader of one block: a short body is a BlockLength error (field 1).
struct F<'a> {
    r: Reader<'a>,
    block: u8,
}

impl<'a> F<'a> {
    fn new(blk: &Block<'a>, block: u8) -> Result<F<'a>, PnioStatus> {
        if blk.version_high != 1 {
            return Err(PnioStatus::connect(block, 2));
        }
        if blk.version_low != 0 {
            return Err(PnioStatus::connect(block, 3));
        }
        Ok(F {
            r: Reader::new(blk.body, Endian::Big),
            block,
        })
    }
    fn short(&self) -> PnioStatus {
        PnioStatus::connect(self.block, 1)
    }
    fn u8(&mut self) -> Result<u8, PnioStatus> {
        self.r.u8().ok_or(self.short())
    }
    fn u16(&mut self) -> Result<u16, PnioStatus> {
        self.r.u16().ok_or(self.short())
    }
    fn u32(&mut self) -> Result<u32, PnioStatus> {
        self.r.u32().ok_or(self.short())
    }
    fn array<const N: usize>(&mut self) -> Result<[u8; N], PnioStatus> {
        self.r.array::<N>().ok_or(self.short())
    }
    fn check(&self, ok: bool, field: u8) -> Result<(), PnioStatus> {
        if ok {
            Ok(())
        } else {
            Err(PnioStatus::connect(self.block, field))
        }
    }
    fn end(&self) -> Result<(), PnioStatus> {
        self.check(self.r.remaining() == 0, 1)
    }
}

/// Context of a Connect the block checks need.
#[derive(Clone, Copy, Debug)]
pub struct ConnectContext {
    /// Where the Connect came from.
    pub peer: Endpoint,
    /// The alarm reference the device gives this AR.
    pub device_alarm_ref: u16,
}

fn parse_ar(blk: &Block<'_>, ctx: &ConnectContext) -> Result<Ar, PnioStatus> {
    let mut f = F::new(blk, b::AR_BLOCK_REQ)?;
    let ar_type = match f.u16()? {
        0x0001 => ArType::IoCarSingle,
        0x0006 => ArType::IoSar,
        _ => return Err(PnioStatus::connect(b::AR_BLOCK_REQ, 4)),
    };
    let ar_uuid = Uuid(f.array()?);
    f.check(!ar_uuid.is_nil(), 5)?;
    let session_key = f.u16()?;
    let controller_mac = MacAddr(f.array()?);
    f.check(!controller_mac.is_multicast(), 7)?;
    let controller_object = Uuid(f.array()?);
    let properties = f.u32()?;
    // State (bits 0-2) must be "active"; RT over UDP and companion ARs are not offered.
    f.check(properties & 0x7 == 1 && properties & 0x0000_0600 == 0, 9)?;
    let device_access = properties & 0x0000_0100 != 0;
    f.check((ar_type == ArType::IoSar) == device_access, 9)?;
    let activity_timeout_factor = f.u16()?;
    f.check((1..=1000).contains(&activity_timeout_factor), 10)?;
    {
        let v = f.u16()?;
        f.check(v == LT_PROFINET, 11)?;
    }
    let name_len = usize::from(f.u16()?);
    f.check((1..=MAX_STATION_NAME).contains(&name_len), 12)?;
    let name =
        f.r.bytes(name_len)
            .ok_or(PnioStatus::connect(b::AR_BLOCK_REQ, 13))?;
    f.end()?;
    let mut controller_station = Vec::new();
    let _ = controller_station.extend_from_slice(name);
    let _ = ctx;
    Ok(Ar {
        ar_uuid,
        ar_type,
        session_key,
        controller_mac,
        controller_object,
        controller_rpc: Endpoint {
            ip: ctx.peer.ip,
            port: crate::ip::RPC_PORT,
        },
        controller_station,
        properties,
        activity_timeout_factor,
        input_cr: None,
        output_cr: None,
        alarm_cr: None,
        submodules: Vec::new(),
        state: ArState::Parameterising,
    })
}

fn parse_iocr(blk: &Block<'_>) -> Result<Iocr, PnioStatus> {
    let mut f = F::new(blk, b::IOCR_BLOCK_REQ)?;
    let iocr_type = match f.u16()? {
        1 => IocrType::Input,
        2 => IocrType::Output,
        _ => return Err(PnioStatus::connect(b::IOCR_BLOCK_REQ, 4)),
    };
    let reference = f.u16()?;
    {
        let v = f.u16()?;
        f.check(v == LT_PROFINET, 6)?;
    }
    let props = f.u32()?;
    // RTClass (bits 0-3): 1 or 2, both RT_CLASS_1 frames (IRT and RT over UDP
    // are not offered); whether it fits the startup mode is checked once the
    // ARBlockReq is known. Reserved_1 (bits 4-12) and reserved_3 (24-31)
    // must be 0; reserved_2 may carry anything and is not checked.
    let rt_class = (props & 0xF) as u8;
    f.check(matches!(rt_class, 1 | 2) && props & 0xFF00_1FF0 == 0, 7)?;
    let data_length = f.u16()?;
    f.check((40..=1440).contains(&data_length), 8)?;
    let frame_id = f.u16()?;
    f.check(frame_id == 0xFFFF || frame_ids(rt_class).contains(&frame_id), 9)?;
    let send_clock_factor = f.u16()?;
    f.check(matches!(send_clock_factor, 32 | 64 | 128), 10)?;
    let reduction_ratio = f.u16()?;
    f.check(reduction_ratio.is_power_of_two() && reduction_ratio <= 512, 11)?;
    let phase = f.u16()?;
    f.check((1..=reduction_ratio).contains(&phase), 12)?;
    let sequence = f.u16()?;
    let frame_send_offset = f.u32()?;
    let send_clock_ns = u32::from(send_clock_factor) * 31_250;
    f.check(
        frame_send_offset == 0xFFFF_FFFF || frame_send_offset < send_clock_ns,
        14,
    )?;
    let watchdog_factor = f.u16()?;
    let cycle_ns = u64::from(send_clock_ns) * u64::from(reduction_ratio);
    let within =
        |factor: u16| (1..=0x1E00).contains(&factor) && cycle_ns * u64::from(factor) <= 1_920_000_000;
    f.check(within(watchdog_factor), 15)?;
    let data_hold_factor = f.u16()?;
    f.check(within(data_hold_factor), 16)?;
    let vlan_tci = f.u16()?;
    f.check(vlan_tci & 0x0FFF == 0 && vlan_tci >> 13 == 6, 17)?;
    let multicast_mac = MacAddr(f.array()?);
    let apis = f.u16()?;
    f.check(apis <= 1, 19)?;
    let mut data = Vec::new();
    let mut iocs = Vec::new();
    if apis == 1 {
        {
            let v = f.u32()?;
            f.check(v == 0, 20)?;
        }
        for (list, count_field, base) in [(&mut data, 21u8, 22u8), (&mut iocs, 25, 26)] {
            let n = f.u16()?;
            f.check(usize::from(n) <= MAX_SUBMODULES, count_field)?;
            for _ in 0..n {
                let slot = f.u16()?;
                let subslot = f.u16()?;
                let frame_offset = f.u16()?;
                f.check(
                    !list
                        .iter()
                        .any(|o: &IoObject| o.slot == slot && o.subslot == subslot),
                    base + 1,
                )?;
                let _ = list.push(IoObject {
                    slot,
                    subslot,
                    frame_offset,
                    data_len: 0,
                });
            }
        }
    }
    f.end()?;
    Ok(Iocr {
        iocr_type,
        reference,
        rt_class,
        frame_id,
        data_length,
        send_clock_factor,
        reduction_ratio,
        phase,
        sequence,
        frame_send_offset,
        watchdog_factor,
        data_hold_factor,
        vlan_tci,
        multicast_mac,
        data,
        iocs,
    })
}

fn parse_alarm_cr(blk: &Block<'_>, device_ref: u16) -> Result<AlarmCr, PnioStatus> {
    let mut f = F::new(blk, b::ALARM_CR_BLOCK_REQ)?;
    {
        let v = f.u16()?;
        f.check(v == 1, 4)?;
    }
    {
        let v = f.u16()?;
        f.check(v == LT_PROFINET, 5)?;
    }
    let properties = f.u32()?;
    f.check(properties & !1 == 0, 6)?; // transport over layer 2 only
    let rta_timeout_factor = f.u16()?;
    f.check((1..=100).contains(&rta_timeout_factor), 7)?;
    let rta_retries = f.u16()?;
    f.check((3..=15).contains(&rta_retries), 8)?;
    let controller_ref = f.u16()?;
    let max = f.u16()?;
    f.check((200..=1432).contains(&max), 10)?;
    let tag_header_high = f.u16()?;
    f.check(tag_header_high & 0x0FFF == 0, 11)?;
    let tag_header_low = f.u16()?;
    f.check(tag_header_low & 0x0FFF == 0, 12)?;
    f.end()?;
    Ok(AlarmCr {
        properties,
        rta_timeout_factor,
        rta_retries,
        controller_ref,
        device_ref,
        max_alarm_data_length: max.min(MAX_ALARM_DATA_LENGTH),
        tag_header_high,
        tag_header_low,
    })
}

fn parse_expected(blk: &Block<'_>, out: &mut Vec<Submodule, MAX_SUBMODULES>) -> Result<(), PnioStatus> {
    let mut f = F::new(blk, b::EXPECTED_SUBMODULE_BLOCK_REQ)?;
    let apis = f.u16()?;
    for _ in 0..apis {
        let api = f.u32()?;
        f.check(api == 0, 5)?;
        let slot = f.u16()?;
        let module_ident = f.u32()?;
        let _module_properties = f.u16()?;
        let n = f.u16()?;
        for _ in 0..n {
            let subslot = f.u16()?;
            let submodule_ident = f.u32()?;
            let props = f.u16()?;
            f.check(props & 0xFFC0 == 0, 12)?;
            let mut desc = |want: u16| -> Result<u16, PnioStatus> {
                {
                    let v = f.u16()?;
                    f.check(v == want, 13)?;
                }
                let len = f.u16()?;
                f.check(len <= 1439, 14)?;
                {
                    let v = f.u8()?;
                    f.check(v == 1, 16)?;
                } // LengthIOCS
                {
                    let v = f.u8()?;
                    f.check(v == 1, 15)?;
                } // LengthIOPS
                Ok(len)
            };
            let data = match props & 0x3 {
                0 => {
                    let len = desc(1)?;
                    if len != 0 {
                        return Err(PnioStatus::connect(b::EXPECTED_SUBMODULE_BLOCK_REQ, 14));
                    }
                    SubmoduleData::NoIo
                }
                1 => SubmoduleData::Input(desc(1)?),
                2 => SubmoduleData::Output(desc(2)?),
                _ => {
                    let i = desc(1)?;
                    SubmoduleData::InputOutput(i, desc(2)?)
                }
            };
            f.check(!out.iter().any(|s| s.slot == slot && s.subslot == subslot), 10)?;
            let (fit, module) = compare(slot, subslot, module_ident, submodule_ident, data);
            let s = Submodule {
                api,
                slot,
                subslot,
                module_ident,
                submodule_ident,
                data,
                fit,
                module,
            };
            out.push(s)
                .map_err(|_| PnioStatus::connect(b::EXPECTED_SUBMODULE_BLOCK_REQ, 9))?;
        }
    }
    f.end()
}

/// The real module at `slot` for an expected module ident: its ident and the
/// module-level fit. Data slots are plug-adaptive (any catalogue module is
/// "plugged" as expected); an IN/OUT-family ident of an unsupported length is
/// a wrong module (the real one reported is the nearest supported length),
/// any other ident or slot is no module.
pub fn real_module(slot: u16, expected: u32) -> (Fit, u32) {
    match slot {
        0 if expected == model::DAP_MODULE_IDENT => (Fit::Proper, expected),
        0 => (Fit::WrongModule, model::DAP_MODULE_IDENT),
        1..=MAX_DATA_SLOTS => match (DataModule::from_ident(expected), expected) {
            (Some(_), _) => (Fit::Proper, expected),
            (None, 0x100..=0x2FF) => {
                let base = expected & 0x300;
                let words = (expected & 0xFF).clamp(
                    u32::from(*model::MODULE_WORDS.start()),
                    u32::from(*model::MODULE_WORDS.end()),
                );
                (Fit::WrongModule, base + words)
            }
            _ => (Fit::NoModule, 0),
        },
        _ => (Fit::NoModule, 0),
    }
}

/// The real submodule ident at `slot`/`subslot` (None: no such subslot).
pub fn real_submodule(slot: u16, subslot: u16) -> Option<u32> {
    match (slot, subslot) {
        (0, 0x0001) => Some(model::DAP_SUBMODULE_IDENT),
        (0, 0x8000) => Some(model::INTERFACE_SUBMODULE_IDENT),
        (0, p @ 0x8001..=0x8002) => Some(model::port_submodule_ident(p - 0x8000)),
        (1..=MAX_DATA_SLOTS, 1) => Some(model::DATA_SUBMODULE_IDENT),
        _ => None,
    }
}

/// RealIdentificationData (block 0x0013, version 1.1): the DAP with its
/// four subslots and, in an AR, each data slot with the module really
/// plugged there (the data slots adapt to the expected modules, P-029; a
/// slot without one is left out); without an AR (implicit read) the DAP
/// only.
pub fn emit_real_identification(w: &mut Writer<'_>, ar: Option<&Ar>) -> Option<()> {
    let mut slots: Vec<(u16, u32), { MAX_DATA_SLOTS as usize }> = Vec::new();
    for s in ar
        .iter()
        .flat_map(|a| a.submodules.iter())
        .filter(|s| s.slot != 0)
    {
        let (fit, ident) = real_module(s.slot, s.module_ident);
        if fit != Fit::NoModule && !slots.iter().any(|x| x.0 == s.slot) {
            let _ = slots.push((s.slot, ident));
        }
    }
    // In slot order without a sort: core's sort keeps a panic path
    // (quicksort's bounds assertion) that the reference board must not have.
    let mut ordered: Vec<(u16, u32), { MAX_DATA_SLOTS as usize }> = Vec::new();
    for slot in 1..=MAX_DATA_SLOTS {
        if let Some(&x) = slots.iter().find(|x| x.0 == slot) {
            let _ = ordered.push(x);
        }
    }
    let slots = ordered;
    emit_block_v(w, REAL_IDENTIFICATION_DATA, 1, |w| {
        w.u16(1)?; // NumberOfAPIs
        w.u32(0)?;
        w.u16(u16::try_from(slots.len() + 1).ok()?)?;
        w.u16(0)?;
        w.u32(model::DAP_MODULE_IDENT)?;
        w.u16(u16::try_from(model::DAP_SUBSLOTS.len()).ok()?)?;
        for sub in model::DAP_SUBSLOTS {
            w.u16(sub)?;
            w.u32(real_submodule(0, sub)?)?;
        }
        for &(slot, ident) in &slots {
            w.u16(slot)?;
            w.u32(ident)?;
            w.u16(1)?;
            w.u16(1)?;
            w.u32(model::DATA_SUBMODULE_IDENT)?;
        }
        Some(())
    })
}

/// Block type of RealIdentificationData.
const REAL_IDENTIFICATION_DATA: u16 = 0x0013;

/// True if `slot`/`subslot` exists in the real model.
pub fn exists(slot: u16, subslot: u16) -> bool {
    real_submodule(slot, subslot).is_some()
}

fn compare(
    slot: u16,
    subslot: u16,
    module_ident: u32,
    submodule_ident: u32,
    data: SubmoduleData,
) -> (Fit, Option<DataModule>) {
    let (mfit, _) = real_module(slot, module_ident);
    if mfit != Fit::Proper {
        return (mfit, None);
    }
    let Some(real) = real_submodule(slot, subslot) else {
        return (Fit::NoSubmodule, None);
    };
    let module = DataModule::from_ident(module_ident).filter(|_| slot != 0);
    // P-029: the data description must carry exactly the module's length, in
    // its direction; anything else is a wrong submodule (deterministic).
    let data_ok = match module {
        None => data == SubmoduleData::NoIo,
        Some(m) => {
            let n = u16::try_from(m.bytes()).unwrap_or(0);
            match m.direction {
                Direction::ToDrive => data == SubmoduleData::Output(n),
                Direction::FromDrive => data == SubmoduleData::Input(n),
            }
        }
    };
    if real != submodule_ident || !data_ok {
        return (Fit::WrongSubmodule, module);
    }
    (Fit::Proper, module)
}

/// Parses and checks a whole Connect; nothing is kept on error.
pub fn parse_connect(args: &[u8], ctx: &ConnectContext) -> Result<Ar, PnioStatus> {
    let unknown = PnioStatus::cmrpc(error_code::IOD_CONNECT_RES, cmrpc::UNKNOWN_BLOCKS);
    let mut blocks = Blocks::new(args);
    let mut ar: Option<Ar> = None;
    let mut crs: Vec<Iocr, 2> = Vec::new();
    let mut alarm: Option<AlarmCr> = None;
    let mut alarm_count = 0u8;
    let mut subs: Vec<Submodule, MAX_SUBMODULES> = Vec::new();
    while let Some(blk) = blocks.next_block() {
        let blk = match blk {
            Ok(blk) => blk,
            Err(BlockError::Truncated) => {
                return Err(PnioStatus::cmrpc(
                    error_code::IOD_CONNECT_RES,
                    cmrpc::ARGS_LENGTH_INVALID,
                ))
            }
            Err(BlockError::Length(t)) => {
                let block = match t {
                    block_type::AR_REQ => b::AR_BLOCK_REQ,
                    block_type::IOCR_REQ => b::IOCR_BLOCK_REQ,
                    block_type::ALARM_CR_REQ => b::ALARM_CR_BLOCK_REQ,
                    block_type::EXPECTED_SUBMODULE_REQ => b::EXPECTED_SUBMODULE_BLOCK_REQ,
                    _ => return Err(unknown),
                };
                return Err(PnioStatus::connect(block, 1));
            }
        };
        match blk.block_type {
            block_type::AR_REQ if ar.is_none() => ar = Some(parse_ar(&blk, ctx)?),
            block_type::AR_REQ => return Err(PnioStatus::connect(b::AR_BLOCK_REQ, 0)),
            block_type::IOCR_REQ => {
                let cr = parse_iocr(&blk)?;
                let dup = crs
                    .iter()
                    .any(|c| c.iocr_type == cr.iocr_type || c.reference == cr.reference);
                if dup {
                    return Err(PnioStatus::connect(b::IOCR_BLOCK_REQ, 4));
                }
                crs.push(cr)
                    .map_err(|_| PnioStatus::connect(b::IOCR_BLOCK_REQ, 4))?;
            }
            block_type::ALARM_CR_REQ => {
                alarm_count = alarm_count.saturating_add(1);
                alarm = Some(parse_alarm_cr(&blk, ctx.device_alarm_ref)?);
            }
            block_type::EXPECTED_SUBMODULE_REQ => parse_expected(&blk, &mut subs)?,
            _ => return Err(unknown),
        }
    }
    let mut ar = ar.ok_or(PnioStatus::connect(b::AR_BLOCK_REQ, 0))?;
    // Advanced startup takes RTClass 2 only; legacy startup RTClass 1 or 2.
    if ar.advanced_startup() && crs.iter().any(|c| c.rt_class != 2) {
        return Err(PnioStatus::connect(b::IOCR_BLOCK_REQ, 7));
    }
    match ar.ar_type {
        ArType::IoCarSingle => {
            if crs.len() != 2 {
                return Err(PnioStatus::cmrpc(
                    error_code::IOD_CONNECT_RES,
                    cmrpc::IOCR_MISSING,
                ));
            }
            if alarm_count != 1 {
                return Err(PnioStatus::cmrpc(
                    error_code::IOD_CONNECT_RES,
                    cmrpc::WRONG_ALARM_CR_COUNT,
                ));
            }
        }
        ArType::IoSar => {
            if !crs.is_empty() || alarm_count != 0 || !subs.is_empty() {
                return Err(PnioStatus::connect(b::AR_BLOCK_REQ, 4));
            }
        }
    }
    // in order, by value, without a heapless IntoIter (whose drop carries an
    // index panic)
    crs.reverse();
    while let Some(mut cr) = crs.pop() {
        resolve(&mut cr, &subs)?;
        if cr.frame_id == 0xFFFF {
            let first = match cr.rt_class {
                2 => ASSIGNED_FRAME_ID_BASE_RT_CLASS_2,
                _ => ASSIGNED_FRAME_ID_BASE,
            };
            let base = match cr.iocr_type {
                IocrType::Output => first,
                IocrType::Input => first + 0x100,
            };
            cr.frame_id = base | (cr.reference & 0xFF);
        }
        match cr.iocr_type {
            IocrType::Input => ar.input_cr = Some(cr),
            IocrType::Output => ar.output_cr = Some(cr),
        }
    }
    ar.alarm_cr = alarm;
    ar.submodules = subs;
    Ok(ar)
}

/// Fills the data lengths of an IOCR's objects from the expected submodules
/// and checks that every object fits the C_SDU.
fn resolve(cr: &mut Iocr, subs: &[Submodule]) -> Result<(), PnioStatus> {
    let err = |field| PnioStatus::connect(b::IOCR_BLOCK_REQ, field);
    let dl = cr.data_length;
    let find = |o: &IoObject, base: u8| -> Result<&Submodule, PnioStatus> {
        if !subs.iter().any(|s| s.slot == o.slot) {
            return Err(err(base));
        }
        subs.iter()
            .find(|s| s.slot == o.slot && s.subslot == o.subslot)
            .ok_or(err(base + 1))
    };
    for o in cr.data.iter_mut() {
        let s = find(o, 22)?;
        let len = match (cr.iocr_type, s.data) {
            (IocrType::Input, SubmoduleData::NoIo) => 0,
            (IocrType::Input, SubmoduleData::Input(n) | SubmoduleData::InputOutput(n, _)) => n,
            (IocrType::Output, SubmoduleData::Output(n) | SubmoduleData::InputOutput(_, n)) => n,
            _ => return Err(err(23)),
        };
        if u32::from(o.frame_offset) + u32::from(len) + 1 > u32::from(dl) {
            return Err(err(24));
        }
        o.data_len = len;
    }
    for o in cr.iocs.iter() {
        find(o, 26)?;
        if u32::from(o.frame_offset) + 1 > u32::from(dl) {
            return Err(err(28));
        }
    }
    Ok(())
}

/// Writes the Connect response blocks for `ar` (ARBlockRes, IOCRBlockRes
/// input then output, AlarmCRBlockRes, ModuleDiffBlock if anything differs).
///
/// In advanced startup an ARServerBlockRes with our name of station
/// (`station`, CMResponderStationName) follows, padded to 32 bits.
pub fn emit_connect_response(w: &mut Writer<'_>, ar: &Ar, our_mac: MacAddr, station: &[u8]) -> Option<()> {
    emit_block(w, block_type::AR_RES, |w| {
        w.u16(ar.ar_type.to_u16())?;
        w.bytes(&ar.ar_uuid.0)?;
        w.u16(ar.session_key)?;
        w.bytes(&our_mac.0)?;
        w.u16(LT_PROFINET)
    })?;
    for cr in [&ar.input_cr, &ar.output_cr].into_iter().flatten() {
        emit_block(w, block_type::IOCR_RES, |w| {
            w.u16(match cr.iocr_type {
                IocrType::Input => 1,
                IocrType::Output => 2,
            })?;
            w.u16(cr.reference)?;
            w.u16(cr.frame_id)
        })?;
    }
    if let Some(a) = &ar.alarm_cr {
        emit_block(w, block_type::ALARM_CR_RES, |w| {
            w.u16(1)?;
            w.u16(a.device_ref)?;
            w.u16(a.max_alarm_data_length)
        })?;
    }
    if ar.has_diff() {
        emit_module_diff(w, ar)?;
    }
    if ar.advanced_startup() {
        emit_block(w, block_type::AR_SERVER_RES, |w| {
            let n = u16::try_from(station.len()).ok()?;
            w.u16(n)?;
            w.bytes(station)?;
            // block header (6) + length (2) + name, padded to a multiple of 4
            let pad = (4 - (8 + station.len()) % 4) % 4;
            w.bytes([0u8; 3].get(..pad)?)
        })?;
    }
    Some(())
}

const SUBMODULE_STATE_DETAIL: u16 = 0x8000;

fn submodule_state(fit: Fit) -> u16 {
    let ident_info: u16 = match fit {
        Fit::Proper => 0,
        Fit::WrongModule | Fit::WrongSubmodule => 2,
        Fit::NoModule | Fit::NoSubmodule => 3,
    };
    SUBMODULE_STATE_DETAIL | ident_info << 11
}

/// Writes the ModuleDiffBlock of `ar`: every module with a misfit, with all
/// its submodules when the module itself is wrong or missing, else only the
/// misfitting ones. An AR without misfits gives NumberOfAPIs = 0.
pub fn emit_module_diff(w: &mut Writer<'_>, ar: &Ar) -> Option<()> {
    let mut slots: Vec<u16, MAX_SUBMODULES> = Vec::new();
    for s in ar.submodules.iter().filter(|s| s.fit != Fit::Proper) {
        if !slots.contains(&s.slot) {
            let _ = slots.push(s.slot);
        }
    }
    emit_block(w, block_type::MODULE_DIFF, |w| {
        if slots.is_empty() {
            return w.u16(0);
        }
        w.u16(1)?;
        w.u32(0)?;
        w.u16(u16::try_from(slots.len()).ok()?)?;
        for &slot in &slots {
            let in_slot = || ar.submodules.iter().filter(move |s| s.slot == slot);
            let ident = in_slot().next()?.module_ident;
            let (mfit, real_ident) = real_module(slot, ident);
            let module_state: u16 = match mfit {
                Fit::NoModule => 0,
                Fit::WrongModule => 1,
                _ => 2,
            };
            let whole = mfit != Fit::Proper;
            let listed = || in_slot().filter(move |s| whole || s.fit != Fit::Proper);
            w.u16(slot)?;
            w.u32(real_ident)?;
            w.u16(module_state)?;
            w.u16(u16::try_from(listed().count()).ok()?)?;
            for s in listed() {
                w.u16(s.subslot)?;
                let real = match s.fit {
                    Fit::NoModule | Fit::NoSubmodule => 0,
                    _ => real_submodule(s.slot, s.subslot).unwrap_or(0),
                };
                w.u32(real)?;
                w.u16(submodule_state(s.fit))?;
            }
        }
        Some(())
    })
}
