//! The slave: ESM + mailbox + CoE dispatch + process data, driven by `poll`.

use crate::coe::{service, CoeConfig, CoeHeader, CoeServer, Dictionary, COE_HEADER_LEN};
use crate::desc::Device;
use crate::emcy::{self, Emcy, EmcyQueue};
use crate::esm::{self, MAX_MAILBOX_LEN, MAX_PDO_BYTES};
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
}

impl core::fmt::Display for StateChange {
    /// `Init -> PreOp`, or `PreOp: request 8 refused, AL status code 0x0011`.
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        if self.code == AlStatusCode::NO_ERROR {
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
            emcy: EmcyQueue::new(),
            pdo_bytes: (desc.output_bytes(), desc.input_bytes()),
            out_len: desc.output_bytes().min(MAX_PDO_BYTES),
            in_len: desc.input_bytes().min(MAX_PDO_BYTES),
            out_start: desc.outputs.start,
            in_start: desc.inputs.start,
            inputs: [0; MAX_PDO_BYTES],
            outputs: [0; MAX_PDO_BYTES],
            rx_frames: 0,
        }
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

    /// One step of the stack: AL control requests, mailbox, process data.
    /// Returns the processed AL control request when it changed the state or was
    /// refused.
    pub fn poll<P: Pdi, A: Dictionary>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        now_ns: u64,
    ) -> Result<Option<StateChange>, P::Error> {
        if !self.started {
            self.write_status(pdi)?;
            self.started = true;
        }
        let events = pdi.al_event()?;
        if let Some(bytes) = app.process_data_bytes() {
            self.pdo_bytes = bytes;
        }
        let change = if events & al_event::AL_CONTROL != 0 {
            self.al_control(pdi, now_ns)?
        } else {
            None
        };
        if esm::mailbox_on(self.state) {
            self.poll_mailbox(pdi, app, events, now_ns)?;
        }
        if esm::process_data_on(self.state) {
            self.process_data(pdi, events)?;
        }
        Ok(change)
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

    fn al_control<P: Pdi>(&mut self, pdi: &mut P, now_ns: u64) -> Result<Option<StateChange>, P::Error> {
        let ctrl = AlControl::from_raw(pdi.read_u16(regs::AL_CONTROL)?);
        if self.error && !ctrl.ack {
            // ETG.1000.6: a request without acknowledge leaves an error indication as it is
            return Ok(None);
        }
        let from = self.state;
        let result = match esm::target(from, ctrl.requested) {
            Err(code) => Err(code),
            Ok(None) => Ok(from),
            Ok(Some(to)) => self.transition(pdi, from, to, now_ns)?.map(|()| to),
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
        };
        Ok((from != self.state || self.error).then_some(change))
    }

    /// Checks and actions of one ESM transition; the outer `Result` is the PDI's.
    fn transition<P: Pdi>(
        &mut self,
        pdi: &mut P,
        from: AlState,
        to: AlState,
        now_ns: u64,
    ) -> Result<Result<(), AlStatusCode>, P::Error> {
        match (from, to) {
            (AlState::Init, AlState::PreOp) => {
                let (sm0, sm1) = (pdi.read_sm(0)?, pdi.read_sm(1)?);
                if let Err(code) = esm::check_mailbox_sms(self.desc, &sm0, &sm1) {
                    return Ok(Err(code));
                }
                self.start_mailbox(&sm0, &sm1);
            }
            (AlState::PreOp, AlState::SafeOp) => {
                let sms = [pdi.read_sm(0)?, pdi.read_sm(1)?, pdi.read_sm(2)?, pdi.read_sm(3)?];
                let (rx, tx) = self.pdo_bytes;
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
                if let Err(code) = self.check_watchdog(pdi)? {
                    return Ok(Err(code));
                }
                let [_, _, sm2, sm3] = sms;
                self.out_start = sm2.start;
                self.in_start = sm3.start;
                // the process image follows the mapping checked above (E-019: a remap
                // takes effect at the next P→S)
                self.out_len = rx.min(MAX_PDO_BYTES);
                self.in_len = tx.min(MAX_PDO_BYTES);
                self.rx_frames = 0;
            }
            (AlState::SafeOp, AlState::Op) => {
                if let Err(code) = self.check_outputs_steady(now_ns) {
                    return Ok(Err(code));
                }
                self.outputs.fill(0);
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

    /// P→S hook for the SM watchdog settings (E-031, AL 001Fh); accepts all for now.
    fn check_watchdog<P: Pdi>(&mut self, _pdi: &mut P) -> Result<Result<(), AlStatusCode>, P::Error> {
        Ok(Ok(()))
    }

    /// S→O hook for "steady process data" (E-033); accepts for now.
    fn check_outputs_steady(&self, _now_ns: u64) -> Result<(), AlStatusCode> {
        Ok(())
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

    fn poll_mailbox<P: Pdi, A: Dictionary>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
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
                self.handle_request(app, now_ns);
            }
        }
        self.coe.tick(now_ns);
        // emergencies go out first once SM1 is free (E-094: through the mailbox)
        if !self.mbx.pending {
            if let Some(e) = self.emcy.pop() {
                self.queue_emcy(&e);
            }
        }
        // the next SDO Info fragment once the previous response has left
        if !self.mbx.pending && self.coe.has_fragments() {
            self.next_fragment(app);
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
    fn handle_request<A: Dictionary>(&mut self, app: &mut A, now_ns: u64) {
        let state = self.state;
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
                    MailboxType::Coe => self
                        .coe
                        .handle(payload, body, app, state, now_ns)
                        .map(|n| n.map(|n| (MailboxType::Coe, n))),
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
    fn next_fragment<A: Dictionary>(&mut self, app: &mut A) {
        let m = &mut self.mbx;
        let Some(body) = m.tx.get_mut(HEADER_LEN..m.tx_len) else {
            self.coe.reset();
            return;
        };
        if let Some(len) = self.coe.next_fragment(body, app) {
            m.queue(MailboxType::Coe, len);
        }
    }

    fn process_data<P: Pdi>(&mut self, pdi: &mut P, events: u32) -> Result<(), P::Error> {
        if self.out_len > 0 && events & al_event::sm(2) != 0 {
            if let Some(out) = self.outputs.get_mut(..self.out_len) {
                // one read of the whole area: the ESC releases the buffer on its last byte
                pdi.read(self.out_start, out)?;
                self.rx_frames = self.rx_frames.wrapping_add(1);
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
