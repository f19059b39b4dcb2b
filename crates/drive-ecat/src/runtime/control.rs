//! The control cycle of both axes (A150, C-1xx): free-running
//! ([`Drive::control_cycle`]) or under the PLL ([`Drive::sync_cycle`]),
//! each axis' fault change as an EMCY, E82/E43 and a diagnosis message.

use super::*;

impl<F: Flash, B: Flash> Drive<F, B> {
    /// One control cycle (A150) of both axes at `now` with the hardware
    /// inputs `io`; returns the power-stage commands. Call it once per
    /// control cycle (SYNC0 / the control timer), independent of
    /// [`poll`](Self::poll): the set-points are the objects as the last poll
    /// left them, the actual values written here go out with the next poll.
    ///
    /// A new cyclic set-point (csp/csv/ip) is taken when an RxPDO frame
    /// arrived in Op since the last control cycle; outside Op (set-points
    /// written by SDO or directly) every cycle carries one. Use
    /// [`control_cycle_with`](Self::control_cycle_with) to say it explicitly.
    pub fn control_cycle(&mut self, now: Nanos, io: &[AxisIo; 2]) -> [AxisCommand; 2] {
        let frames = self.slave.outputs_received();
        let new = self.slave.state() != AlState::Op || frames != self.ctl_rx_frames;
        self.ctl_rx_frames = frames;
        self.control_cycle_with(now, io, [new, new])
    }

    /// [`control_cycle`](Self::control_cycle) with the "new set-point" flag
    /// of each axis given by the caller (e.g. a per-cycle RxPDO flag of the
    /// board). Queues the axes' EMCYs (fault on T13, fault cleared on T15)
    /// and keeps 1001h (error register) at the OR of both axes' faults. The
    /// single-axis device ([`crate::Variant::Single`]) runs axis A only and
    /// returns [`AxisCommand::OFF`] for B.
    pub fn control_cycle_with(
        &mut self,
        now: Nanos,
        io: &[AxisIo; 2],
        new_setpoint: [bool; 2],
    ) -> [AxisCommand; 2] {
        // the two axes one after the other, without zipped iterators over
        // six arrays (~20 instructions per cycle less)
        let [axis_a, axis_b] = &mut self.axes;
        let [cache_a, cache_b] = &mut self.axis_caches;
        let [sent_a, sent_b] = &mut self.event52_emcy_sent;
        let [io_a, io_b] = io;
        let [new_a, new_b] = new_setpoint;
        let (objects, slave) = (&mut self.objects, &mut self.slave);
        let [diag_a, diag_b] = &mut self.fault_diag;
        let a = axis_cycle(axis_a, cache_a, sent_a, objects, slave, io_a, now, new_a, diag_a);
        // the single-axis device has no axis B: it stays idle (power stage
        // off, brake applied, no objects, no EMCY)
        let b = if objects.variant().axes() > 1 {
            axis_cycle(axis_b, cache_b, sent_b, objects, slave, io_b, now, new_b, diag_b)
        } else {
            AxisCommand::OFF
        };
        // a running motor action (B42/B49) replaces the axis' command (both
        // looks skipped while none runs, as on PROFINET)
        let (a, b) = if self.actions.measuring() {
            let e48 = drive_core::axis::e48;
            let a = match self.actions.control(0, e48(axis_a.state()), io_a) {
                Some(cmd) => {
                    axis_a.overridden();
                    cmd
                }
                None => a,
            };
            let b = match self.actions.control(1, e48(axis_b.state()), io_b) {
                Some(cmd) => {
                    axis_b.overridden();
                    cmd
                }
                None => b,
            };
            (a, b)
        } else {
            (a, b)
        };
        let register = axis_a.error_register() | axis_b.error_register();
        write_slot(&mut self.objects, self.slots.error_register, i64::from(register));
        [a, b]
    }

    /// One control cycle under the PLL (E-111, E-112), started by
    /// [`cycle_start`](Self::cycle_start) which returned `cmd`: runs the
    /// steps [`CycleCommand::steps`] lists, in their A149 order — Rx
    /// (decode the RxPDO frame the last poll read from SM2; Op only), the application
    /// ([`control_cycle_with`](Self::control_cycle_with)), Tx (encode the
    /// TxPDO image the next poll copies to SM3; Safe-Op and Op) — with Rx and
    /// Tx only in the aligned cycle (`index == 0`): A149 = 0 sends this
    /// cycle's actual values, A149 = 1 those of the previous cycle. From the
    /// first call on the poll no longer decodes or encodes the process data
    /// itself (until the PLL goes). A new set-point is flagged when Rx
    /// decoded a new frame (outside Op every cycle, as in
    /// [`control_cycle`](Self::control_cycle)).
    pub fn sync_cycle(&mut self, cmd: &CycleCommand, now: Nanos, io: &[AxisIo; 2]) -> [AxisCommand; 2] {
        self.cycle_pdo = self.pll.is_some();
        let mut new = self.slave.state() != AlState::Op;
        // A149's two orders run directly (Rx first in both; Tx before or
        // after the application), not through `CycleCommand::steps` and a
        // match per step (~90 instructions per cycle less)
        if cmd.rx {
            new |= self.read_outputs();
            self.ctl_rx_frames = self.slave.outputs_received();
        }
        // (exhaustive: a new order must be written out here)
        let tx_first = match cmd.sequence {
            CycleSequence::RxAppTx => false,
            CycleSequence::RxTxApp => true,
        };
        if cmd.tx && tx_first {
            self.process_inputs();
        }
        let commands = self.control_cycle_with(now, io, [new, new]);
        if cmd.tx && !tx_first {
            self.process_inputs();
        }
        commands
    }
}

/// One axis of [`Drive::control_cycle_with`]: its cycle, the EMCY of a
/// fault change (the event 52 EMCY only once for the device) with E82/E43,
/// a raised fault noted in `diag` for the history; returns the power-stage
/// command.
#[allow(clippy::too_many_arguments)]
fn axis_cycle(
    axis: &mut Axis,
    cache: &mut AxisCache,
    sent: &mut bool,
    objects: &mut DriveObjects,
    slave: &mut Slave,
    io: &AxisIo,
    now: Nanos,
    new: bool,
    diag: &mut Option<drive_core::faults::Fault>,
) -> AxisCommand {
    let report = axis.cycle_cached(cache, objects, io, now, new);
    let mut fault = report.fault;
    if report.transition.is_some_and(|t| t.number == 13) {
        // the event 52 EMCY is already queued (once for the device)
        if core::mem::take(sent) && fault.is_some_and(|f| is_event52(&f)) {
            fault = None;
        }
    }
    if let Some(f) = fault {
        slave.emergency(crate::emcy::of_change(&f, axis.index()));
        let (e82, e43) = match f {
            FaultChange::Raised(f) => {
                *diag = Some(f);
                (f.event, f.cause)
            }
            FaultChange::Cleared => (crate::emcy::E82_INACTIVE, 0),
        };
        let _ = objects.set(E82, 0, i64::from(e82));
        let _ = objects.set(E43, 0, i64::from(e43));
    }
    report.command
}
