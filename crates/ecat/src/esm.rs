//! EtherCAT state machine rules (spec §3–4): which requests are transitions,
//! and the SyncManager checks of I→P and P→S. Pure functions; [`crate::Slave`]
//! applies them to the ESC.

use crate::desc::{Device, MailboxSm};
use crate::emcy::SmFault;
use esc::{regs, AlState, AlStatusCode, SmDirection, SmMode, SyncManager};

/// Smallest mailbox SyncManager length accepted: header + CoE header + SDO frame.
pub const MIN_MAILBOX_LEN: u16 = 16;
/// Largest mailbox the stack buffers.
pub const MAX_MAILBOX_LEN: usize = 512;
/// Largest process image per direction: 4 PDOs × 24 entries × 32 bit.
pub const MAX_PDO_BYTES: usize = 384;

/// What an AL control request asks for, seen from state `from`:
/// `Ok(None)` = stay (the requested state is the current one), `Ok(Some(to))` =
/// a transition of the ESM (upward ones still need their checks), `Err(code)` =
/// refused (0011h invalid change, 0012h unknown state, 0013h bootstrap).
pub fn target(from: AlState, requested: u8) -> Result<Option<AlState>, AlStatusCode> {
    use AlState::*;
    let to = AlState::from_code(requested).ok_or(AlStatusCode::UNKNOWN_STATE)?;
    if to == Bootstrap {
        return Err(AlStatusCode::BOOTSTRAP_NOT_SUPPORTED);
    }
    if to == from {
        return Ok(None);
    }
    match (from, to) {
        // upward: one step at a time
        (Init, PreOp) | (PreOp, SafeOp) | (SafeOp, Op) => Ok(Some(to)),
        // downward: always
        (Op, SafeOp | PreOp | Init) | (SafeOp, PreOp | Init) | (PreOp, Init) => Ok(Some(to)),
        _ => Err(AlStatusCode::INVALID_STATE_CHANGE),
    }
}

/// Whether the mailbox runs in `state` (Pre-Op and up).
pub fn mailbox_on(state: AlState) -> bool {
    matches!(state, AlState::PreOp | AlState::SafeOp | AlState::Op)
}

/// Whether process data runs in `state` (Safe-Op and Op).
pub fn process_data_on(state: AlState) -> bool {
    matches!(state, AlState::SafeOp | AlState::Op)
}

fn mailbox_sm_ok(sm: &SyncManager, want: &MailboxSm, dir: SmDirection) -> bool {
    sm.enabled()
        && sm.start == want.start
        && (MIN_MAILBOX_LEN..=want.length).contains(&sm.length)
        && usize::from(sm.length) <= MAX_MAILBOX_LEN
        && sm.control().mode() == SmMode::Mailbox
        && sm.control().direction() == dir
}

/// I→P check (E-025): SM0/SM1 enabled, at the description's start address, length
/// between [`MIN_MAILBOX_LEN`] and the description's length, mailbox mode, right
/// direction. Failure: AL 0016h.
pub fn check_mailbox_sms(desc: &Device, sm0: &SyncManager, sm1: &SyncManager) -> Result<(), AlStatusCode> {
    if mailbox_sm_ok(sm0, &desc.mailbox_out, SmDirection::MasterWrite)
        && mailbox_sm_ok(sm1, &desc.mailbox_in, SmDirection::MasterRead)
    {
        Ok(())
    } else {
        Err(AlStatusCode::INVALID_MAILBOX_CONFIG)
    }
}

/// The memory an active SyncManager occupies, as a half-open range.
fn area(sm: &SyncManager) -> Option<(u32, u32)> {
    (sm.enabled() && sm.length > 0).then(|| {
        let start = u32::from(sm.start);
        (start, start + sm.occupied_len())
    })
}

fn overlap(a: Option<(u32, u32)>, b: Option<(u32, u32)>) -> bool {
    matches!((a, b), (Some((a0, a1)), Some((b0, b1))) if a0 < b1 && b0 < a1)
}

/// Why a process-data SyncManager was refused, for the AL status code and the
/// diag code of the state-transition EMCY (spec §8.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SmRefusal {
    /// AL status code (0017h, 001Dh or 001Eh).
    pub code: AlStatusCode,
    /// The SyncManager at fault (2 or 3).
    pub sm: u8,
    /// What is wrong with it.
    pub fault: SmFault,
}

fn process_sm_fault(sm: &SyncManager, bytes: usize, dir: SmDirection, ram_end: u32) -> Option<SmFault> {
    if bytes == 0 {
        return (sm.length != 0 && sm.enabled()).then_some(SmFault::Length);
    }
    let end = u32::from(sm.start) + sm.occupied_len();
    if sm.start < regs::PROCESS_RAM || end > ram_end {
        Some(SmFault::Address)
    } else if bytes > MAX_PDO_BYTES || usize::from(sm.length) != bytes {
        Some(SmFault::Length)
    } else if !sm.enabled() || sm.control().mode() != SmMode::Buffered || sm.control().direction() != dir {
        Some(SmFault::Settings)
    } else {
        None
    }
}

/// P→S check (E-028, E-045): `sms` are SM0..SM3 as configured by the master,
/// `rx_bytes`/`tx_bytes` the lengths of the assigned RxPDOs/TxPDOs.
/// Reserved mode/direction bits or overlapping areas: 0017h; SM2 (outputs,
/// three-buffer, MasterWrite, length = RxPDO bytes, inside process RAM):
/// 001Dh; SM3 (inputs, likewise): 001Eh.
pub fn check_process_sms(
    desc: &Device,
    sms: &[SyncManager; 4],
    rx_bytes: usize,
    tx_bytes: usize,
) -> Result<(), SmRefusal> {
    let [sm0, sm1, sm2, sm3] = sms;
    for (n, sm) in [(2, sm2), (3, sm3)] {
        let c = sm.control();
        let reserved =
            matches!(c.mode(), SmMode::Reserved(_)) || matches!(c.direction(), SmDirection::Reserved(_));
        if area(sm).is_some() && reserved {
            return Err(SmRefusal {
                code: AlStatusCode::INVALID_SM_CONFIG,
                sm: n,
                fault: SmFault::Settings,
            });
        }
    }
    let (a0, a1, a2, a3) = (area(sm0), area(sm1), area(sm2), area(sm3));
    for (n, a, other) in [(2, a2, a3), (3, a3, a2)] {
        if overlap(a, other) || overlap(a0, a) || overlap(a1, a) {
            return Err(SmRefusal {
                code: AlStatusCode::INVALID_SM_CONFIG,
                sm: n,
                fault: SmFault::Address2,
            });
        }
    }
    let ram_end = desc.process_ram_end;
    if let Some(fault) = process_sm_fault(sm2, rx_bytes, SmDirection::MasterWrite, ram_end) {
        return Err(SmRefusal {
            code: AlStatusCode::INVALID_OUTPUT_CONFIG,
            sm: 2,
            fault,
        });
    }
    if let Some(fault) = process_sm_fault(sm3, tx_bytes, SmDirection::MasterRead, ram_end) {
        return Err(SmRefusal {
            code: AlStatusCode::INVALID_INPUT_CONFIG,
            sm: 3,
            fault,
        });
    }
    Ok(())
}
