//! The control cycle of both axes with the PROFIdrive profile on the
//! cyclic data ([`PnDrive::control_cycle`]): the receive telegram applied
//! and the response built on the cycle after a frame arrived (issue 36),
//! the axes' fault changes as diagnosis alarms and E82/E43, saves the
//! profile asked for.

use super::*;

impl<F: Flash, H: RecordHook> PnDrive<F, H> {
    /// One control cycle of both axes at `now` with the hardware inputs `io`;
    /// returns the power-stage commands. A fault raised or reset becomes a
    /// diagnosis alarm appearing or disappearing, and E82/E43 follow it.
    /// While PROFIenergy pauses ([`energy`]) the axes see no supply.
    pub fn control_cycle(&mut self, now: Nanos, io: &[AxisIo; 2]) -> [AxisCommand; 2] {
        self.profinet_active();
        self.energy_inputs();
        // a copy of the inputs only while paused (two `AxisIo` copied every
        // cycle cost ~730 instructions on QEMU, issue 36)
        let paused_io;
        let io = if self.energy_paused() {
            paused_io = io.map(|io| AxisIo {
                supply_ok: false,
                ..io
            });
            &paused_io
        } else {
            io
        };
        let new = core::mem::take(&mut self.exchanged) || !self.device.exchanging();
        // the profile per telegram: decoded and applied when a frame
        // arrived, when the mode the core shows changed since (the CW1
        // context, P-086) and while a homing run it started is active;
        // the cycles in between run the core only
        let [axis_a, _] = &self.axes;
        let mode = self.profile.mode_display(&self.objects, axis_a);
        let run_profile = core::mem::take(&mut self.telegram_new)
            || self.profile_mode != Some(mode)
            || self.profile.homing();
        // the data modules looked up once for both halves of the telegram
        // (issue 36: not once in each)
        let modules = if run_profile {
            self.data_slots()
        } else {
            (None, None)
        };
        if run_profile {
            self.profile_receive(modules.0);
        }
        let mut commands = [AxisCommand::OFF; 2];
        for (i, ((axis, cache), io)) in self
            .axes
            .iter_mut()
            .zip(self.caches.iter_mut())
            .zip(io)
            .enumerate()
        {
            let report = axis.cycle_cached(cache, &mut self.objects, io, now, new);
            let (Some(command), Some(raised)) = (commands.get_mut(i), self.raised.get(i).copied()) else {
                continue;
            };
            match report.fault {
                Some(FaultChange::Raised(f)) => {
                    let _ = self.objects.set(E82, 0, i64::from(f.event));
                    let _ = self.objects.set(E43, 0, i64::from(f.cause));
                    if self.device.raise_diagnosis(f.event, f.cause) {
                        if let Some(r) = self.raised.get_mut(i) {
                            *r = Some((f.event, f.cause));
                        }
                    }
                }
                Some(FaultChange::Cleared) => {
                    let _ = self.objects.set(E82, 0, i64::from(E82_INACTIVE));
                    let _ = self.objects.set(E43, 0, 0);
                    if let Some(r) = self.raised.get_mut(i) {
                        *r = None;
                    }
                    // the diagnosis sits on the drive (DAP subslot 1): it goes
                    // when no axis holds it any more
                    if let Some((hh, s)) = raised {
                        if !self.raised.contains(&Some((hh, s))) {
                            self.device.clear_diagnosis(hh, s);
                        }
                    }
                }
                None => {}
            }
            *command = report.command;
        }
        // a running motor action replaces the axis' command (B40…B44, B49, B300, B301); the axis
        // follows the shaft meanwhile (`Axis::overridden`)
        if self.actions.measuring() {
            for ((i, axis), (command, io)) in
                self.axes.iter_mut().enumerate().zip(commands.iter_mut().zip(io))
            {
                if let Some(c) = self.actions.control(i, drive_core::axis::e48(axis.state()), io) {
                    axis.overridden();
                    *command = c;
                }
            }
            self.serve_actions();
        }
        self.powered = commands.map(|c| c.power_stage);
        // the scope's sample of this cycle (one branch while not recording)
        self.sample_scope(io);
        if run_profile {
            // once per telegram: the response the device sends next
            self.profile_respond(modules.1);
            let [axis_a, _] = &self.axes;
            self.profile_mode = Some(self.profile.mode_display(&self.objects, axis_a));
        }
        commands
    }

    /// The profile (telegrams, CW1/ZSW1, PKW).
    pub fn profile(&self) -> &profile::Profile {
        &self.profile
    }

    /// The data modules: (controller → drive slot, drive → controller slot).
    pub(crate) fn data_slots(&self) -> (Option<u16>, Option<u16>) {
        let (mut to_drive, mut from_drive) = (None, None);
        for (slot, _, to) in self.device.data_modules() {
            match to {
                true if to_drive.is_none() => to_drive = Some(slot),
                false if from_drive.is_none() => from_drive = Some(slot),
                _ => {}
            }
        }
        (to_drive, from_drive)
    }

    /// The received telegram into the objects and axis A (before the axes'
    /// cycle), while the outputs are current.
    fn profile_receive(&mut self, to_drive: Option<u16>) {
        let Some(slot) = to_drive else {
            return;
        };
        // read where the device holds it, beside the hook that serves the
        // live values (issue 36: a copy out and a cleared buffer per
        // telegram cost ~120 instructions on QEMU)
        let (Some(data), hook) = self.device.output_data_with_hook(slot) else {
            return;
        };
        let [axis, _] = &mut self.axes;
        let live = &mut hook.inner.inner;
        self.profile.receive_with(data, &mut self.objects, axis, live);
        // A75 only changes by a parameter write: looked at after one, and
        // every telegram while an action is shown (issue 36: two lookups of
        // A75 per telegram cost some 580 instructions on QEMU)
        let writes = self.profile.parameter_writes();
        if writes != self.actions_seen_writes || self.actions.busy() {
            self.actions_seen_writes = writes;
            self.serve_actions();
        }
        self.serve_saves();
    }

    /// The saves asked through the parameter access, PKW or record 0xB02E:
    /// PNU 971 = 1 or 256 (the profile's), A00\[0\] = 1 and 1010h:01 "save"
    /// (the dictionary's, reached as PNU = index). Saving is synchronous
    /// here, so the save is done before the request is answered or the
    /// next telegram is read: PNU 971 reads 0 again at once. The parameters
    /// and the records are one image (P-199, P-200).
    pub(crate) fn serve_saves(&mut self) {
        let profile = self.profile.take_save_request();
        let requests = self.objects.requests();
        if !profile && !requests.save {
            return;
        }
        if requests.save {
            // a restart asked as well stays asked
            if self.objects.take_requests().restart {
                self.objects.request_restart();
            }
        }
        let _ = self.save();
        self.profile.save_done();
    }

    /// The response telegram into the input data (after the axes' cycle).
    fn profile_respond(&mut self, from_drive: Option<u16>) {
        let Some(slot) = from_drive else {
            return;
        };
        // built in place in the module's data (issue 36: a cleared buffer
        // and its byte-wise copy into the device cost ~200 instructions per
        // telegram on QEMU); nothing is written before the first telegram
        let Some(out) = self.device.input_data_mut(slot) else {
            return;
        };
        let [axis, _] = &self.axes;
        let _ = self.profile.respond(&mut self.objects, axis, out);
    }
}
