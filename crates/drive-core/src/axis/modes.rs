//! The set-point generators of the modes (module docs of [`super`], table
//! "Modes"): one method per mode, each returning the cycle's [`Demand`],
//! and the stop ramps.

use super::*;

impl Axis {
    /// Sets the generator of `mode` up from the present set-point state
    /// (bumpless mode change and enable).
    pub(super) fn activate(&mut self, mode: Mode, o: &Snapshot, actual: i32) {
        self.running = Running::start(mode, self.last_out.map_or(0.0, |c| c.torque_nm));
        self.following.reset();
        self.in_position.reset();
        self.velocity_window.reset();
        // a bit 4 already set is no edge (pp, homing)
        self.prev_cw = o.controlword;
        match mode {
            Mode::CyclicPosition | Mode::InterpolatedPosition => {
                if let Some(i) = self.interp.as_mut() {
                    i.start(self.sp_pos);
                }
            }
            Mode::CyclicVelocity => {
                if let Some(v) = self.vinterp.as_mut() {
                    v.start(self.sp_vel);
                }
            }
            Mode::ProfileTorque => {}
            Mode::Homing => self.homing.activate(actual),
            Mode::ProfilePosition => {
                self.record_fresh = true;
                // entered while moving (from pv, vl, jog): no target yet, so
                // brake with 6084h instead of cruising on
                self.profile.take_over(self.sp_pos, self.sp_vel);
                if self.sp_vel != 0.0 {
                    let _ = self.profile.stop(o.deceleration as f32, jerk(o.jerk));
                }
            }
            _ => self.profile.take_over(self.sp_pos, self.sp_vel),
        }
    }

    pub(super) fn run_stop(
        &mut self,
        o: &Snapshot,
        d: Decel,
        from_actual: bool,
        actual: i32,
        i199: bool,
        dt_ns: u32,
    ) -> Demand {
        if self.stop.is_none() {
            let vl = matches!(self.running, Running::Velocity(_));
            let (decel, jerk_) = match d {
                Decel::SlowDown if vl => (ramp_rate(o.vl_deceleration), f32::INFINITY),
                Decel::SlowDown => (o.deceleration as f32, jerk(o.jerk)),
                Decel::QuickStop if vl => (ramp_rate(o.vl_quick_stop), f32::INFINITY),
                Decel::QuickStop => (o.quick_stop_deceleration as f32, f32::INFINITY),
                Decel::CurrentLimit | Decel::VoltageLimit => (0.0, 0.0),
            };
            let (p, v) = if from_actual || self.last_entry != Some(ControlEntry::Position) {
                (actual, self.velocity)
            } else {
                (self.sp_pos, self.sp_vel)
            };
            self.profile.take_over(p, v);
            self.stop = match self.profile.stop(decel, jerk_) {
                Ok(()) => Some(Stop::Profile),
                Err(_) => Some(Stop::Brake),
            };
            self.running = Running::Idle;
        }
        match self.stop {
            Some(Stop::Brake) => {
                if i199 {
                    // at standstill: hold where the axis stopped
                    self.profile.reset(actual);
                    self.stop = Some(Stop::Profile);
                }
                Demand {
                    entry: ControlEntry::Velocity,
                    bits: if i199 { SW_TARGET_REACHED } else { 0 },
                    ..Demand::hold(actual)
                }
            }
            _ => {
                let s = self.profile.step(dt_ns);
                Demand {
                    position: s.position,
                    velocity: s.velocity,
                    acceleration: s.acceleration,
                    bits: if s.done && i199 { SW_TARGET_REACHED } else { 0 },
                    ..Demand::hold(s.position)
                }
            }
        }
    }

    // out of line: inlined into `motion` it costs the csp cycle ~30 instructions
    #[inline(never)]
    pub(super) fn cyclic_position(
        &mut self,
        master: &mut MasterTrack,
        o: &Snapshot,
        ip: bool,
        new_setpoint: bool,
    ) -> Demand {
        let enabled = !ip || o.controlword & CW_MODE_BIT4 != 0;
        let torque = self.per_mille(i32::from(o.torque_offset));
        if !enabled {
            if let Some(interp) = self.interp.as_mut() {
                interp.start(self.sp_pos);
            }
            master.setpoint = None;
            master.user = None;
            return Demand {
                torque,
                ..Demand::hold(self.sp_pos)
            };
        }
        let target = match self.modulo {
            // C-111: the master sends wrapped positions; unwrapped the short way
            Some(m) if new_setpoint => {
                let sent = i64::from(if ip {
                    o.ip_setpoint_user
                } else {
                    o.target_position_user
                });
                let (base, base_user) = match (master.setpoint, master.user) {
                    (Some(b), Some(u)) => (b, u),
                    _ => (self.sp_pos, self.user_position(self.sp_pos)),
                };
                master.user = Some(m.wrap(sent));
                base.wrapping_add(self.increments(m.distance(base_user, sent, ModuloDirection::Shortest)))
            }
            Some(_) => master.setpoint.unwrap_or(self.sp_pos),
            None if ip => o.ip_setpoint,
            None => o.target_position,
        };
        // C-148: set-value monitoring of the master's steps
        let master_period = Nanos::from_ns(self.ratio.map_or(0, |r| u64::from(r.master_ns())));
        master.age += Nanos::from_ns(u64::from(self.ratio.map_or(0, |r| r.control_ns())));
        if new_setpoint {
            let from = master.setpoint.unwrap_or(self.sp_pos);
            let step = target.wrapping_sub(from).unsigned_abs() as f32;
            let elapsed = master.age.max(master_period);
            let elapsed_s = motion::float::from_u64(elapsed.as_ns()) * 1e-9;
            let allowed = 2.0 * o.max_profile_velocity as f32 * elapsed_s + o.target_window as f32;
            master.setpoint = Some(target);
            master.age = Nanos::ZERO;
            if self.params.set_value_monitoring && step > allowed {
                self.raise(Event::SET_VALUE_JUMP);
                return Demand::hold(self.sp_pos);
            }
        }
        let Some(interp) = self.interp.as_mut() else {
            return Demand::hold(self.sp_pos);
        };
        let sp = new_setpoint.then_some(MasterSetpoint {
            position: target,
            velocity_offset: o.velocity_offset as f32,
        });
        match interp.cycle(sp) {
            Ok(x) => {
                let (position, velocity, acceleration) = if self.lock.refuses_move(self.sp_pos, x.position) {
                    (self.sp_pos, 0.0, 0.0)
                } else {
                    (x.position, x.velocity_feedforward, x.acceleration_feedforward)
                };
                Demand {
                    entry: ControlEntry::Position,
                    position,
                    velocity,
                    acceleration,
                    torque,
                    bits: SW_MODE_BIT12,
                }
            }
            Err(f) => {
                self.raise(f.event());
                Demand::hold(self.sp_pos)
            }
        }
    }

    pub(super) fn cyclic_velocity(&mut self, o: &Snapshot, new_setpoint: bool) -> Demand {
        let torque = self.per_mille(i32::from(o.torque_offset));
        let Some(v) = self.vinterp.as_mut() else {
            return Demand::hold(self.sp_pos);
        };
        match v.cycle(new_setpoint.then_some(o.target_velocity as f32)) {
            Ok(x) => Demand {
                entry: ControlEntry::Velocity,
                velocity: self.lock.filter_velocity(x.velocity + o.velocity_offset as f32),
                acceleration: x.acceleration,
                torque,
                bits: SW_MODE_BIT12,
                position: self.sp_pos,
            },
            Err(f) => {
                self.raise(f.event());
                Demand {
                    entry: ControlEntry::Velocity,
                    ..Demand::hold(self.sp_pos)
                }
            }
        }
    }

    pub(super) fn profile_position(
        &mut self,
        pp: &mut PpState,
        o: &Snapshot,
        halt: bool,
        actual: i32,
        now_ns: Nanos,
        dt_ns: u32,
    ) -> Demand {
        let cw = o.controlword;
        let bit4 = cw & CW_MODE_BIT4 != 0;
        let edge = bit4 && self.prev_cw & CW_MODE_BIT4 == 0;
        if halt && !pp.halting {
            let _ = self.profile.stop(o.deceleration as f32, jerk(o.jerk));
            pp.halting = true;
            pp.target = None;
        } else if !halt && pp.halting {
            pp.halting = false;
        }
        if edge && !halt {
            self.take_pp_target(pp, o, actual);
        }
        if !bit4 {
            pp.ack = false;
        }
        // C-030: a changed override re-plans the running move (0 % pauses it)
        if o.override_percent != pp.override_percent && !pp.halting {
            pp.override_percent = o.override_percent;
            if let Some(t) = pp.target {
                let _ = if o.override_percent == 0 {
                    self.profile.stop(o.deceleration as f32, jerk(o.jerk))
                } else {
                    self.profile
                        .move_to(
                            PositionTarget::Absolute(t),
                            self.profile_limits(o),
                            SetMode::Immediate,
                        )
                        .map(|_| ())
                };
            }
        }
        let s = self.profile.step(dt_ns);
        let target = pp.target.unwrap_or(self.profile.target());
        if s.done && s.position == target {
            pp.target = None;
        }
        let reached = if pp.halting {
            s.done
        } else {
            self.in_position.update(target, actual, s.done, now_ns)
        };
        let mut bits = 0;
        if reached {
            bits |= SW_TARGET_REACHED;
        }
        if pp.ack {
            bits |= SW_MODE_BIT12;
        }
        Demand {
            position: s.position,
            velocity: s.velocity,
            acceleration: s.acceleration,
            bits,
            ..Demand::hold(s.position)
        }
    }

    /// A bit-4 edge in pp (C-041 – C-047, C-050).
    pub(super) fn take_pp_target(&mut self, pp: &mut PpState, o: &Snapshot, actual: i32) {
        let cw = o.controlword;
        let d = o.target_position;
        let (target, resolved, relative) = if cw & CW_MODE_BIT6 == 0 {
            match self.modulo {
                // C-111: a position within the revolution length, reached the
                // way 60F2h bits 7..6 say (01 negative, 10 positive, else the
                // shorter way); outside the length the move is refused (I90 = 10)
                Some(m) => {
                    let t = i64::from(o.target_position_user);
                    if t < 0 || t >= m.length() {
                        return;
                    }
                    let dir = match (o.positioning_option >> 6) & 0b11 {
                        0b01 => ModuloDirection::Negative,
                        0b10 => ModuloDirection::Positive,
                        _ => ModuloDirection::Shortest,
                    };
                    let from = self.user_position(self.sp_pos);
                    let p = self
                        .sp_pos
                        .wrapping_add(self.increments(m.distance(from, t, dir)));
                    (PositionTarget::Absolute(p), p, false)
                }
                None => (PositionTarget::Absolute(d), d, false),
            }
        } else if o.positioning_option & 0b11 == 0b10 {
            (
                PositionTarget::Relative { distance: d, actual },
                actual.wrapping_add(d),
                true,
            )
        } else {
            (
                PositionTarget::Additive(d),
                pp.target.unwrap_or(self.profile.target()).wrapping_add(d),
                true,
            )
        };
        let refused = (!relative && self.params.absolute_needs_reference && !self.is_referenced())
            || (relative && self.limits.relative_move_exceeds_computing_limit(i64::from(d)))
            || self.lock.refuses_move(self.sp_pos, resolved);
        if refused {
            return;
        }
        let mode = if cw & CW_MODE_BIT5 != 0 {
            SetMode::Immediate
        } else {
            SetMode::WhenStandstill
        };
        if o.override_percent == 0 {
            // paused by the override: taken over, started when A340 > 0
            pp.target = Some(resolved);
            pp.override_percent = 0;
            pp.ack = true;
            self.in_position.reset();
            return;
        }
        if let Ok(true) = self.profile.move_to(target, self.profile_limits(o), mode) {
            pp.target = Some(self.profile.target());
            pp.override_percent = o.override_percent;
            pp.ack = true;
            self.in_position.reset();
        }
    }

    pub(super) fn profile_velocity(
        &mut self,
        pv: &mut VelocityCommand,
        o: &Snapshot,
        halt: bool,
        now_ns: Nanos,
        dt_ns: u32,
    ) -> Demand {
        // C-030: 60FFh × A340
        let target = self
            .lock
            .filter_velocity(o.target_velocity as f32 * override_factor(o));
        if halt {
            if !pv.halting {
                let _ = self.profile.stop(o.deceleration as f32, jerk(o.jerk));
                pv.halting = true;
                pv.commanded = None;
            }
        } else {
            pv.halting = false;
            if pv.commanded != Some(target) {
                let limits = ProfileLimits {
                    velocity: o.max_profile_velocity as f32,
                    ..self.profile_limits(o)
                };
                if self.profile.run_velocity(target, limits).is_ok() {
                    pv.commanded = Some(target);
                }
            }
        }
        let s = self.profile.step(dt_ns);
        let st = self
            .velocity_window
            .update(target, s.velocity, self.velocity, now_ns);
        let mut bits = 0;
        if st.target_reached {
            bits |= SW_TARGET_REACHED;
        }
        if st.zero_speed {
            bits |= SW_MODE_BIT12;
        }
        if st.slippage_error {
            bits |= SW_MODE_BIT13;
        }
        Demand {
            entry: ControlEntry::Velocity,
            velocity: s.velocity,
            acceleration: s.acceleration,
            bits,
            ..Demand::hold(s.position)
        }
    }

    pub(super) fn profile_torque(&mut self, ramp: &mut f32, o: &Snapshot, dt_ns: u32, actual: i32) -> Demand {
        let max = self.per_mille(i32::from(o.max_torque));
        let target = self
            .lock
            .filter_torque(self.per_mille(i32::from(o.target_torque)).max(-max).min(max));
        let slope = self.per_mille(i32::try_from(o.torque_slope).unwrap_or(i32::MAX)) * dt_ns as f32 * 1e-9;
        let diff = target - *ramp;
        *ramp = if o.torque_slope == 0 || diff.abs() <= slope {
            target
        } else {
            *ramp + slope.copysign(diff)
        };
        Demand {
            entry: ControlEntry::Torque,
            torque: *ramp,
            bits: if *ramp == target { SW_TARGET_REACHED } else { 0 },
            ..Demand::hold(actual)
        }
    }

    pub(super) fn velocity_mode(&mut self, vl: &mut VelocityCommand, o: &Snapshot, dt_ns: u32) -> Demand {
        let cw = o.controlword;
        let max = o.vl_max as f32;
        let min = o.vl_min as f32;
        let mut rpm = (f32::from(o.vl_target) * override_factor(o)).max(-max).min(max);
        if rpm != 0.0 && rpm.abs() < min {
            rpm = min.copysign(rpm);
        }
        let enable = cw & CW_MODE_BIT4 != 0 && cw & CW_MODE_BIT6 != 0;
        let unlocked = cw & CW_MODE_BIT5 != 0;
        let target = if enable {
            self.lock.filter_velocity(rpm * RPM_TO_INC_PER_S)
        } else {
            0.0
        };
        if (unlocked || !enable) && vl.commanded != Some(target) {
            let limits = ProfileLimits {
                velocity: (max * RPM_TO_INC_PER_S).max(1.0),
                acceleration: ramp_rate(o.vl_acceleration),
                deceleration: ramp_rate(o.vl_deceleration),
                jerk: f32::INFINITY,
            };
            if self.profile.run_velocity(target, limits).is_ok() {
                vl.commanded = Some(target);
            }
        }
        let s = self.profile.step(dt_ns);
        self.vl_demand = s.velocity;
        Demand {
            entry: ControlEntry::Velocity,
            velocity: s.velocity,
            acceleration: s.acceleration,
            ..Demand::hold(s.position)
        }
    }

    pub(super) fn run_homing(
        &mut self,
        o: &Snapshot,
        io: &AxisIo,
        actual: &mut i32,
        i199: bool,
        dt_ns: u32,
    ) -> Demand {
        let p = self.params;
        let cfg = HomingConfig {
            method: o.homing_method,
            fast_speed: o.homing_fast as f32,
            slow_speed: o.homing_slow as f32,
            acceleration: o.homing_acceleration as f32,
            jerk: p.homing_jerk,
            home_offset: o.home_offset,
            move_to_home: p.homing_move_to_home,
            index_search_offset: p.homing_index_offset,
            torque_hold: p.homing_torque_hold_ns,
            max_search_distance: 0,
            limit_as_reference: p.homing_limit_as_reference,
        };
        // the latest latched change of each switch in this cycle, user coordinates
        let edge = |id: SwitchId| {
            io.switch_edges
                .iter()
                .flatten()
                .rfind(|e| e.switch == id)
                .map(|e| self.to_user(e.position_inc, o.polarity))
        };
        let switch = |active: bool, id: SwitchId| SwitchInput {
            active,
            edge: edge(id),
        };
        let limits = self.limits.config();
        let input = HomingInput {
            actual_position: *actual,
            negative_limit: switch(
                limits.negative_switch && io.limit_negative,
                SwitchId::NegativeLimit,
            ),
            positive_limit: switch(
                limits.positive_switch && io.limit_positive,
                SwitchId::PositiveLimit,
            ),
            reference_switch: switch(io.reference, SwitchId::Reference),
            index: io.index.map(|i| self.to_user(i.position_inc, o.polarity)),
            torque_limit: self.last_out.is_some_and(|c| c.torque_limited),
            standstill: i199,
            start: o.controlword & CW_MODE_BIT4 != 0,
            halt: o.controlword & CW_HALT != 0,
        };
        let h = self.homing.step(&cfg, &input, dt_ns);
        if let Some(ev) = h.reference {
            // C-061: the reference point reads 607Ch from now on
            self.shift_coordinates(ev.shift);
            *actual = actual.wrapping_add(ev.shift);
        }
        Demand {
            position: h.position,
            velocity: h.velocity,
            acceleration: h.acceleration,
            bits: h.status.statusword_bits() & (SW_TARGET_REACHED | SW_MODE_BIT12 | SW_MODE_BIT13),
            ..Demand::hold(h.position)
        }
    }

    pub(super) fn jog(&mut self, jog: &mut VelocityCommand, o: &Snapshot, dt_ns: u32) -> Demand {
        let p = self.params;
        let cw = o.controlword;
        let dir: f32 = match (cw & CW_MODE_BIT4 != 0, cw & CW_MODE_BIT5 != 0) {
            (true, false) => 1.0,
            (false, true) => -1.0,
            _ => 0.0,
        };
        let limits = ProfileLimits {
            velocity: p.jog_velocity,
            acceleration: p.jog_acceleration,
            deceleration: p.jog_deceleration,
            jerk: p.jog_jerk,
        };
        self.jog_with(jog, dir, limits, dt_ns)
    }

    /// The core's jog: `dir` (+1, −1, 0 = stop) at `limits.velocity` with
    /// `limits`' ramps; under position control (I26 = 1) it stops before a
    /// software limit (C-092). A changed velocity re-plans. Jog mode (−1)
    /// and the jog records (259/260, `records.rs`) run on it.
    pub(super) fn jog_with(
        &mut self,
        jog: &mut VelocityCommand,
        dir: f32,
        limits: ProfileLimits,
        dt_ns: u32,
    ) -> Demand {
        let p = self.params;
        let referenced = self.is_referenced();
        let soft = referenced && self.limits.config().software_limits_configured();
        let target = self.lock.filter_velocity(dir * limits.velocity);
        if jog.commanded != Some(target) {
            let ok = if target == 0.0 {
                self.profile.stop(limits.deceleration, limits.jerk).is_ok()
            } else if p.jog_position_control && soft {
                // C-092: stop before the software limit
                let far = if target > 0.0 { i32::MAX } else { i32::MIN };
                let goal = self.limits.clamp_target(far, referenced);
                self.profile
                    .move_to(PositionTarget::Absolute(goal), limits, SetMode::Immediate)
                    .is_ok()
            } else {
                self.profile.run_velocity(target, limits).is_ok()
            };
            if ok {
                jog.commanded = Some(target);
            }
        }
        let s = self.profile.step(dt_ns);
        Demand {
            entry: if p.jog_position_control {
                ControlEntry::Position
            } else {
                ControlEntry::Velocity
            },
            position: s.position,
            velocity: s.velocity,
            acceleration: s.acceleration,
            torque: 0.0,
            bits: 0,
        }
    }

    /// 0.1 % of the rated torque → N·m.
    pub(super) fn per_mille(&self, v: i32) -> f32 {
        self.motor.rated_torque_nm() * v as f32 * 0.001
    }
}
