//! EtherCAT state machine rules (spec §3–4): which requests are transitions,
//! and the SyncManager checks of I→P and P→S. Pure functions; [`crate::Slave`]
//! applies them to the ESC.

use crate::app::PdoTimeout;
use crate::desc::{Device, MailboxSm};
use crate::emcy::SmFault;
use esc::{regs, AlState, AlStatusCode, SmDirection, SmMode, SyncManager};
use nanos::Nanos;

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
///
/// Bootstrap follows [`target_with_boot`] with `boot = false`: a device
/// without FoE refuses it with 0013h.
pub fn target(from: AlState, requested: u8) -> Result<Option<AlState>, AlStatusCode> {
    target_with_boot(from, requested, false)
}

/// [`target`] for a device that may support Bootstrap (`boot`: it declares FoE,
/// the firmware download, issue 8). With `boot`: Init → Boot and Boot → Init are
/// transitions; every other change into or out of Boot (P/S/O → B, B → P/S/O) is
/// refused with 0011h, as any other invalid change (ETG.1000.6: Boot is entered
/// and left through Init only). Without `boot`: Boot is refused with 0013h from
/// any state.
pub fn target_with_boot(from: AlState, requested: u8, boot: bool) -> Result<Option<AlState>, AlStatusCode> {
    use AlState::*;
    let to = AlState::from_code(requested).ok_or(AlStatusCode::UNKNOWN_STATE)?;
    if to == Bootstrap && !boot {
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
        // Bootstrap (only with `boot`, see above): through Init only
        (Init, Bootstrap) | (Bootstrap, Init) => Ok(Some(to)),
        _ => Err(AlStatusCode::INVALID_STATE_CHANGE),
    }
}

/// Whether the mailbox runs in `state` (Pre-Op and up, and Bootstrap).
pub fn mailbox_on(state: AlState) -> bool {
    matches!(
        state,
        AlState::PreOp | AlState::SafeOp | AlState::Op | AlState::Bootstrap
    )
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
    match faulty_mailbox_sm(desc, sm0, sm1) {
        None => Ok(()),
        Some(_) => Err(AlStatusCode::INVALID_MAILBOX_CONFIG),
    }
}

/// The first mailbox SyncManager (0 = master → slave, "mailbox Rx"; 1 =
/// slave → master, "mailbox Tx") that fails [`check_mailbox_sms`].
pub fn faulty_mailbox_sm(desc: &Device, sm0: &SyncManager, sm1: &SyncManager) -> Option<u8> {
    if !mailbox_sm_ok(sm0, &desc.mailbox_out, SmDirection::MasterWrite) {
        Some(0)
    } else if !mailbox_sm_ok(sm1, &desc.mailbox_in, SmDirection::MasterRead) {
        Some(1)
    } else {
        None
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

/// `1C32h:01` synchronisation types (ETG.1020).
pub mod sync_type {
    /// Free run: not synchronised.
    pub const FREE_RUN: u16 = 0;
    /// Synchronous with the SM2 event.
    pub const SM2: u16 = 1;
    /// DC SYNC0.
    pub const DC_SYNC0: u16 = 2;
}

/// The synchronisation mode the master chose (spec §11.1), decided at P→S.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SyncMode {
    /// Free run (`1C32h:01` = 0): needs SM2 in 3-buffer mode (0029h).
    FreeRun,
    /// SM-synchronous (`1C32h:01` = 1, the SM2 event). Also the mode assumed
    /// when the application has no `1C32h` (no mode-specific check then).
    #[default]
    SmSync,
    /// DC SYNC0: 0x0981 has cyclic operation and SYNC0 active, or `1C32h:01` = 2.
    DcSync0,
}

impl SyncMode {
    /// The `1C32h:01` value of the mode.
    pub const fn sync_type(self) -> u16 {
        match self {
            Self::FreeRun => sync_type::FREE_RUN,
            Self::SmSync => sync_type::SM2,
            Self::DcSync0 => sync_type::DC_SYNC0,
        }
    }
}

/// 0x0981 bits 0 (cyclic operation) and 1 (SYNC0 active).
pub const DC_ACTIVATION_SYNC0: u8 = 0x03;

/// The sync mode from the ESC's DC activation register (0x0981) and
/// `1C32h:01` (`None`: the application has no such entry). DC wins when
/// the master activated SYNC0 (ethercrab writes 0x0981 without touching
/// `1C32h`). A sync type this device does not support (3 = DC SYNC1 and
/// above, spec §11.9: `1C32h:04` = 0007h) is refused with 0030h.
pub fn sync_mode(dc_activation: u8, sync_type: Option<u16>) -> Result<SyncMode, AlStatusCode> {
    if dc_activation & DC_ACTIVATION_SYNC0 == DC_ACTIVATION_SYNC0 {
        return Ok(SyncMode::DcSync0);
    }
    match sync_type {
        None | Some(sync_type::SM2) => Ok(SyncMode::SmSync),
        Some(sync_type::FREE_RUN) => Ok(SyncMode::FreeRun),
        Some(sync_type::DC_SYNC0) => Ok(SyncMode::DcSync0),
        Some(_) => Err(AlStatusCode::INVALID_DC_SYNC_CONFIG),
    }
}

/// E-030: in free run the outputs need SM2 in 3-buffer mode; an SM2 that
/// carries outputs in 1-buffer (mailbox) mode is refused with 0029h. Other
/// SM2 faults are left to [`check_process_sms`] (001Dh). Run before it, so
/// the more specific code wins.
pub fn check_free_run(mode: SyncMode, sm2: &SyncManager, rx_bytes: usize) -> Result<(), AlStatusCode> {
    if mode == SyncMode::FreeRun && rx_bytes > 0 && sm2.enabled() && sm2.control().mode() == SmMode::Mailbox {
        Err(AlStatusCode::FREERUN_NEEDS_3BUFFER)
    } else {
        Ok(())
    }
}

/// The ESC's process-data watchdog as the master configured it (0x0400,
/// 0x0420, SM2's watchdog trigger bit).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EscWatchdog {
    /// Watchdog divider (0x0400): one unit is (divider + 2) × 40 ns.
    pub divider: u16,
    /// Process-data watchdog time (0x0420) in units; 0 = disabled.
    pub pd_time: u16,
    /// SM2 retriggers the watchdog (SM control bit 6).
    pub sm2_trigger: bool,
}

impl EscWatchdog {
    /// The watchdog time, `None` when disabled (time 0 or no SM2 trigger).
    pub fn time(&self) -> Option<Nanos> {
        (self.pd_time != 0 && self.sm2_trigger)
            .then(|| Nanos::from_ns(u64::from(self.pd_time) * (u64::from(self.divider) + 2) * 40))
    }
}

/// How the RxPDO reception is monitored in Op (spec §13.1), from the
/// application's [`PdoTimeout`] and the process-data cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PdoMonitor {
    /// No new RxPDO for longer than this is a PDO timeout.
    Timeout(Nanos),
    /// [`PdoTimeout::EscWatchdog`]: the ESC's SM watchdog decides (AL event
    /// 6, 0x0440 bit 0); the tolerance is the watchdog time.
    EscWatchdog(Nanos),
}

impl PdoMonitor {
    /// The tolerated time without RxPDO.
    pub const fn tolerance(&self) -> Nanos {
        match *self {
            Self::Timeout(t) | Self::EscWatchdog(t) => t,
        }
    }
}

/// The monitoring `timeout` asks for, with `cycle_ns` the process-data
/// cycle (SYNC0 cycle in DC mode, else `1C32h:02`) and the ESC's watchdog.
/// Lost frames: a gap of `lost + 1` cycles passes, plus half a cycle for
/// jitter. The ESC's watchdog: off when the master disabled it.
pub fn pdo_monitor(timeout: PdoTimeout, cycle_ns: u32, wd: &EscWatchdog) -> Option<PdoMonitor> {
    let cycle = u64::from(cycle_ns);
    match timeout {
        PdoTimeout::Off => None,
        PdoTimeout::Ms(0) => None,
        PdoTimeout::Ms(ms) => Some(PdoMonitor::Timeout(Nanos::from_ms(u64::from(ms)))),
        PdoTimeout::LostFrames(lost) => Some(PdoMonitor::Timeout(Nanos::from_ns(
            (u64::from(lost) + 1) * cycle + cycle / 2,
        ))),
        PdoTimeout::EscWatchdog => wd.time().map(PdoMonitor::EscWatchdog),
    }
}

/// Longest watchdog tolerance a u16 ms diagnosis value can show.
pub const MAX_WATCHDOG: Nanos = Nanos::from_ms(65_535);

/// P→S check of the SM watchdog settings (E-031, AL 001Fh). Invalid:
/// - a running process-data watchdog (time ≠ 0) with divider 0 (a 80 ns
///   unit: no master means that);
/// - with [`PdoTimeout::EscWatchdog`] (the application relies on the
///   master's SM watchdog, spec §13.2): the watchdog disabled (time 0 or
///   SM2 without its trigger bit while outputs are mapped), shorter than
///   one process-data cycle (`cycle_ns`: it would fire between two frames)
///   or longer than [`MAX_WATCHDOG`] (65535 ms).
pub fn check_watchdog(
    timeout: PdoTimeout,
    wd: &EscWatchdog,
    cycle_ns: u32,
    rx_bytes: usize,
) -> Result<(), AlStatusCode> {
    let invalid = Err(AlStatusCode::INVALID_WATCHDOG_CONFIG);
    if wd.pd_time != 0 && wd.divider == 0 {
        return invalid;
    }
    if timeout == PdoTimeout::EscWatchdog && rx_bytes > 0 {
        match wd.time() {
            None => return invalid,
            Some(t) if t < Nanos::from_ns(u64::from(cycle_ns)) || t > MAX_WATCHDOG => return invalid,
            Some(_) => {}
        }
    }
    Ok(())
}

/// RxPDO frames in a row, each within the tolerance of the previous one,
/// that make the reception "stable and regular" for S→O (E-033).
pub const STEADY_FRAMES: u32 = 3;
/// How long an S→O request waits for stable RxPDO before it is refused
/// (spec §3.3).
pub const STEADY_WAIT: Nanos = Nanos::from_ms(200);

/// Why the slave left Op by itself ([`crate::Slave::take_op_loss`]); the
/// application raises its own event for it (the drive: event 52 with cause
/// 6 or 7, EMCY 7500h, its fault reaction).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OpLoss {
    /// No RxPDO within the monitoring's tolerance, or the ESC's SM watchdog
    /// expired (AL 001Bh).
    PdoTimeout,
    /// In DC mode the application reported a synchronisation fault through
    /// [`crate::Slave::set_sync_state`] (0032h, 0033h, 0034h).
    Sync,
}

/// What the application tells the slave about its synchronisation (the
/// DC-Sync PLL, which the slave does not own) before each
/// [`crate::Slave::poll`], through [`crate::Slave::set_sync_state`].
/// Only used while the mode accepted at P→S is [`SyncMode::DcSync0`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SyncState {
    /// The application supervises the synchronisation (DC mode with its
    /// PLL enabled); `false`: no sync check at S→O, no sync fault in Op.
    pub required: bool,
    /// Whether Safe-Op → Op may go ahead (PLL locked, no latched fault);
    /// otherwise the AL code to refuse with (002Dh no SYNC0, 0032h not
    /// locked, or the latched fault's code).
    pub ready: Result<(), AlStatusCode>,
    /// A latched synchronisation fault (0032h lost lock, 0033h late frames,
    /// 0034h SYNC0 timeout, 001Ah): in Op it drops to Safe-Op with this code
    /// and [`OpLoss::Sync`]. The application clears it when
    /// the master acknowledges the error ([`crate::Slave::take_error_ack`]).
    pub fault: Option<AlStatusCode>,
}

impl SyncState {
    /// Not supervised (free run, SM-Sync, PLL disabled): no sync checks.
    pub const NONE: Self = Self {
        required: false,
        ready: Ok(()),
        fault: None,
    };
}

impl Default for SyncState {
    fn default() -> Self {
        Self::NONE
    }
}

#[cfg(test)]
mod boot_tests {
    use super::*;

    const ALL: [AlState; 5] = [
        AlState::Init,
        AlState::PreOp,
        AlState::Bootstrap,
        AlState::SafeOp,
        AlState::Op,
    ];

    #[test]
    fn e022_e023_bootstrap_through_init_only_with_foe() {
        use AlState::*;
        for from in ALL {
            for to in ALL {
                let with = target_with_boot(from, to.code(), true);
                let want = match (from, to) {
                    _ if from == to => Ok(None),
                    (Init, Bootstrap) | (Bootstrap, Init) => Ok(Some(to)),
                    (Bootstrap, _) | (_, Bootstrap) => Err(AlStatusCode::INVALID_STATE_CHANGE),
                    _ => target(from, to.code()),
                };
                assert_eq!(with, want, "{from:?} -> {to:?} with FoE");
            }
            // without FoE: 0013h from everywhere, as before
            assert_eq!(
                target(from, 3),
                Err(AlStatusCode::BOOTSTRAP_NOT_SUPPORTED),
                "{from:?} -> Boot without FoE"
            );
        }
        assert!(mailbox_on(Bootstrap));
        assert!(!process_data_on(Bootstrap));
    }
}
