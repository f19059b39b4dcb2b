//! DC-Sync (spec §11): the PLL built at the first SYNC0, the cycle
//! commands of the control-cycle timer, the sync diagnostics (A261, A298,
//! 1C32h/1C33h), the A287 optimiser and the sync state handed to the slave.

use super::*;

/// The PLL settings the objects give (A292 phase offset, A149 sequence,
/// A290 on/off), as [`Drive::cycle_start`] keeps them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct PllSettings {
    pub(super) a292_ns: i32,
    pub(super) sequence: dcsync::CycleSequence,
    pub(super) enabled: bool,
}

impl<F: Flash, B: Flash> Drive<F, B> {
    /// Where the aligned cycle does Rx and Tx after its start, ns (the
    /// firmware's measured step times; 0 and 0 until set): what the A287
    /// measurement records for Rx and Tx.
    pub fn set_step_offsets(&mut self, rx_after_start_ns: u32, tx_after_start_ns: u32) {
        self.step_offsets_ns = (rx_after_start_ns, tx_after_start_ns);
    }

    /// The A287 measurement (its outcome once finished).
    pub fn optimizer(&self) -> &dcsync::Optimizer {
        &self.optimizer
    }

    /// A287: `[0]` = 1 written (by SDO) starts the measurement when none
    /// runs (result 2 at once when not in Safe-Op/Op with DC SYNC0 and a
    /// running PLL, or the master cycle ≠ A291); a measurement running when
    /// the drive leaves Safe-Op/Op or the PLL goes ends with 2. `[1]`, `[2]`
    /// and the results follow the measurement; `[0]` goes back to 0 when it
    /// is finished.
    pub(super) fn update_optimizer(&mut self) {
        let start = self.objects.get(A287, 1).is_ok_and(|v| v == 1);
        let usable = matches!(self.slave.state(), AlState::SafeOp | AlState::Op)
            && self.slave.sync_status().mode == SyncMode::DcSync0
            && self.pll.is_some();
        if (start && !self.optimizer.is_running()) || (self.optimizer.is_running() && !usable) {
            let req = self.optimize_request(usable);
            self.optimizer.start(req);
            self.frame_rel_sync0_ns = None;
        }
        self.update_optimizer_live();
    }

    /// The A287 preconditions as they are now.
    pub(super) fn optimize_request(&self, usable: bool) -> dcsync::OptimizeRequest {
        let get = |index| self.objects.get(index, 0).unwrap_or(0);
        let ns = |us: i64| u32::try_from(us.saturating_mul(1000)).unwrap_or(0);
        let pll = self.pll.as_ref();
        dcsync::OptimizeRequest {
            safe_op_or_op: matches!(self.slave.state(), AlState::SafeOp | AlState::Op),
            dc_sync: usable,
            master_cycle_ns: pll.and_then(|p| p.measured_sync0_cycle_ns()).unwrap_or(0),
            a291_ns: ns(get(A291)),
            sync0_cycle_ns: pll.map_or(0, |p| p.config().sync0_cycle_ns),
            a150_ns: ns(get(A150)),
            a292_ns: i32::try_from(get(A292).saturating_mul(1000)).unwrap_or(0),
            guard_ns: OPTIMIZE_GUARD_NS,
        }
    }

    /// A287[0..7] from the measurement.
    pub(super) fn update_optimizer_live(&mut self) {
        let o = &self.optimizer;
        let (progress, result) = (o.progress_percent(), o.result_code());
        let _ = self.objects.set(A287, 2, i64::from(progress));
        let _ = self.objects.set(A287, 3, i64::from(result));
        if let Some(out) = o.outcome() {
            let _ = self.objects.set(A287, 1, 0);
            // the µs range inside the ns range (rounded inwards)
            let (mut lo, mut hi) = (
                out.a292_min_ns.div_euclid(1000) + i64::from(out.a292_min_ns.rem_euclid(1000) != 0),
                out.a292_max_ns.div_euclid(1000),
            );
            if lo > hi {
                let mid = (out.a292_min_ns + out.a292_max_ns).div_euclid(2000);
                (lo, hi) = (mid, mid);
            }
            let us = |ns: i64| ns.div_euclid(1000);
            let _ = self.objects.set(A287, 4, lo);
            let _ = self.objects.set(A287, 5, hi);
            let _ = self.objects.set(A287, 6, us(out.end_of_frame_to_sync_ns));
            let _ = self.objects.set(A287, 7, us(out.frame_duration_ns));
            let _ = self.objects.set(A287, 8, us(out.sync_to_rx_ns));
        }
    }

    /// One A287 sample for the aligned cycle starting at `t_local`: the
    /// last frame's arrival (start = end: the SM2 event gives one time), the
    /// cycle start and the Rx/Tx offsets, all relative to SYNC0.
    pub(super) fn record_optimizer_sample(&mut self, t_local: Nanos) {
        if !self.optimizer.is_running() {
            return;
        }
        let Some(pll) = self.pll.as_ref() else { return };
        let (Some(frame), Some(start)) = (self.frame_rel_sync0_ns.take(), pll.relative_to_sync0(t_local))
        else {
            return;
        };
        let (rx, tx) = self.step_offsets_ns;
        self.optimizer.record(&dcsync::FrameSample {
            sof_ns: frame,
            eof_ns: frame,
            cycle_start_ns: start,
            rx_after_start_ns: rx,
            tx_after_start_ns: tx,
        });
        self.update_optimizer_live();
    }

    /// The DC-Sync PLL, while SYNC0 runs.
    pub fn pll(&self) -> Option<&Pll> {
        self.pll.as_ref()
    }

    /// The DC-Sync PLL, mutable (e.g. to acknowledge its fault).
    pub fn pll_mut(&mut self) -> Option<&mut Pll> {
        self.pll.as_mut()
    }

    /// Why the PLL refused the SYNC0 configuration last seen (`None` while
    /// it runs or before any SYNC0).
    pub fn sync_error(&self) -> Option<SyncError> {
        self.sync_error
    }

    /// What the slave stack is told about the synchronisation (see
    /// [`Slave::set_sync_state`]): supervised in DC SYNC0 mode with the PLL
    /// not deactivated (A290 ≠ 1 leaves the drive unsynchronised on purpose).
    /// Without a PLL (no SYNC0 yet, or a configuration it refused) S→O waits
    /// with 002Dh (or the refusal's code).
    pub fn sync_state(&self) -> SyncState {
        if self.slave.sync_status().mode != SyncMode::DcSync0 {
            return SyncState::NONE;
        }
        let code = |f: dcsync::SyncFault| AlStatusCode(f.al_status_code());
        match &self.pll {
            Some(p) if p.state() == dcsync::PllState::Disabled => SyncState::NONE,
            Some(p) => SyncState {
                required: true,
                ready: p.ready_for_op().map_err(code),
                fault: p.fault().map(code),
            },
            None => SyncState {
                required: true,
                ready: Err(self.sync_error.map_or(AlStatusCode(dcsync::al::NO_SYNC), |e| {
                    AlStatusCode(e.al_status_code())
                })),
                fault: None,
            },
        }
    }

    /// The period of the free-running control cycle (no SYNC0): A150,
    /// the cycle the axes integrate with (E-125, C-144);
    /// [`A150_FALLBACK_US`](crate::params::A150_FALLBACK_US) while A150 holds
    /// no allowed cycle time.
    pub fn free_run_period(&self) -> Nanos {
        let a150_ns =
            u32::try_from(read_slot(&self.objects, self.slots.a150, 0).saturating_mul(1000)).unwrap_or(0);
        Nanos::from_ns(u64::from(
            motion::cycle::application_cycle_ns(a150_ns).unwrap_or(crate::params::A150_FALLBACK_US * 1000),
        ))
    }

    /// The PLL configuration from the ESC's SYNC0 cycle and the objects
    /// (A150, A292, A149, A290; µs in the objects).
    pub(super) fn pll_config(&self, sync0_cycle_ns: u32) -> dcsync::Config {
        let get = |slot| read_slot(&self.objects, slot, 0);
        let a150_ns = u32::try_from(get(self.slots.a150).saturating_mul(1000)).unwrap_or(0);
        let mut cfg = dcsync::Config::new(sync0_cycle_ns, a150_ns, TIMER_HZ);
        cfg.a292_ns = i32::try_from(get(self.slots.a292).saturating_mul(1000)).unwrap_or(0);
        cfg.sequence = u8::try_from(get(self.slots.a149))
            .ok()
            .and_then(dcsync::CycleSequence::from_a149)
            .unwrap_or_default();
        cfg.enabled = read_slot(&self.objects, self.slots.a290, 1) == 1;
        cfg
    }

    /// SYNC0 interrupt at local time `t_local` (the timer's time base).
    /// Builds the PLL at the first pulse, or again when the SYNC0 cycle
    /// (0x09A0, read through `pdi`) changed; a refused configuration leaves
    /// the PLL off ([`Drive::sync_error`], `A261[0]`).
    pub fn on_sync0<P: Pdi>(&mut self, pdi: &mut P, t_local: Nanos) -> Result<(), P::Error> {
        let cycle = pdi.read_u32(regs::dc::SYNC0_CYCLE)?;
        let current = self.pll.as_ref().map(|p| p.config().sync0_cycle_ns);
        if current != Some(cycle) || self.pll_from_sm {
            self.pll_from_sm = false;
            self.build_pll(cycle);
        }
        if let Some(pll) = self.pll.as_mut() {
            pll.on_sync0(t_local);
        }
        self.update_sync_live();
        Ok(())
    }

    /// Control-cycle timer interrupt at the programmed local start
    /// `t_local`: applies changed A292/A149/A290 and asks the PLL for
    /// this cycle's length (program the next start at `start +
    /// period_ticks`). `None` without a PLL (free-running A150 timer).
    pub fn cycle_start(&mut self, t_local: Nanos) -> Option<CycleCommand> {
        let generation = self.objects.config_generation();
        let settings = match self.pll_settings {
            Some((g, s)) if g == generation => s,
            _ => {
                let cfg = self.pll_config(self.pll.as_ref()?.config().sync0_cycle_ns);
                let s = PllSettings {
                    a292_ns: cfg.a292_ns,
                    sequence: cfg.sequence,
                    enabled: cfg.enabled,
                };
                self.pll_settings = Some((generation, s));
                s
            }
        };
        let pll = self.pll.as_mut()?;
        let wanted = *pll.config();
        if settings.a292_ns != wanted.a292_ns {
            pll.set_phase_offset(settings.a292_ns);
        }
        if settings.sequence != wanted.sequence {
            pll.set_sequence(settings.sequence);
        }
        if settings.enabled != wanted.enabled {
            pll.set_enabled(settings.enabled);
        }
        let cmd = pll.on_cycle_start(t_local);
        let now = (pll.status(), pll.fault());
        if cmd.index == 0 {
            self.record_optimizer_sample(t_local);
        }
        // A298 and the sync-error flags at once when they differ from what
        // they show; the phase error of A261[3] follows with the next SYNC0
        // (on_sync0), so the control cycle does not rewrite the diagnostics
        // every cycle
        if self.sync_shown != Some(now) {
            self.update_sync_live();
        }
        Some(cmd)
    }

    /// The master's process data (SM2) arrived at local time `t_local`:
    /// `A261[1]`, `[2]`. `None` without a PLL or before the first SYNC0.
    ///
    /// In SM-Sync (`1C32h:01` = 1 accepted at P→S, Safe-Op and Op) the SM2
    /// event is the synchronisation signal instead (E-110, spec §9.5.1): the
    /// PLL is built at the first event with the process-data cycle
    /// (`1C32h:02`, else A150) and locks the control cycle to event − A292
    /// like to SYNC0 − A292; it goes when the drive leaves Safe-Op/Op.
    pub fn on_frame(&mut self, t_local: Nanos) -> Option<FrameTiming> {
        if self.slave.sync_status().mode == SyncMode::SmSync
            && matches!(self.slave.state(), AlState::SafeOp | AlState::Op)
        {
            self.on_sm_event(t_local);
            return None;
        }
        let timing = self.pll.as_mut()?.on_frame(t_local);
        if let Some(t) = timing {
            self.frame_rel_sync0_ns = Some(t.rel_sync0_ns);
        }
        self.update_sync_live();
        timing
    }

    /// SM-Sync: the SM2 event at `t_local` as the PLL's sync pulse.
    pub(super) fn on_sm_event(&mut self, t_local: Nanos) {
        let cycle = self.slave.sync_status().cycle_ns;
        let current = self.pll.as_ref().map(|p| p.config().sync0_cycle_ns);
        if current != Some(cycle) || !self.pll_from_sm {
            self.build_pll(cycle);
            self.pll_from_sm = true;
        }
        if let Some(pll) = self.pll.as_mut() {
            pll.on_sync0(t_local);
        }
        self.update_sync_live();
    }

    /// A new PLL for a sync pulse every `cycle` ns; a refused configuration
    /// leaves the PLL off and its error in [`Drive::sync_error`] (`A261[0]`).
    fn build_pll(&mut self, cycle: u32) {
        self.sync_shown = None;
        match Pll::new(self.pll_config(cycle)) {
            Ok(pll) => {
                self.pll = Some(pll);
                self.sync_error = None;
            }
            Err(e) => {
                self.pll = None;
                self.sync_error = Some(e);
            }
        }
    }

    /// A296, A298 and A261 from the PLL (A261[0] also from a refused
    /// configuration; everything 0 without SYNC0).
    pub(super) fn update_sync_live(&mut self) {
        self.sync_shown = self.pll.as_ref().map(|p| (p.status(), p.fault()));
        let (status, diag, measured) = match &self.pll {
            Some(p) => (
                p.status().0,
                p.diagnostics(),
                p.measured_sync0_cycle_ns().unwrap_or(0),
            ),
            None => {
                let mut d = dcsync::SyncDiagnostics::default();
                if let Some(e) = self.sync_error {
                    d.code = e.diag_code();
                }
                let status = if self.sync_error.is_some() {
                    dcsync::PllStatus::ERROR
                } else {
                    0
                };
                (status, d, 0)
            }
        };
        // µs, rounded to nearest
        let measured_us = i64::from(measured.saturating_add(500) / 1000);
        // bit 4: A296 > A291 (spec §11.6; the PLL itself compares with the
        // SYNC0 cycle it was configured for)
        let a291_us = read_slot(&self.objects, self.slots.a291, 0);
        let status = if measured_us > 0 && a291_us > 0 && measured_us > a291_us {
            status | dcsync::PllStatus::SYNC_CYCLE_TOO_LONG
        } else {
            status
        };
        let (od, slots) = (&mut self.objects, &self.slots);
        write_slot(od, slots.a298, i64::from(status));
        write_slot(od, slots.a296, measured_us);
        let [code, data_us, late, phase] = diag.elements();
        // `[3]` is declared U32: the phase error's two's complement
        let a261 = [code, data_us, late].map(i64::from);
        for (slot, v) in slots
            .a261
            .into_iter()
            .zip(a261.into_iter().chain([i64::from(phase as u32)]))
        {
            write_slot(od, slot, v);
        }
        // 1C32h/1C33h (mirrored in A264/A265, E-119): :0B SM-event missed
        // = the late frames of A261[2], :20 sync error = a PLL fault or a
        // refused SYNC0 configuration
        let fault = self.pll.as_ref().is_some_and(|p| p.fault().is_some()) || self.sync_error.is_some();
        for (missed, error) in slots.sm_missed.into_iter().zip(slots.sync_error) {
            write_slot(od, missed, i64::from(late.clamp(0, i32::from(u16::MAX))));
            write_slot(od, error, i64::from(fault));
        }
    }
}
