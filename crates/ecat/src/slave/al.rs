//! The AL control requests: the ESM decision, the checks of each
//! transition (mailbox and process-data SyncManagers, sync mode, DC cycle,
//! watchdog), the AL status written back, a pending S→O waiting for steady
//! process data and the synchronisation.

use super::*;

impl Slave {
    /// The AL event request register and the AL control request it carries.
    pub(super) fn poll_al_control<P: Pdi, A: Application>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        now: Nanos,
    ) -> Result<(u32, Option<StateChange>), P::Error> {
        if !self.started {
            self.write_status(pdi)?;
            self.started = true;
        }
        let events = pdi.al_event()?;
        if let Some(bytes) = app.process_data_bytes() {
            self.pdo_bytes = bytes;
        }
        let mut change = if events & al_event::AL_CONTROL != 0 {
            self.al_control(pdi, app, now)?
        } else {
            None
        };
        if change.is_none() {
            change = self.check_sm_enables(pdi)?;
        }
        if !eoe_on(self.state) {
            self.eoe.reset();
        }
        Ok((events, change))
    }

    /// E-025, E-045 (issue 33): a SyncManager the master switched off
    /// (activate register bit 0) while the state needs it is a local error:
    /// a mailbox SM (0, 1) in Pre-Op, Safe-Op or Op falls back to Init with
    /// 0016h; SM2 (outputs) / SM3 (inputs) in Safe-Op or Op to Pre-Op with
    /// 001Dh / 001Eh (an SM without process data is not needed). An
    /// unsolicited change with the error indication (ETG.1000.6 ESM).
    pub(super) fn check_sm_enables<P: Pdi>(&mut self, pdi: &mut P) -> Result<Option<StateChange>, P::Error> {
        let from = self.state;
        if !matches!(from, AlState::PreOp | AlState::SafeOp | AlState::Op) {
            return Ok(None);
        }
        let off = |pdi: &mut P, n: u8| -> Result<bool, P::Error> {
            Ok(pdi.read_u8(regs::sm(n) + 6)? & activate::ENABLE == 0)
        };
        let fault = if off(pdi, 0)? || off(pdi, 1)? {
            Some((AlState::Init, AlStatusCode::INVALID_MAILBOX_CONFIG))
        } else if from == AlState::PreOp {
            None
        } else if self.out_len > 0 && off(pdi, 2)? {
            Some((AlState::PreOp, AlStatusCode::INVALID_OUTPUT_CONFIG))
        } else if self.in_len > 0 && off(pdi, 3)? {
            Some((AlState::PreOp, AlStatusCode::INVALID_INPUT_CONFIG))
        } else {
            None
        };
        let Some((to, code)) = fault else {
            return Ok(None);
        };
        self.pending_op = None;
        if to == AlState::Init {
            self.mbx.pending = false;
            self.mbx.tx_valid = false;
            self.coe.reset();
        }
        self.state = to;
        self.error = true;
        self.code = code;
        self.sync.unsolicited = true;
        self.write_status(pdi)?;
        Ok(Some(StateChange {
            from,
            to,
            requested: from.code(),
            code,
            unsolicited: true,
        }))
    }

    /// The outcome of a transition: the new state with the error cleared,
    /// or the old state with the error flag and `code`.
    fn settle(&mut self, result: Result<AlState, AlStatusCode>) {
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
    }

    pub(super) fn write_status<P: Pdi>(&self, pdi: &mut P) -> Result<(), P::Error> {
        // explicit device identification: the ID stands in the status code
        // register while no error is shown
        let id = self.id_loaded.filter(|_| !self.error);
        let status = AlStatus {
            state: self.state,
            error: self.error,
            id_loaded: id.is_some(),
        };
        pdi.write_u16(regs::AL_STATUS_CODE, id.unwrap_or(self.code.0))?;
        pdi.write_u16(regs::AL_STATUS, status.raw())
    }

    pub(super) fn al_control<P: Pdi, A: Application>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        now: Nanos,
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
        // "unsolicited" / "triggered" indications; a repeated Op request
        // while S→O waits keeps its start (E-033: masters that rewrite AL
        // control every cycle get the refusal 200 ms after the first one)
        let waiting = self
            .pending_op
            .take()
            .map(|since| (since, self.pending_op_frames));
        self.sync.unsolicited = false;
        self.sync.triggered = false;
        // ETG.1000.6 explicit device identification (AL control bit 5): the
        // ID (the settable value, else the station alias 0x0012) is shown
        // in 0x0134 with AL status bit 5 until a request without the bit
        self.id_loaded = if ctrl.id_request {
            Some(match self.identification {
                Some(id) => id,
                None => pdi.read_u16(regs::STATION_ALIAS)?,
            })
        } else {
            None
        };
        let from = self.state;
        let result = match esm::target_with_boot(from, ctrl.requested, self.foe_supported()) {
            Err(code) => Err(code),
            Ok(None) => Ok(from),
            Ok(Some(AlState::Op)) if from == AlState::SafeOp => {
                self.sync.monitor = self.pdo_monitor(pdi, app)?;
                if !self.outputs_steady(now) || self.sync_ready().is_err() {
                    // E-033: wait (up to 200 ms) for stable RxPDO and, in DC
                    // mode, for the PLL lock; the status stays Safe-Op
                    // without error meanwhile
                    let (since, frames) = waiting.unwrap_or((now, self.rx_frames));
                    self.pending_op = Some(since);
                    self.pending_op_frames = frames;
                    self.error = false;
                    self.code = AlStatusCode::NO_ERROR;
                    self.write_status(pdi)?;
                    return Ok(None);
                }
                self.transition(pdi, app, from, AlState::Op, now)?
                    .map(|()| AlState::Op)
            }
            Ok(Some(to)) => self.transition(pdi, app, from, to, now)?.map(|()| to),
        };
        self.settle(result);
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
    pub(super) fn transition<P: Pdi, A: Application>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        from: AlState,
        to: AlState,
        now: Nanos,
    ) -> Result<Result<(), AlStatusCode>, P::Error> {
        match (from, to) {
            (AlState::Init, AlState::PreOp | AlState::Bootstrap) => {
                // E-047: the ESC could not load its configuration area from the
                // SII EEPROM (checksum error, 0502h bit 11): AL 0051h
                if pdi.read_u16(regs::SII_CONTROL)? & esc::sii::control::CHECKSUM_ERROR != 0 {
                    return Ok(Err(AlStatusCode::EEPROM_ERROR));
                }
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
                self.op_entry = now;
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
    pub(super) fn esc_watchdog<P: Pdi>(pdi: &mut P, sm2: &SyncManager) -> Result<EscWatchdog, P::Error> {
        Ok(EscWatchdog {
            divider: pdi.read_u16(regs::WATCHDOG_DIVIDER)?,
            pd_time: pdi.read_u16(regs::WATCHDOG_TIME_PD)?,
            sm2_trigger: sm2.control().watchdog(),
        })
    }

    /// P→S: the SM watchdog settings against the application's RxPDO
    /// monitoring (E-031, AL 001Fh; see [`esm::check_watchdog`]).
    pub(super) fn check_watchdog<P: Pdi, A: Application>(
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
    pub(super) fn pdo_monitor<P: Pdi, A: Application>(
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

    /// E-033: answers a waiting S→O request once the RxPDO is steady and
    /// (DC mode) the synchronisation ready, or refuses it after
    /// [`esm::STEADY_WAIT`] (with the synchronisation's code when that is
    /// what is missing).
    pub(super) fn pending_op<P: Pdi, A: Application>(
        &mut self,
        pdi: &mut P,
        app: &mut A,
        now: Nanos,
    ) -> Result<Option<StateChange>, P::Error> {
        let Some(since) = self.pending_op else {
            return Ok(None);
        };
        if self.state != AlState::SafeOp {
            self.pending_op = None;
            return Ok(None);
        }
        let sync = self.sync_ready();
        let result = if self.outputs_steady(now) && sync.is_ok() {
            self.transition(pdi, app, AlState::SafeOp, AlState::Op, now)?
        } else if now.wrapping_sub(since) > esm::STEADY_WAIT {
            // spec §3.3 "S→O: SYNC0 present, PLL locked": 002Dh / 0032h / …
            if let Err(code) = sync {
                Err(code)
            } else {
                // Not stable within 200 ms: refused. The spec names no AL code
                // (§3.3: 001Bh or 002Bh). E-047: no RxPDO at all since the
                // request is 002Bh "no valid inputs and outputs"; RxPDO that
                // came but not regularly is 001Bh "SM watchdog", the one §4 ties
                // to "not within the tolerated time". The application's
                // diagnosis tells this refusal by the code and `from`.
                if self.rx_frames == self.pending_op_frames {
                    Err(AlStatusCode::NO_VALID_IO)
                } else {
                    Err(AlStatusCode::SM_WATCHDOG)
                }
            }
        } else {
            return Ok(None);
        };
        self.pending_op = None;
        self.settle(result.map(|()| AlState::Op));
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
    /// tolerance of `now`. With monitoring off nothing is required: the
    /// drive would never notice missing frames in Op either, and masters
    /// that request Op before their cyclic task runs (ethercrab's `into_op`)
    /// still get there.
    pub(super) fn outputs_steady(&self, now: Nanos) -> bool {
        let Some(m) = self.sync.monitor else {
            return true;
        };
        let tol = m.tolerance();
        if self.rx_seen < esm::STEADY_FRAMES {
            return false;
        }
        let mut newer = now;
        for &t in &self.rx_times {
            if newer.wrapping_sub(t) > tol {
                return false;
            }
            newer = t;
        }
        true
    }
}
