//! The mailbox of the slave: the SM0/SM1 areas set up at I→P, one request
//! read and dispatched (CoE, EoE, FoE, mailbox errors), one response or
//! queued message (EMCY, SDO Info fragment, EoE fragment) written when SM1
//! is free, repeat requests.

use super::*;

/// Mailbox state: the SM areas as configured at I→P, the request buffer and the
/// last (or pending) response.
#[derive(Clone)]
pub(super) struct Mailbox {
    pub(super) rx_start: u16,
    pub(super) rx_len: usize,
    pub(super) tx_start: u16,
    pub(super) tx_len: usize,
    pub(super) rx: [u8; MAX_MAILBOX_LEN],
    pub(super) tx: [u8; MAX_MAILBOX_LEN],
    /// `tx` holds a response (for a repeat request).
    pub(super) tx_valid: bool,
    /// `tx` holds a response not yet written into SM1.
    pub(super) pending: bool,
    /// Counter of the last request (duplicate detection).
    pub(super) last_counter: u8,
    /// Counter of the last response.
    pub(super) counter: u8,
}

impl Mailbox {
    /// Completes the response whose `len` data bytes are in `tx` after the
    /// header: zero fill, next counter, header; the response is pending.
    pub(super) fn queue(&mut self, kind: MailboxType, len: usize) {
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

impl Slave {
    pub(super) fn start_mailbox(&mut self, sm0: &SyncManager, sm1: &SyncManager) {
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

    /// One mailbox step: an FoE transfer ends outside Bootstrap; in the
    /// mailbox states, a request from SM0 is answered into SM1, then the
    /// EMCY queue, SDO Info fragments and outgoing EoE fragments.
    pub(super) fn mailbox_step<P: Pdi, A: Application, H: FoeHandler, E: EthernetPort>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        foe: &mut H,
        eth: &mut E,
        events: u32,
        now: Nanos,
    ) -> Result<(), P::Error> {
        if self.state != AlState::Bootstrap {
            self.foe.reset(foe);
        }
        if !esm::mailbox_on(self.state) {
            return Ok(());
        }
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
                self.handle_request(app, foe, eth, now);
                if let Some(e) = self.eoe.take_emcy() {
                    self.emcy.push(e);
                }
            }
        }
        self.coe.tick(now);
        self.foe.tick(foe, now);
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

    pub(super) fn write_response<P: Pdi>(&mut self, pdi: &mut P) -> Result<(), P::Error> {
        if let Some(tx) = self.mbx.tx.get(..self.mbx.tx_len) {
            pdi.write(self.mbx.tx_start, tx)?;
        }
        self.mbx.pending = false;
        Ok(())
    }

    /// Handles the request in `mbx.rx`; a response goes to `mbx.tx` and is pending.
    pub(super) fn handle_request<A: Application, H: FoeHandler, E: EthernetPort>(
        &mut self,
        app: &mut A,
        foe: &mut H,
        eth: &mut E,
        now: Nanos,
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
                            .handle(payload, body, foe, boot, max_data, now)
                            .map(|n| n.map(|n| (MailboxType::Foe, n)))
                    }
                    MailboxType::Coe if !boot => self
                        .coe
                        .handle(payload, body, app, state, now)
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
    pub(super) fn queue_emcy(&mut self, e: &Emcy) {
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
    pub(super) fn next_fragment<A: Application>(&mut self, app: &mut A) {
        let m = &mut self.mbx;
        let Some(body) = m.tx.get_mut(HEADER_LEN..m.tx_len) else {
            self.coe.reset();
            return;
        };
        if let Some(len) = self.coe.next_fragment(body, app) {
            m.queue(MailboxType::Coe, len);
        }
    }
}
