//! The motion and control steps of [`Axis::cycle_cached`] (steps 8 and 9):
//! the set-points of this cycle from the device control's stop or the
//! active mode ([`Axis::motion`]), then the cascade and the monitors
//! ([`Axis::control`]); and the set-point state's resets when the drive
//! function goes off.

use super::*;

impl Axis {
    /// Drive function off: the set-point state follows the actual position.
    pub(super) fn disengage(&mut self, actual: i32) {
        self.sp_pos = actual;
        self.sp_vel = 0.0;
        self.running = Running::Idle;
        self.stop = None;
        self.vl_demand = 0.0;
        self.profile.reset(actual);
        self.following.reset();
        if let Some(c) = self.cascade.as_mut() {
            c.reset(actual);
        }
    }

    /// The limits asked for a quick stop without a fault (jog, I26 = 0).
    pub(super) fn local_quick_stop(&mut self, o: &Snapshot) {
        if !matches!(self.running, Running::Idle) && self.stop.is_none() {
            let _ = self.profile.stop(o.quick_stop_deceleration as f32, f32::INFINITY);
            if let Some(c) = self.running.velocity_command() {
                c.commanded = Some(0.0);
            }
        }
    }

    /// The pp limits: 6081h × A340 (C-030), capped by 607Fh.
    pub(super) fn profile_limits(&self, o: &Snapshot) -> ProfileLimits {
        let cap = o.max_profile_velocity as f32;
        ProfileLimits {
            velocity: (o.profile_velocity as f32 * override_factor(o)).min(cap),
            acceleration: o.acceleration as f32,
            deceleration: o.deceleration as f32,
            jerk: jerk(o.jerk),
        }
    }

    /// The set-points of this cycle: the device control's stop, or the mode.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn motion(
        &mut self,
        od: &mut DriveObjects,
        o: &Snapshot,
        out: &Outputs,
        io: &AxisIo,
        actual: &mut i32,
        i199: bool,
        now_ns: Nanos,
        dt_ns: u32,
        new_setpoint: bool,
    ) -> Option<Demand> {
        if !out.drive_function {
            self.disengage(*actual);
            return None;
        }
        match out.ramp {
            Ramp::QuickStop(d) | Ramp::Disable(d) | Ramp::FaultReaction(d) => {
                let from_actual = matches!(out.ramp, Ramp::FaultReaction(_));
                return Some(self.run_stop(o, d, from_actual, *actual, i199, dt_ns));
            }
            Ramp::Halt(_) | Ramp::None => {}
        }
        self.stop = None;
        if !out.motion_enabled {
            return Some(Demand::hold(self.sp_pos));
        }
        let mode = self.dc.mode();
        if !self.running.is(mode) {
            self.activate(mode, o, *actual);
        }
        let halt = matches!(out.ramp, Ramp::Halt(_));
        // the mode's own state, out of the axis while its generator runs and
        // back afterwards; csp/ip, the mode a master drives every cycle, moves
        // only its payload (a copy of the whole enum costs ~20 instructions)
        if let Running::CyclicPosition { ip, mut master } = self.running {
            let d = self.cyclic_position(&mut master, o, ip, new_setpoint);
            if let Running::CyclicPosition { master: m, .. } = &mut self.running {
                *m = master;
            }
            return Some(d);
        }
        let mut running = self.running;
        let d = match &mut running {
            Running::CyclicVelocity => self.cyclic_velocity(o, new_setpoint),
            Running::CyclicTorque => Demand {
                entry: ControlEntry::Torque,
                torque: self
                    .lock
                    .filter_torque(self.per_mille(i32::from(o.target_torque) + i32::from(o.torque_offset))),
                bits: SW_MODE_BIT12,
                ..Demand::hold(*actual)
            },
            Running::ProfilePosition(_) if self.record_command != 0 => {
                self.record_position(od, o, halt, *actual, i199, now_ns, dt_ns)
            }
            Running::ProfilePosition(pp) => self.profile_position(pp, o, halt, *actual, now_ns, dt_ns),
            Running::ProfileVelocity(pv) => self.profile_velocity(pv, o, halt, now_ns, dt_ns),
            Running::ProfileTorque { torque } => self.profile_torque(torque, o, dt_ns, *actual),
            Running::Velocity(vl) => self.velocity_mode(vl, o, dt_ns),
            Running::Homing => self.run_homing(o, io, actual, i199, dt_ns),
            Running::Jog(jog) => self.jog(jog, o, dt_ns),
            // csp/ip returned above
            Running::CyclicPosition { .. } | Running::NoMode | Running::Idle => Demand::hold(self.sp_pos),
        };
        self.running = running;
        Some(d)
    }

    /// The cascade and the monitors; returns (torque N·m user coordinates,
    /// mode bits incl. bit 11, following error inc).
    pub(super) fn control(
        &mut self,
        demand: Option<Demand>,
        actual: i32,
        now_ns: Nanos,
        dt_ns: u32,
    ) -> (f32, u16, i32) {
        let shifted = self.shift(demand, dt_ns);
        let (Some(d), Some(cascade)) = (demand, self.cascade.as_mut()) else {
            self.last_out = None;
            self.last_entry = None;
            self.following.reset();
            return (0.0, 0, 0);
        };
        let fed = shifted.unwrap_or(d);
        let input = CascadeInput {
            entry: d.entry,
            position_setpoint_inc: fed.position,
            velocity_inc_per_s: fed.velocity,
            acceleration_feedforward_inc_per_s2: fed.acceleration,
            torque_nm: d.torque,
            actual_position_inc: actual,
            actual_velocity_inc_per_s: Some(self.velocity),
        };
        let c = cascade.cycle(&input, dt_ns);
        self.last_out = Some(c);
        self.last_entry = Some(d.entry);
        let mut bits = d.bits;
        if d.entry == ControlEntry::Position {
            self.sp_pos = d.position;
            self.sp_vel = d.velocity;
            let fe = self.following.update(fed.position, actual, now_ns);
            if let Some(ev) = fe.event {
                self.raise(ev);
            }
            if let Some(ev) = fe.limit_event {
                self.raise(ev);
            }
            // bit 13 of csp/pp is the monitor's state after this cycle
            if matches!(
                self.running,
                Running::CyclicPosition { ip: false, .. } | Running::ProfilePosition(_)
            ) && fe.following_error
            {
                bits |= SW_MODE_BIT13;
            }
        } else {
            self.sp_pos = actual;
            self.sp_vel = if d.entry == ControlEntry::Velocity {
                d.velocity
            } else {
                self.velocity
            };
            self.following.reset();
        }
        if c.internal_limit || self.lock.any() {
            bits |= SW_INTERNAL_LIMIT;
        }
        (c.torque_nm, bits, c.following_error_inc)
    }
}
