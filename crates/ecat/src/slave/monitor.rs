//! Process data and its monitoring in Op: the SM2/SM3 buffers, the RxPDO
//! timeout or SM watchdog, the synchronisation faults the application
//! reports; each ends Op with an unsolicited change to Safe-Op.

use super::*;

impl Slave {
    pub(super) fn poll_process_data<P: Pdi, A: Application>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        events: u32,
        mut change: Option<StateChange>,
        now: Nanos,
    ) -> Result<Option<StateChange>, P::Error> {
        if esm::process_data_on(self.state) {
            self.process_data(pdi, events, now)?;
        }
        if change.is_none() {
            change = self.pending_op(pdi, app, now)?;
        }
        if change.is_none() && self.state == AlState::Op {
            change = self.monitor_rxpdo(pdi, events, now)?;
        }
        if change.is_none() && self.state == AlState::Op {
            change = self.monitor_sync(pdi)?;
        }
        Ok(change)
    }

    pub(super) fn process_data<P: Pdi>(
        &mut self,
        pdi: &mut P,
        events: u32,
        now: Nanos,
    ) -> Result<(), P::Error> {
        if self.out_len > 0 && events & al_event::sm(2) != 0 {
            if let Some(out) = self.outputs.get_mut(..self.out_len) {
                // one read of the whole area: the ESC releases the buffer on its last byte
                pdi.read(self.out_start, out)?;
                self.rx_frames = self.rx_frames.wrapping_add(1);
                self.rx_times.rotate_right(1);
                if let Some(newest) = self.rx_times.first_mut() {
                    *newest = now;
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

    /// In Op (E-044, E-126…E-128): a PDO timeout or an expired SM watchdog
    /// leaves Op for Safe-Op with the error indication, AL 001Bh, EMCY 7500h
    /// (event 52, cause 6) and an unsolicited state change (E-038). Only in
    /// Op, so a master leaving Op on purpose never triggers it.
    pub(super) fn monitor_rxpdo<P: Pdi>(
        &mut self,
        pdi: &mut P,
        events: u32,
        now: Nanos,
    ) -> Result<Option<StateChange>, P::Error> {
        let expired = match self.sync.monitor {
            None => false,
            Some(PdoMonitor::Timeout(t)) => {
                let newest = self.rx_times.first().copied().filter(|_| self.rx_seen > 0);
                let last = newest.map_or(self.op_entry, |t| t.max(self.op_entry));
                now.wrapping_sub(last) > t
            }
            Some(PdoMonitor::EscWatchdog(_)) => {
                // the event is cleared by reading 0x0440; bit 0 = 0: expired
                events & al_event::WATCHDOG_PD != 0 && pdi.read_u16(regs::WATCHDOG_STATUS_PD)? & 1 == 0
            }
        };
        if !expired {
            return Ok(None);
        }
        self.sync.triggered = true;
        self.sync.trigger_count = self.sync.trigger_count.saturating_add(1);
        self.leave_op(pdi, AlStatusCode::SM_WATCHDOG, OpLoss::PdoTimeout)
    }

    /// The synchronisation is supervised: DC SYNC0 accepted at P→S and the
    /// application says it checks it ([`SyncState::required`]).
    pub(super) fn sync_supervised(&self) -> bool {
        self.sync.mode == SyncMode::DcSync0 && self.sync_state.required
    }

    /// S→O condition of the synchronisation (spec §3.3): `Ok` when not
    /// supervised.
    pub(super) fn sync_ready(&self) -> Result<(), AlStatusCode> {
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
    pub(super) fn monitor_sync<P: Pdi>(&mut self, pdi: &mut P) -> Result<Option<StateChange>, P::Error> {
        if !self.sync_supervised() {
            return Ok(None);
        }
        let Some(code) = self.sync_state.fault else {
            return Ok(None);
        };
        self.leave_op(pdi, code, OpLoss::Sync)
    }

    /// Op → Safe-Op on the device's own account: the error indication with
    /// `code`, the reason kept, an unsolicited state change (E-038).
    fn leave_op<P: Pdi>(
        &mut self,
        pdi: &mut P,
        code: AlStatusCode,
        loss: OpLoss,
    ) -> Result<Option<StateChange>, P::Error> {
        self.state = AlState::SafeOp;
        self.error = true;
        self.code = code;
        self.sync.unsolicited = true;
        self.op_loss = Some(loss);
        self.write_status(pdi)?;
        Ok(Some(StateChange {
            from: AlState::Op,
            to: AlState::SafeOp,
            requested: AlState::Op.code(),
            code,
            unsolicited: true,
        }))
    }
}
