//! The slave: ESM + mailbox + CoE dispatch + process data, driven by `poll`.

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

/// Mailbox state: the SM areas as configured at I→P, the request buffer and the
/// last (or pending) response.
struct Mailbox {
    rx_start: u16,
    rx_len: usize,
    tx_start: u16,
    tx_len: usize,
    rx: [u8; MAX_MAILBOX_LEN],
    tx: [u8; MAX_MAILBOX_LEN],
    /// `tx` holds a response (for a repeat request).
    tx_valid: bool,
    /// `tx` holds a response not yet written into SM1.
    pending: bool,
    /// Counter of the last request (duplicate detection).
    last_counter: u8,
    /// Counter of the last response.
    counter: u8,
}

impl Mailbox {
    /// Completes the response whose `len` data bytes are in `tx` after the
    /// header: zero fill, next counter, header; the response is pending.
    fn queue(&mut self, kind: MailboxType, len: usize) {
        if let Some(rest) = self
            .tx
            .get_mut(..self.tx_len)
            .and_then(|t| t.get_mut(HEADER_LEN.saturating_add(len)..))
        {
            rest.fill(0);
        }
        self.counter = next_counter(self.counter);
        let header = MailboxHeader {
            length: len as u16,
            address: 0,
            channel: 0,
            priority: 0,
            kind,
            counter: self.counter,
        };
        if let Some(head) = self.tx.get_mut(..HEADER_LEN) {
            head.copy_from_slice(&header.to_bytes());
        }
        self.tx_valid = true;
        self.pending = true;
    }
}

/// The EtherCAT slave stack (sans-IO). See the crate documentation.
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
    rx_times: [u64; esm::STEADY_FRAMES as usize],
    /// Frames recorded in `rx_times` (saturating).
    rx_seen: u32,
    /// An S→O request waiting for stable RxPDO since this time (E-033).
    pending_op: Option<u64>,
    /// When Op was last entered (start of the PDO timeout).
    op_entry_ns: u64,
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
            rx_times: [0; esm::STEADY_FRAMES as usize],
            rx_seen: 0,
            pending_op: None,
            op_entry_ns: 0,
            sync: SyncStatus {
                k: 1,
                ..SyncStatus::default()
            },
            sync_state: SyncState::NONE,
            error_acked: false,
            op_loss: None,
            mailbox_fault: None,
        }
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
        now_ns: u64,
    ) -> Result<Option<StateChange>, P::Error> {
        self.poll_with_foe(pdi, app, &mut NoFiles, now_ns)
    }

    /// [`poll`](Self::poll) with the application's FoE file handler (the
    /// firmware slots): FoE writes in Bootstrap go to `foe`; a transfer in
    /// progress ends when the slave leaves Bootstrap or after
    /// [`crate::foe::FOE_TIMEOUT_NS`] without a packet.
    pub fn poll_with_foe<P: Pdi, A: Application, H: FoeHandler>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        foe: &mut H,
        now_ns: u64,
    ) -> Result<Option<StateChange>, P::Error> {
        self.poll_with_eoe(pdi, app, foe, &mut NoEthernet, now_ns)
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
        now_ns: u64,
    ) -> Result<Option<StateChange>, P::Error> {
        let (events, change) = self.poll_al_control(pdi, app, now_ns)?;
        self.mailbox_step(pdi, app, foe, eth, events, now_ns)?;
        self.poll_process_data(pdi, app, events, change, now_ns)
    }

    /// The ESC-event part of [`poll_with_eoe`](Self::poll_with_eoe) for a
    /// high-priority task: AL control, process data and its monitoring,
    /// without the mailbox. Run [`poll_mailbox_only`](Self::poll_mailbox_only)
    /// at a lower priority to serve the mailbox.
    pub fn poll_esc<P: Pdi, A: Application>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        now_ns: u64,
    ) -> Result<Option<StateChange>, P::Error> {
        let (events, change) = self.poll_al_control(pdi, app, now_ns)?;
        self.poll_process_data(pdi, app, events, change, now_ns)
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
        now_ns: u64,
    ) -> Result<(), P::Error> {
        let events = pdi.al_event()?;
        self.mailbox_step(pdi, app, foe, eth, events, now_ns)
    }

    /// The AL event request register and the AL control request it carries.
    fn poll_al_control<P: Pdi, A: Application>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        now_ns: u64,
    ) -> Result<(u32, Option<StateChange>), P::Error> {
        if !self.started {
            self.write_status(pdi)?;
            self.started = true;
        }
        let events = pdi.al_event()?;
        if let Some(bytes) = app.process_data_bytes() {
            self.pdo_bytes = bytes;
        }
        let change = if events & al_event::AL_CONTROL != 0 {
            self.al_control(pdi, app, now_ns)?
        } else {
            None
        };
        if !eoe_on(self.state) {
            self.eoe.reset();
        }
        Ok((events, change))
    }

    fn mailbox_step<P: Pdi, A: Application, H: FoeHandler, E: EthernetPort>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        foe: &mut H,
        eth: &mut E,
        events: u32,
        now_ns: u64,
    ) -> Result<(), P::Error> {
        if self.state != AlState::Bootstrap {
            self.foe.reset(foe);
        }
        if esm::mailbox_on(self.state) {
            self.poll_mailbox(pdi, app, foe, eth, events, now_ns)?;
        }
        Ok(())
    }

    fn poll_process_data<P: Pdi, A: Application>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        events: u32,
        mut change: Option<StateChange>,
        now_ns: u64,
    ) -> Result<Option<StateChange>, P::Error> {
        if esm::process_data_on(self.state) {
            self.process_data(pdi, events, now_ns)?;
        }
        if change.is_none() {
            change = self.pending_op(pdi, app, now_ns)?;
        }
        if change.is_none() && self.state == AlState::Op {
            change = self.monitor_rxpdo(pdi, events, now_ns)?;
        }
        if change.is_none() && self.state == AlState::Op {
            change = self.monitor_sync(pdi)?;
        }
        Ok(change)
    }

    /// E-033: answers a waiting S→O request once the RxPDO is steady and
    /// (DC mode) the synchronisation ready, or refuses it after
    /// [`esm::STEADY_WAIT_NS`] (with the synchronisation's code when that is
    /// what is missing).
    fn pending_op<P: Pdi, A: Application>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        now_ns: u64,
    ) -> Result<Option<StateChange>, P::Error> {
        let Some(since) = self.pending_op else {
            return Ok(None);
        };
        if self.state != AlState::SafeOp {
            self.pending_op = None;
            return Ok(None);
        }
        let sync = self.sync_ready();
        let result = if self.outputs_steady(now_ns) && sync.is_ok() {
            self.transition(pdi, app, AlState::SafeOp, AlState::Op, now_ns)?
        } else if now_ns.wrapping_sub(since) > esm::STEADY_WAIT_NS {
            // spec §3.3 "S→O: SYNC0 present, PLL locked": 002Dh / 0032h / …
            if let Err(code) = sync {
                Err(code)
            } else {
                // Not stable within 200 ms: refused. The spec names no AL code
                // (§3.3: 001Bh or 002Bh); 001Bh "SM watchdog" is the one §4 ties to
                // "no RxPDO received, or not within the tolerated time". The
                // application's diagnosis tells this refusal by the code and `from`.
                Err(AlStatusCode::SM_WATCHDOG)
            }
        } else {
            return Ok(None);
        };
        self.pending_op = None;
        match result {
            Ok(()) => {
                self.state = AlState::Op;
                self.error = false;
                self.code = AlStatusCode::NO_ERROR;
            }
            Err(code) => {
                self.error = true;
                self.code = code;
            }
        }
        self.write_status(pdi)?;
        Ok(Some(StateChange {
            from: AlState::SafeOp,
            to: self.state,
            requested: AlState::Op.code(),
            code: self.code,
            unsolicited: false,
        }))
    }

    /// Whether the RxPDO is "stable and regular" for S→O (E-033): with
    /// monitoring on, the last [`esm::STEADY_FRAMES`] frames each
    /// within the tolerance of the previous one and the newest within the
    /// tolerance of `now_ns`. With monitoring off nothing is required: the
    /// drive would never notice missing frames in Op either, and masters
    /// that request Op before their cyclic task runs (ethercrab's `into_op`)
    /// still get there.
    fn outputs_steady(&self, now_ns: u64) -> bool {
        let Some(m) = self.sync.monitor else {
            return true;
        };
        let tol = m.tolerance_ns();
        if self.rx_seen < esm::STEADY_FRAMES {
            return false;
        }
        let mut newer = now_ns;
        for &t in &self.rx_times {
            if newer.wrapping_sub(t) > tol {
                return false;
            }
            newer = t;
        }
        true
    }

    /// In Op (E-044, E-126…E-128): a PDO timeout or an expired SM watchdog
    /// leaves Op for Safe-Op with the error indication, AL 001Bh, EMCY 7500h
    /// (event 52, cause 6) and an unsolicited state change (E-038). Only in
    /// Op, so a master leaving Op on purpose never triggers it.
    fn monitor_rxpdo<P: Pdi>(
        &mut self,
        pdi: &mut P,
        events: u32,
        now_ns: u64,
    ) -> Result<Option<StateChange>, P::Error> {
        let expired = match self.sync.monitor {
            None => false,
            Some(PdoMonitor::Timeout(t)) => {
                let newest = self.rx_times.first().copied().filter(|_| self.rx_seen > 0);
                let last = newest.map_or(self.op_entry_ns, |t| t.max(self.op_entry_ns));
                now_ns.wrapping_sub(last) > t
            }
            Some(PdoMonitor::EscWatchdog(_)) => {
                // the event is cleared by reading 0x0440; bit 0 = 0: expired
                events & al_event::WATCHDOG_PD != 0 && pdi.read_u16(regs::WATCHDOG_STATUS_PD)? & 1 == 0
            }
        };
        if !expired {
            return Ok(None);
        }
        self.state = AlState::SafeOp;
        self.error = true;
        self.code = AlStatusCode::SM_WATCHDOG;
        self.sync.triggered = true;
        self.sync.trigger_count = self.sync.trigger_count.saturating_add(1);
        self.sync.unsolicited = true;
        self.op_loss = Some(OpLoss::PdoTimeout);
        self.write_status(pdi)?;
        Ok(Some(StateChange {
            from: AlState::Op,
            to: AlState::SafeOp,
            requested: AlState::Op.code(),
            code: self.code,
            unsolicited: true,
        }))
    }

    /// The synchronisation is supervised: DC SYNC0 accepted at P→S and the
    /// application says it checks it ([`SyncState::required`]).
    fn sync_supervised(&self) -> bool {
        self.sync.mode == SyncMode::DcSync0 && self.sync_state.required
    }

    /// S→O condition of the synchronisation (spec §3.3): `Ok` when not
    /// supervised.
    fn sync_ready(&self) -> Result<(), AlStatusCode> {
        if self.sync_supervised() {
            self.sync_state.ready
        } else {
            Ok(())
        }
    }

    /// In Op in DC mode (spec §3.3, E-046, E-131): a synchronisation fault
    /// the application reports (SYNC0 timeout 0034h, late frames 0033h, lost
    /// lock 0032h) leaves Op for Safe-Op with the error indication and that
    /// code, EMCY 7500h (event 52, cause 7) and an unsolicited state change
    /// (E-038). Not an RxPDO monitoring trigger (`triggered` is left alone).
    fn monitor_sync<P: Pdi>(&mut self, pdi: &mut P) -> Result<Option<StateChange>, P::Error> {
        if !self.sync_supervised() {
            return Ok(None);
        }
        let Some(code) = self.sync_state.fault else {
            return Ok(None);
        };
        self.state = AlState::SafeOp;
        self.error = true;
        self.code = code;
        self.sync.unsolicited = true;
        self.op_loss = Some(OpLoss::Sync);
        self.write_status(pdi)?;
        Ok(Some(StateChange {
            from: AlState::Op,
            to: AlState::SafeOp,
            requested: AlState::Op.code(),
            code,
            unsolicited: true,
        }))
    }

    fn write_status<P: Pdi>(&self, pdi: &mut P) -> Result<(), P::Error> {
        let status = AlStatus {
            state: self.state,
            error: self.error,
            id_loaded: false,
        };
        pdi.write_u16(regs::AL_STATUS_CODE, self.code.0)?;
        pdi.write_u16(regs::AL_STATUS, status.raw())
    }

    fn al_control<P: Pdi, A: Application>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        now_ns: u64,
    ) -> Result<Option<StateChange>, P::Error> {
        let ctrl = AlControl::from_raw(pdi.read_u16(regs::AL_CONTROL)?);
        if self.error && !ctrl.ack {
            // ETG.1000.6: a request without acknowledge leaves an error indication as it is
            return Ok(None);
        }
        if self.error && ctrl.ack {
            self.error_acked = true;
        }
        // any processed request replaces a waiting S→O and ends the
        // "unsolicited" / "triggered" indications
        self.pending_op = None;
        self.sync.unsolicited = false;
        self.sync.triggered = false;
        let from = self.state;
        let result = match esm::target_with_boot(from, ctrl.requested, self.foe_supported()) {
            Err(code) => Err(code),
            Ok(None) => Ok(from),
            Ok(Some(AlState::Op)) if from == AlState::SafeOp => {
                self.sync.monitor = self.pdo_monitor(pdi, app)?;
                if !self.outputs_steady(now_ns) || self.sync_ready().is_err() {
                    // E-033: wait (up to 200 ms) for stable RxPDO and, in DC
                    // mode, for the PLL lock; the status stays Safe-Op
                    // without error meanwhile
                    self.pending_op = Some(now_ns);
                    self.error = false;
                    self.code = AlStatusCode::NO_ERROR;
                    self.write_status(pdi)?;
                    return Ok(None);
                }
                self.transition(pdi, app, from, AlState::Op, now_ns)?
                    .map(|()| AlState::Op)
            }
            Ok(Some(to)) => self.transition(pdi, app, from, to, now_ns)?.map(|()| to),
        };
        match result {
            Ok(to) => {
                self.state = to;
                self.error = false;
                self.code = AlStatusCode::NO_ERROR;
            }
            Err(code) => {
                self.error = true;
                self.code = code;
            }
        }
        self.write_status(pdi)?;
        let change = StateChange {
            from,
            to: self.state,
            requested: ctrl.requested,
            code: self.code,
            unsolicited: false,
        };
        Ok((from != self.state || self.error).then_some(change))
    }

    /// Checks and actions of one ESM transition; the outer `Result` is the PDI's.
    fn transition<P: Pdi, A: Application>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        from: AlState,
        to: AlState,
        now_ns: u64,
    ) -> Result<Result<(), AlStatusCode>, P::Error> {
        match (from, to) {
            (AlState::Init, AlState::PreOp | AlState::Bootstrap) => {
                // the bootstrap mailbox is the standard one (the SII says so)
                let (sm0, sm1) = (pdi.read_sm(0)?, pdi.read_sm(1)?);
                self.mailbox_fault = esm::faulty_mailbox_sm(self.desc, &sm0, &sm1);
                if let Err(code) = esm::check_mailbox_sms(self.desc, &sm0, &sm1) {
                    return Ok(Err(code));
                }
                self.start_mailbox(&sm0, &sm1);
            }
            (AlState::PreOp, AlState::SafeOp) => {
                let sms = [pdi.read_sm(0)?, pdi.read_sm(1)?, pdi.read_sm(2)?, pdi.read_sm(3)?];
                let (rx, tx) = self.pdo_bytes;
                // E-029/E-030: the sync mode the master chose
                let activation = pdi.read_u8(regs::dc::ACTIVATION)?;
                let sync_type = read_uint(app, SM_OUTPUT_PARAMETER, 1).and_then(|v| u16::try_from(v).ok());
                let mode = match esm::sync_mode(activation, sync_type) {
                    Ok(mode) => mode,
                    Err(code) => return Ok(Err(code)),
                };
                let [_, _, sm2, _] = &sms;
                if let Err(code) = esm::check_free_run(mode, sm2, rx) {
                    return Ok(Err(code));
                }
                if let Err(refusal) = esm::check_process_sms(self.desc, &sms, rx, tx) {
                    // E-028: EMCY A000h, error register = ESM state (Pre-Op = 2),
                    // diag code 4·SM + fault (spec §8.4)
                    let diag = emcy::diag_code(refusal.sm, refusal.fault);
                    self.emcy.push(Emcy::state_transition(
                        emcy::code::PREOP_TO_SAFEOP,
                        2,
                        diag,
                        [0; 4],
                    ));
                    return Ok(Err(refusal.code));
                }
                let app_cycle_ns = app.cycle_ns();
                let (cycle_ns, k) = match mode {
                    SyncMode::DcSync0 => {
                        let dc = DcRequest {
                            sync0_ns: pdi.read_u32(regs::dc::SYNC0_CYCLE)?,
                            sm2_cycle_ns: read_uint(app, SM_OUTPUT_PARAMETER, 2).unwrap_or(0),
                            sm3_cycle_ns: read_uint(app, SM_INPUT_PARAMETER, 2).unwrap_or(0),
                        };
                        match app.check_dc(&dc) {
                            Ok(k) => (dc.sync0_ns, k),
                            Err(code) => return Ok(Err(code)),
                        }
                    }
                    _ => {
                        let c = read_uint(app, SM_OUTPUT_PARAMETER, 2).unwrap_or(0);
                        (if c == 0 { app_cycle_ns } else { c }, 1)
                    }
                };
                if let Err(code) = self.check_watchdog(pdi, app, sm2, cycle_ns, rx)? {
                    return Ok(Err(code));
                }
                self.sync.mode = mode;
                self.sync.cycle_ns = cycle_ns;
                self.sync.k = k;
                self.sync.monitor = None;
                if mode == SyncMode::DcSync0 {
                    // 1C32h/1C33h:01/:02 show what runs (the master may only
                    // have written 0x0981); ignored if the application refuses
                    for index in [SM_OUTPUT_PARAMETER, SM_INPUT_PARAMETER] {
                        let _ = app.write(index, 1, &mode.sync_type().to_le_bytes(), CommState::PreOp);
                        let _ = app.write(index, 2, &cycle_ns.to_le_bytes(), CommState::PreOp);
                    }
                }
                let [_, _, sm2, sm3] = sms;
                self.out_start = sm2.start;
                self.in_start = sm3.start;
                // the process image follows the mapping checked above (E-019: a remap
                // takes effect at the next P→S)
                self.out_len = rx.min(MAX_PDO_BYTES);
                self.in_len = tx.min(MAX_PDO_BYTES);
                self.rx_frames = 0;
                self.rx_seen = 0;
            }
            (AlState::SafeOp, AlState::Op) => {
                // the steadiness (E-033) was checked by the caller
                self.outputs.fill(0);
                // the PDO timeout runs from the entry into Op at the earliest
                self.op_entry_ns = now_ns;
                if let Some(PdoMonitor::EscWatchdog(_)) = self.sync.monitor {
                    // clears an SM watchdog event left over from Safe-Op
                    let _ = pdi.read_u16(regs::WATCHDOG_STATUS_PD)?;
                }
            }
            // downward transitions always succeed
            _ => {}
        }
        if to == AlState::Init {
            self.mbx.pending = false;
            self.mbx.tx_valid = false;
            self.coe.reset();
        }
        Ok(Ok(()))
    }

    /// The ESC's process-data watchdog as the master set it up.
    fn esc_watchdog<P: Pdi>(pdi: &mut P, sm2: &SyncManager) -> Result<EscWatchdog, P::Error> {
        Ok(EscWatchdog {
            divider: pdi.read_u16(regs::WATCHDOG_DIVIDER)?,
            pd_time: pdi.read_u16(regs::WATCHDOG_TIME_PD)?,
            sm2_trigger: sm2.control().watchdog(),
        })
    }

    /// P→S: the SM watchdog settings against the application's RxPDO
    /// monitoring (E-031, AL 001Fh; see [`esm::check_watchdog`]).
    fn check_watchdog<P: Pdi, A: Application>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        sm2: &SyncManager,
        cycle_ns: u32,
        rx_bytes: usize,
    ) -> Result<Result<(), AlStatusCode>, P::Error> {
        let wd = Self::esc_watchdog(pdi, sm2)?;
        Ok(esm::check_watchdog(app.pdo_timeout(), &wd, cycle_ns, rx_bytes))
    }

    /// The RxPDO monitoring the application asks for now (read at each S→O
    /// request).
    fn pdo_monitor<P: Pdi, A: Application>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
    ) -> Result<Option<PdoMonitor>, P::Error> {
        if self.out_len == 0 {
            return Ok(None);
        }
        let sm2 = pdi.read_sm(2)?;
        let wd = Self::esc_watchdog(pdi, &sm2)?;
        Ok(esm::pdo_monitor(app.pdo_timeout(), self.sync.cycle_ns, &wd))
    }

    fn start_mailbox(&mut self, sm0: &SyncManager, sm1: &SyncManager) {
        let m = &mut self.mbx;
        m.rx_start = sm0.start;
        m.rx_len = usize::from(sm0.length).min(MAX_MAILBOX_LEN);
        m.tx_start = sm1.start;
        m.tx_len = usize::from(sm1.length).min(MAX_MAILBOX_LEN);
        m.tx_valid = false;
        m.pending = false;
        m.last_counter = 0;
        m.counter = 0;
        self.coe.reset();
    }

    fn poll_mailbox<P: Pdi, A: Application, H: FoeHandler, E: EthernetPort>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        foe: &mut H,
        eth: &mut E,
        events: u32,
        now_ns: u64,
    ) -> Result<(), P::Error> {
        let sm1 = pdi.read_sm(1)?;
        let mut full = sm1.status & status::MAILBOX_FULL != 0;
        let repeat = sm1.activate & activate::REPEAT != 0;
        if repeat != (sm1.pdi_control & pdi_control::REPEAT_ACK != 0) {
            // Repeat request: the master lost the last response. If SM1 is still
            // full, that response is still there; else write it again.
            if !full && self.mbx.tx_valid {
                self.write_response(pdi)?;
                full = true;
            }
            let ack = if repeat { pdi_control::REPEAT_ACK } else { 0 };
            pdi.write_u8(
                regs::sm(1) + 7,
                (sm1.pdi_control & !pdi_control::REPEAT_ACK) | ack,
            )?;
        }
        // A pending response holds the request back (SM0 stays full: flow control).
        if !self.mbx.pending && events & al_event::sm(0) != 0 {
            let m = &mut self.mbx;
            if let Some(rx) = m.rx.get_mut(..m.rx_len) {
                pdi.read(m.rx_start, rx)?;
                self.handle_request(app, foe, eth, now_ns);
                if let Some(e) = self.eoe.take_emcy() {
                    self.emcy.push(e);
                }
            }
        }
        self.coe.tick(now_ns);
        self.foe.tick(foe, now_ns);
        // emergencies go out first once SM1 is free (E-094: through the mailbox);
        // not in Bootstrap (FoE only), they wait
        if !self.mbx.pending && self.state != AlState::Bootstrap {
            if let Some(e) = self.emcy.pop() {
                self.queue_emcy(&e);
            }
        }
        // the next SDO Info fragment once the previous response has left
        if !self.mbx.pending && self.coe.has_fragments() {
            self.next_fragment(app);
        }
        // then the next outgoing EoE fragment (E-095)
        if !self.mbx.pending && eoe_on(self.state) && self.eoe_supported() {
            let m = &mut self.mbx;
            if let Some(body) = m.tx.get_mut(HEADER_LEN..m.tx_len) {
                if let Some(len) = self.eoe.next_fragment(body, eth) {
                    m.queue(MailboxType::Eoe, len);
                }
            }
        }
        if self.mbx.pending && !full {
            self.write_response(pdi)?;
        }
        Ok(())
    }

    fn write_response<P: Pdi>(&mut self, pdi: &mut P) -> Result<(), P::Error> {
        if let Some(tx) = self.mbx.tx.get(..self.mbx.tx_len) {
            pdi.write(self.mbx.tx_start, tx)?;
        }
        self.mbx.pending = false;
        Ok(())
    }

    /// Handles the request in `mbx.rx`; a response goes to `mbx.tx` and is pending.
    fn handle_request<A: Application, H: FoeHandler, E: EthernetPort>(
        &mut self,
        app: &mut A,
        foe: &mut H,
        eth: &mut E,
        now_ns: u64,
    ) {
        let state = self.state;
        let boot = state == AlState::Bootstrap;
        let foe_on = self.foe_supported();
        let eoe = self.eoe_supported() && eoe_on(state);
        let m = &mut self.mbx;
        let rx = m.rx.get(..m.rx_len).unwrap_or_default();
        let Some(body) = m.tx.get_mut(HEADER_LEN..m.tx_len) else {
            return;
        };
        let reply = match MailboxHeader::check(rx) {
            Err(e) => Err(e),
            Ok(h) if h.counter != 0 && h.counter == m.last_counter => return, // duplicate
            Ok(h) => {
                m.last_counter = h.counter;
                let payload = h.payload(rx).unwrap_or_default();
                match h.kind {
                    // Bootstrap: FoE only
                    MailboxType::Foe if foe_on => {
                        let max_data = m.rx_len.saturating_sub(HEADER_LEN + FOE_HEADER_LEN);
                        self.foe
                            .handle(payload, body, foe, boot, max_data, now_ns)
                            .map(|n| n.map(|n| (MailboxType::Foe, n)))
                    }
                    MailboxType::Coe if !boot => self
                        .coe
                        .handle(payload, body, app, state, now_ns)
                        .map(|n| n.map(|n| (MailboxType::Coe, n))),
                    // E-095: Pre-Op, Safe-Op and Op
                    MailboxType::Eoe if eoe => self
                        .eoe
                        .handle(payload, body, eth)
                        .map(|n| n.map(|n| (MailboxType::Eoe, n))),
                    _ => Err(MailboxError::UNSUPPORTED_PROTOCOL),
                }
            }
        };
        let (kind, len) = match reply {
            Ok(Some(r)) => r,
            Ok(None) => return,
            Err(e) => {
                let data = e.to_bytes();
                match body.get_mut(..data.len()) {
                    Some(b) => b.copy_from_slice(&data),
                    None => return,
                }
                (MailboxType::Error, data.len())
            }
        };
        m.queue(kind, len);
    }

    /// Puts an EMCY (CoE service 1) into `mbx.tx` (pending).
    fn queue_emcy(&mut self, e: &Emcy) {
        let m = &mut self.mbx;
        let coe = CoeHeader {
            number: 0,
            service: service::EMERGENCY,
        }
        .to_bytes();
        let Some(body) =
            m.tx.get_mut(HEADER_LEN..HEADER_LEN + COE_HEADER_LEN + emcy::EMCY_LEN)
        else {
            return;
        };
        for (dst, src) in body.iter_mut().zip(coe.into_iter().chain(e.to_bytes())) {
            *dst = src;
        }
        m.queue(MailboxType::Coe, COE_HEADER_LEN + emcy::EMCY_LEN);
    }

    /// Puts the next SDO Info fragment into `mbx.tx` (pending).
    fn next_fragment<A: Application>(&mut self, app: &mut A) {
        let m = &mut self.mbx;
        let Some(body) = m.tx.get_mut(HEADER_LEN..m.tx_len) else {
            self.coe.reset();
            return;
        };
        if let Some(len) = self.coe.next_fragment(body, app) {
            m.queue(MailboxType::Coe, len);
        }
    }

    fn process_data<P: Pdi>(&mut self, pdi: &mut P, events: u32, now_ns: u64) -> Result<(), P::Error> {
        if self.out_len > 0 && events & al_event::sm(2) != 0 {
            if let Some(out) = self.outputs.get_mut(..self.out_len) {
                // one read of the whole area: the ESC releases the buffer on its last byte
                pdi.read(self.out_start, out)?;
                self.rx_frames = self.rx_frames.wrapping_add(1);
                self.rx_times.rotate_right(1);
                if let Some(newest) = self.rx_times.first_mut() {
                    *newest = now_ns;
                }
                self.rx_seen = self.rx_seen.saturating_add(1);
            }
        }
        if self.in_len > 0 {
            if let Some(inp) = self.inputs.get(..self.in_len) {
                pdi.write(self.in_start, inp)?;
            }
        }
        Ok(())
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
