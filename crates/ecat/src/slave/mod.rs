//! The slave: ESM + mailbox + CoE dispatch + process data, driven by `poll`.

mod al;
mod mailbox;
mod monitor;

use mailbox::Mailbox;

use crate::app::{Application, DcRequest};
use crate::coe::{service, CoeConfig, CoeHeader, CoeServer, CommState, Dictionary, COE_HEADER_LEN};
use crate::desc::Device;
use crate::emcy::{self, Emcy, EmcyQueue};
use crate::eoe::{EoeServer, EthernetPort, NoEthernet};
use crate::esm::{
    self, EscWatchdog, OpLoss, PdoMonitor, SyncMode, SyncState, MAX_MAILBOX_LEN, MAX_PDO_BYTES,
};
use crate::foe::{FoeHandler, FoeServer, NoFiles, FOE_HEADER_LEN};
use crate::mailbox::{next_counter, MailboxError, MailboxHeader, MailboxType, HEADER_LEN};
use esc::regs::{self, al_event};
use esc::sm::{activate, pdi_control, status};
use esc::{AlControl, AlState, AlStatus, AlStatusCode, Pdi, PdiExt, SyncManager};
use nanos::Nanos;

/// An AL control request the slave processed: a state change or a refusal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StateChange {
    /// State before the request.
    pub from: AlState,
    /// State after it (`from` when refused).
    pub to: AlState,
    /// The requested state code (AL control bits 0..3).
    pub requested: u8,
    /// The AL status code (0 on success).
    pub code: AlStatusCode,
    /// The slave left the state on its own (PDO timeout / SM watchdog / sync
    /// fault, E-038:
    /// red LED single flash); `requested` is then the state it left.
    pub unsolicited: bool,
}

impl core::fmt::Display for StateChange {
    /// `Init -> PreOp`, or `PreOp: request 8 refused, AL status code 0x0011`.
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        if self.unsolicited {
            write!(
                f,
                "{:?} -> {:?} (unsolicited, AL status code {:#06x})",
                self.from, self.to, self.code.0
            )
        } else if self.code == AlStatusCode::NO_ERROR {
            write!(f, "{:?} -> {:?}", self.from, self.to)
        } else {
            write!(
                f,
                "{:?}: request {} refused, AL status code {:#06x}",
                self.from, self.requested, self.code.0
            )
        }
    }
}

static ZEROS: [u8; MAX_PDO_BYTES] = [0; MAX_PDO_BYTES];

/// Emergencies the slave holds while the mailbox is busy (the oldest is dropped beyond).
pub const EMCY_QUEUE: usize = 8;

/// Output / input SyncManager parameter objects (spec §11.9).
pub const SM_OUTPUT_PARAMETER: u16 = 0x1C32;
/// Input SyncManager parameter object.
pub const SM_INPUT_PARAMETER: u16 = 0x1C33;

/// The synchronisation the slave accepted at the last P→S (spec §11), and
/// the RxPDO monitoring (spec §13.1–13.2): what `1C32h`/`1C33h` and the
/// application's diagnosis show.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SyncStatus {
    /// Mode accepted at P→S.
    pub mode: SyncMode,
    /// Process-data cycle, ns: the SYNC0 cycle in DC mode, else `1C32h:02`
    /// (the application's cycle when that is 0).
    pub cycle_ns: u32,
    /// Drive cycles per SYNC0 cycle (DC), 1 otherwise.
    pub k: u32,
    /// The RxPDO monitoring in force (set at S→O from the application's
    /// [`PdoTimeout`](crate::app::PdoTimeout)).
    pub monitor: Option<PdoMonitor>,
    /// The PDO timeout / SM watchdog triggered (until the master's next
    /// acknowledged request).
    pub triggered: bool,
    /// How often it triggered.
    pub trigger_count: u16,
    /// The last state change was unsolicited (E-038) until the master's
    /// next acknowledged request.
    pub unsolicited: bool,
}

/// The EtherCAT slave stack (sans-IO). See the crate documentation.
#[derive(Clone)]
pub struct Slave {
    desc: &'static Device,
    state: AlState,
    error: bool,
    code: AlStatusCode,
    started: bool,
    mbx: Mailbox,
    /// CoE server: SDO transfers and SDO Info fragments spanning mailbox messages.
    coe: CoeServer,
    /// FoE server: the file download in Bootstrap (devices that declare FoE).
    foe: FoeServer,
    /// EoE server: Ethernet frames and IP parameters (Pre-Op, Safe-Op, Op).
    eoe: EoeServer,
    /// Emergencies waiting for a free SM1 (sent before the next response).
    emcy: EmcyQueue<EMCY_QUEUE>,
    /// Lengths of the assigned RxPDOs and TxPDOs (bytes), from the dictionary.
    pdo_bytes: (usize, usize),
    out_len: usize,
    in_len: usize,
    out_start: u16,
    in_start: u16,
    inputs: [u8; MAX_PDO_BYTES],
    outputs: [u8; MAX_PDO_BYTES],
    rx_frames: u32,
    /// Times of the last [`esm::STEADY_FRAMES`] RxPDO frames (newest first).
    rx_times: [Nanos; esm::STEADY_FRAMES as usize],
    /// Frames recorded in `rx_times` (saturating).
    rx_seen: u32,
    /// An S→O request waiting for stable RxPDO since this time (E-033).
    pending_op: Option<Nanos>,
    /// `rx_frames` when that request came: none since means "no valid
    /// outputs" (AL 002Bh) rather than "not steady" (001Bh) at the refusal.
    pending_op_frames: u32,
    /// When Op was last entered (start of the PDO timeout).
    op_entry: Nanos,
    sync: SyncStatus,
    /// The application's synchronisation state (DC-Sync PLL), set before each poll.
    sync_state: SyncState,
    /// The master acknowledged an error indication since the last
    /// [`Slave::take_error_ack`].
    error_acked: bool,
    /// Why the slave left Op by itself since the last [`Slave::take_op_loss`].
    op_loss: Option<OpLoss>,
    /// The mailbox SyncManager the last I→P check refused.
    mailbox_fault: Option<u8>,
    /// The explicit device identification value set by the application
    /// (`None`: the station alias, register 0x0012).
    identification: Option<u16>,
    /// The ID shown in 0x0134 (AL status bit 5) after an ID request.
    id_loaded: Option<u16>,
}

impl Slave {
    /// A slave in Init for the device `desc`.
    pub fn new(desc: &'static Device) -> Self {
        Self {
            desc,
            state: AlState::Init,
            error: false,
            code: AlStatusCode::NO_ERROR,
            started: false,
            mbx: Mailbox {
                rx_start: 0,
                rx_len: 0,
                tx_start: 0,
                tx_len: 0,
                rx: [0; MAX_MAILBOX_LEN],
                tx: [0; MAX_MAILBOX_LEN],
                tx_valid: false,
                pending: false,
                last_counter: 0,
                counter: 0,
            },
            coe: CoeServer::new(CoeConfig::from_details(desc.coe_details)),
            foe: FoeServer::new(),
            eoe: EoeServer::new(),
            emcy: EmcyQueue::new(),
            pdo_bytes: (desc.output_bytes(), desc.input_bytes()),
            out_len: desc.output_bytes().min(MAX_PDO_BYTES),
            in_len: desc.input_bytes().min(MAX_PDO_BYTES),
            out_start: desc.outputs.start,
            in_start: desc.inputs.start,
            inputs: [0; MAX_PDO_BYTES],
            outputs: [0; MAX_PDO_BYTES],
            rx_frames: 0,
            rx_times: [Nanos::ZERO; esm::STEADY_FRAMES as usize],
            rx_seen: 0,
            pending_op: None,
            pending_op_frames: 0,
            op_entry: Nanos::ZERO,
            sync: SyncStatus {
                k: 1,
                ..SyncStatus::default()
            },
            sync_state: SyncState::NONE,
            error_acked: false,
            op_loss: None,
            mailbox_fault: None,
            identification: None,
            id_loaded: None,
        }
    }

    /// Sets the value explicit device identification reports (ETG.1000.6:
    /// AL control bit 5 → the ID in 0x0134, AL status bit 5); `None` (the
    /// default) reports the station alias the ESC loaded from the SII
    /// (0x0012). Takes effect at the next ID request.
    pub fn set_identification(&mut self, id: Option<u16>) {
        self.identification = id;
    }

    /// The synchronisation and RxPDO monitoring state (1C32h/1C33h and the
    /// application's diagnosis).
    pub fn sync_status(&self) -> &SyncStatus {
        &self.sync
    }

    /// The application's synchronisation state (its DC-Sync PLL), to be set
    /// before each [`poll`](Self::poll). Used only while the mode accepted at
    /// P→S is DC SYNC0 and `state.required`: S→O then waits (up to 200 ms,
    /// like the steady-RxPDO wait) for `state.ready` and is refused with its
    /// code; in Op `state.fault` drops to Safe-Op with that code, EMCY 7500h
    /// (event 52 cause 7) and an unsolicited state change (spec §3.3, E-046,
    /// E-131, E-038).
    pub fn set_sync_state(&mut self, state: SyncState) {
        self.sync_state = state;
    }

    /// The synchronisation state last set by the application.
    pub fn sync_state(&self) -> &SyncState {
        &self.sync_state
    }

    /// Whether the master acknowledged an error indication (AL control with
    /// the acknowledge bit while the error was set) since the last call; the
    /// application then clears its latched faults (e.g. `Pll::clear_fault`).
    pub fn take_error_ack(&mut self) -> bool {
        core::mem::take(&mut self.error_acked)
    }

    /// Why the slave left Op for Safe-Op by itself since the last call (a
    /// PDO timeout or a synchronisation fault): the application raises its
    /// event for it (its EMCY and fault reaction; the drive: event 52).
    pub fn take_op_loss(&mut self) -> Option<OpLoss> {
        self.op_loss.take()
    }

    /// The mailbox SyncManager (0 = master → slave, 1 = slave → master)
    /// the last Init → Pre-Op / Bootstrap request was refused for (AL 0016h),
    /// `None` when it passed.
    pub fn mailbox_fault(&self) -> Option<u8> {
        self.mailbox_fault
    }

    /// The RUN LED's pattern now (E-133, [`crate::led::run`]).
    pub fn run_led(&self) -> crate::led::Pattern {
        crate::led::run(self.state)
    }

    /// The ERR LED's pattern now (E-132, [`crate::led::err`]).
    pub fn err_led(&self) -> crate::led::Pattern {
        crate::led::err(self.error, self.sync.unsolicited, self.code)
    }

    /// Whether an S→O request waits for stable RxPDO (E-033) or for the
    /// synchronisation (DC mode).
    pub fn op_pending(&self) -> bool {
        self.pending_op.is_some()
    }

    /// The device description.
    pub fn device(&self) -> &'static Device {
        self.desc
    }

    /// Current ESM state.
    pub fn state(&self) -> AlState {
        self.state
    }

    /// Current AL status code (0 = no error).
    pub fn al_status_code(&self) -> AlStatusCode {
        self.code
    }

    /// Queues an emergency (device fault, fault cleared, EoE error); it is sent
    /// through the mailbox from Pre-Op on, before the next SDO response.
    pub fn emergency(&mut self, e: Emcy) {
        self.emcy.push(e);
    }

    /// Emergencies waiting to be sent.
    pub fn emergencies_pending(&self) -> usize {
        self.emcy.len()
    }

    /// Whether the AL status error indication is set.
    pub fn error(&self) -> bool {
        self.error
    }

    /// The inputs (TxPDO image, SM3) the application fills; copied to the ESC
    /// every poll in Safe-Op and Op.
    pub fn inputs_mut(&mut self) -> &mut [u8] {
        self.inputs.get_mut(..self.in_len).unwrap_or_default()
    }

    /// The outputs (RxPDO image, SM2) last received in Op; all zero below Op
    /// (E-032, E-035).
    pub fn outputs(&self) -> &[u8] {
        let buf = if self.state == AlState::Op {
            &self.outputs
        } else {
            &ZEROS
        };
        buf.get(..self.out_len).unwrap_or_default()
    }

    /// Number of RxPDO frames read from SM2 since the last P→S.
    pub fn outputs_received(&self) -> u32 {
        self.rx_frames
    }

    /// Whether the device declares FoE (SII mailbox protocols): it then supports
    /// the Bootstrap state for the firmware download.
    pub fn foe_supported(&self) -> bool {
        self.desc.mailbox_protocols & esc::sii::mailbox_protocol::FOE != 0
    }

    /// The FoE server (transfer state, timeouts).
    pub fn foe(&self) -> &FoeServer {
        &self.foe
    }

    /// Whether the device declares EoE (SII mailbox protocols).
    pub fn eoe_supported(&self) -> bool {
        self.desc.mailbox_protocols & esc::sii::mailbox_protocol::EOE != 0
    }

    /// The EoE server: the IP parameters the master set, counters.
    pub fn eoe(&self) -> &EoeServer {
        &self.eoe
    }

    /// One step of the stack: AL control requests, mailbox, process data.
    /// Returns the processed AL control request when it changed the state or was
    /// refused. FoE requests are refused ([`NoFiles`]); see
    /// [`poll_with_foe`](Self::poll_with_foe).
    pub fn poll<P: Pdi, A: Application>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        now: Nanos,
    ) -> Result<Option<StateChange>, P::Error> {
        self.poll_with_foe(pdi, app, &mut NoFiles, now)
    }

    /// [`poll`](Self::poll) with the application's FoE file handler (the
    /// firmware slots): FoE writes in Bootstrap go to `foe`; a transfer in
    /// progress ends when the slave leaves Bootstrap or after
    /// [`crate::foe::FOE_TIMEOUT`] without a packet.
    pub fn poll_with_foe<P: Pdi, A: Application, H: FoeHandler>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        foe: &mut H,
        now: Nanos,
    ) -> Result<Option<StateChange>, P::Error> {
        self.poll_with_eoe(pdi, app, foe, &mut NoEthernet, now)
    }

    /// [`poll_with_foe`](Self::poll_with_foe) with the application's
    /// Ethernet interface (devices that declare EoE, from Pre-Op on, E-095):
    /// complete frames tunnelled by the master go to `eth.receive`, frames
    /// from `eth.transmit` go out in fragments, one per mailbox message, when
    /// SM1 is free; set-IP-parameter requests are answered here (E-096,
    /// E-097, EMCY FFF0h on refusal, E-093).
    pub fn poll_with_eoe<P: Pdi, A: Application, H: FoeHandler, E: EthernetPort>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        foe: &mut H,
        eth: &mut E,
        now: Nanos,
    ) -> Result<Option<StateChange>, P::Error> {
        let (events, change) = self.poll_al_control(pdi, app, now)?;
        self.mailbox_step(pdi, app, foe, eth, events, now)?;
        self.poll_process_data(pdi, app, events, change, now)
    }

    /// The ESC-event part of [`poll_with_eoe`](Self::poll_with_eoe) for a
    /// high-priority task: AL control, process data and its monitoring,
    /// without the mailbox. Run [`poll_mailbox_only`](Self::poll_mailbox_only)
    /// at a lower priority to serve the mailbox.
    pub fn poll_esc<P: Pdi, A: Application>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        now: Nanos,
    ) -> Result<Option<StateChange>, P::Error> {
        let (events, change) = self.poll_al_control(pdi, app, now)?;
        self.poll_process_data(pdi, app, events, change, now)
    }

    /// The mailbox part of [`poll_with_eoe`](Self::poll_with_eoe) for a
    /// low-priority task: one request from SM0 (CoE, EoE, FoE) answered
    /// into SM1, the EMCY queue, SDO Info fragments, outgoing EoE fragments
    /// and the FoE timeout. Nothing happens outside the mailbox states.
    pub fn poll_mailbox_only<P: Pdi, A: Application, H: FoeHandler, E: EthernetPort>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        foe: &mut H,
        eth: &mut E,
        now: Nanos,
    ) -> Result<(), P::Error> {
        let events = pdi.al_event()?;
        self.mailbox_step(pdi, app, foe, eth, events, now)
    }
}

/// E-095: EoE runs in Pre-Op, Safe-Op and Op (not in Init or Bootstrap).
fn eoe_on(state: AlState) -> bool {
    matches!(state, AlState::PreOp | AlState::SafeOp | AlState::Op)
}

/// Reads an unsigned entry of up to 4 bytes (little-endian) through the
/// dictionary; `None` if it is missing or unreadable.
fn read_uint<A: Dictionary>(app: &mut A, index: u16, sub: u8) -> Option<u32> {
    let mut buf = [0u8; 4];
    let n = app.read(index, sub, &mut buf, CommState::PreOp).ok()?;
    let bytes = buf.get(..n)?;
    Some(bytes.iter().rev().fold(0u32, |v, &b| (v << 8) | u32::from(b)))
}
