//! The running AR's real-time side: the output CR's consumer, the input CR's
//! provider and the alarm CR, configured from the connection management's
//! [`Ar`], and the process data the application exchanges with them
//! (`Device::output_data`, `input_data_mut` and the rest, here).

use heapless::Vec;
use nanos::Nanos;

use crate::alarm::{AlarmCr, AlarmCrConfig, Location, Priority};
use crate::cm::{Ar, Iocr, IocrType};
use crate::model::{self, Direction};
use crate::rpc::uuid::Uuid;
use crate::rt::{Consumer, CrConfig, IoDataObject, IocsEntry, Ioxs, Provider};
use crate::wire::MacAddr;

/// Longest data module (19 words).
pub const MAX_MODULE_BYTES: usize = 38;
/// Data modules an AR carries (one per data slot).
pub const MAX_MODULES: usize = 2;

/// One data module's bytes.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(super) struct ModuleData {
    pub slot: u16,
    pub data: Vec<u8, MAX_MODULE_BYTES>,
}

/// The RT side of the AR `ar`.
pub(super) struct Cyclic {
    pub ar: Uuid,
    pub consumer: Option<Consumer>,
    pub provider: Option<Provider>,
    pub alarm: Option<AlarmCr>,
    /// Controller → drive, the last valid frame's (empty until one arrived).
    pub outputs: Vec<ModuleData, MAX_MODULES>,
    /// `outputs` holds the current data (valid frame, data hold not expired).
    pub outputs_valid: bool,
    /// Drive → controller, sent with every provider frame.
    pub inputs: Vec<ModuleData, MAX_MODULES>,
    /// The AR is lost; only the alarm CR's ERR PDU is still to go out.
    pub lost: bool,
}

fn cr_config(cr: &Iocr, local: MacAddr, remote: MacAddr) -> CrConfig {
    let mut objects = Vec::new();
    for o in &cr.data {
        let _ = objects.push(IoDataObject {
            slot: o.slot,
            subslot: o.subslot,
            offset: o.frame_offset,
            len: o.data_len,
        });
    }
    let mut iocs = Vec::new();
    for o in &cr.iocs {
        let _ = iocs.push(IocsEntry {
            slot: o.slot,
            subslot: o.subslot,
            offset: o.frame_offset,
        });
    }
    CrConfig {
        frame_id: cr.frame_id,
        data_length: cr.data_length,
        send_clock_factor: cr.send_clock_factor,
        reduction_ratio: cr.reduction_ratio,
        phase: cr.phase,
        watchdog_factor: cr.watchdog_factor,
        data_hold_factor: cr.data_hold_factor,
        local,
        remote,
        // RT_CLASS_1 frames carry the controller's IOCRTagHeader (priority 6)
        tag: Some(cr.vlan_tci),
        objects,
        iocs,
    }
}

fn tci(t: u16) -> Option<u16> {
    Some(t)
}

impl Cyclic {
    /// The RT side of `ar` from `now`; CRs the RT layer refuses stay `None`
    /// (the AR then has no cyclic data in that direction).
    pub fn new(ar: &Ar, local: MacAddr, now: Nanos) -> Cyclic {
        let remote = ar.controller_mac;
        let consumer = ar
            .output_cr
            .as_ref()
            .filter(|c| c.iocr_type == IocrType::Output)
            .and_then(|c| Consumer::new(cr_config(c, local, remote)).ok());
        let provider = ar
            .input_cr
            .as_ref()
            .and_then(|c| Provider::new(cr_config(c, local, remote), now).ok());
        let alarm = ar.alarm_cr.and_then(|a| {
            AlarmCr::new(AlarmCrConfig {
                local_ref: a.device_ref,
                remote_ref: a.controller_ref,
                rta_timeout_factor: a.rta_timeout_factor,
                rta_retries: a.rta_retries,
                max_alarm_data_length: a.max_alarm_data_length,
                only_low_priority: a.properties & 1 != 0,
                tag_high: tci(a.tag_header_high),
                tag_low: tci(a.tag_header_low),
                local,
                remote,
            })
            .ok()
        });
        let mut outputs = Vec::new();
        let mut inputs = Vec::new();
        for s in &ar.submodules {
            let Some((dir, bytes)) = s.telegram() else {
                continue;
            };
            let mut data = Vec::new();
            let _ = data.resize(bytes.min(MAX_MODULE_BYTES), 0);
            let m = ModuleData { slot: s.slot, data };
            let _ = match dir {
                Direction::ToDrive => outputs.push(m),
                Direction::FromDrive => inputs.push(m),
            };
        }
        let mut c = Cyclic {
            ar: ar.ar_uuid,
            consumer,
            provider,
            alarm,
            outputs,
            outputs_valid: false,
            inputs,
            lost: false,
        };
        if let Some(p) = c.provider.as_mut() {
            // our submodules' data is good from the start; misfits are bad
            p.set_all_iops(Ioxs::GOOD);
            p.set_all_iocs(Ioxs::GOOD);
            for s in &ar.submodules {
                if s.fit != crate::cm::Fit::Proper {
                    p.set_iops(s.slot, s.subslot, Ioxs::BAD_BY_DEVICE);
                    p.set_iocs(s.slot, s.subslot, Ioxs::BAD_BY_DEVICE);
                }
            }
            p.set_run(true);
            p.set_data_valid(true);
        }
        c
    }

    /// Where the drive's diagnoses sit: the DAP's subslot 1 (the drive as a
    /// whole).
    pub fn drive_location() -> Location {
        Location {
            api: 0,
            slot: 0,
            subslot: 1,
            module_ident: model::DAP_MODULE_IDENT,
            submodule_ident: model::DAP_SUBMODULE_IDENT,
        }
    }

    /// Whether the alarm channel can take the next diagnosis alarm.
    pub fn alarm_free(&self) -> bool {
        self.alarm.as_ref().is_some_and(|a| a.can_send(Priority::Low))
    }
}

/// The process data the application reads and writes: the data modules of
/// the running AR.
impl<H: crate::cm::RecordHook> super::Device<H> {
    /// The controller's output data for the IN module at `slot` (controller →
    /// drive, the receive telegram), while it is current: an AR exchanges
    /// valid cyclic data and the data hold time has not expired.
    pub fn output_data(&self, slot: u16) -> Option<&[u8]> {
        valid_outputs(&self.cyclic, slot)
    }

    /// The output data of the module at `slot` (controller → drive) beside
    /// the record hook: a profile that reads the one while the hook serves
    /// it takes both without copying the frame out first (issue 36).
    pub fn output_data_with_hook(&mut self, slot: u16) -> (Option<&[u8]>, &mut H) {
        (valid_outputs(&self.cyclic, slot), self.cm.hook_mut())
    }

    /// The input data of the module at `slot` (drive → controller) to
    /// write in place for the next provider frames, its configured length;
    /// `None` if the AR has no such module (or no AR runs). What
    /// [`set_input_data`](Self::set_input_data) does, without a buffer to
    /// copy from (issue 36: the response telegram is built here).
    pub fn input_data_mut(&mut self, slot: u16) -> Option<&mut [u8]> {
        self.cyclic
            .as_mut()?
            .inputs
            .iter_mut()
            .find(|m| m.slot == slot)
            .map(|m| m.data.as_mut_slice())
    }

    /// Sets the input data of the OUT module at `slot` (drive → controller,
    /// the response telegram) for the next provider frames; `false` if the
    /// AR has no such module (or no AR runs). Extra bytes are ignored; missing
    /// ones stay as they were.
    pub fn set_input_data(&mut self, slot: u16, data: &[u8]) -> bool {
        let Some(m) = self
            .cyclic
            .as_mut()
            .and_then(|c| c.inputs.iter_mut().find(|m| m.slot == slot))
        else {
            return false;
        };
        for (d, s) in m.data.iter_mut().zip(data) {
            *d = *s;
        }
        true
    }

    /// The configured lengths of the AR's data modules (P-028): (slot, bytes,
    /// direction seen from the drive: `true` = to the drive).
    pub fn data_modules(&self) -> impl Iterator<Item = (u16, usize, bool)> + '_ {
        self.cyclic.iter().flat_map(|c| {
            let outs = c.outputs.iter().map(|m| (m.slot, m.data.len(), true));
            let ins = c.inputs.iter().map(|m| (m.slot, m.data.len(), false));
            outs.chain(ins)
        })
    }
}

/// The output data of `slot` while it is current ([`output_data`](super::Device::output_data)).
fn valid_outputs(cyclic: &Option<Cyclic>, slot: u16) -> Option<&[u8]> {
    let c = cyclic.as_ref().filter(|c| c.outputs_valid)?;
    c.outputs
        .iter()
        .find(|m| m.slot == slot)
        .map(|m| m.data.as_slice())
}
