//! The configuration of an axis from its snapshot: what changes only when
//! the configuration generation does (limits, windows, scaling, the
//! cascade's gains, the interpolators).

use super::*;

impl Axis {
    /// Applies the configuration objects and parameters.
    pub(super) fn configure(&mut self, od: &mut DriveObjects, slots: &CyclicSlots, o: &Snapshot, dt_ns: u32) {
        // the settings of the dictionary (issue 40), in increments
        let [v, a, d, j] = o.jog.map(|x| x as f32);
        self.params.jog_velocity = v;
        self.params.jog_acceleration = a;
        self.params.jog_deceleration = d;
        self.params.jog_jerk = if j > 0.0 { j } else { f32::INFINITY };
        self.params.jog_position_control = o.i26 != 0;
        self.params.quick_stop_on_enable_loss = o.a44 == 1;
        self.configure_brake(o);
        self.params.following_error_fault = o.monitors.0 == 1;
        self.params.set_value_monitoring = o.monitors.1 == 1;
        self.params.limits.endless_axis = o.i00 == 1;
        // I101/I102 (C-104): 0 off, 1 the input, 2 I210
        self.params.limits.positive_switch = o.switch_source[0] != 0;
        self.params.limits.negative_switch = o.switch_source[1] != 0;
        self.params.limits.permitted_direction = match o.i04 {
            1 => PermittedDirection::PositiveOnly,
            2 => PermittedDirection::NegativeOnly,
            _ => PermittedDirection::Both,
        };
        self.params.homing_torque_limit_per_mille = o.homing_torque.0;
        self.params.homing_torque_hold_ns = ms_to_ns(o.homing_torque.1);
        self.params.homing_limit_as_reference = o.i30_i43.0 == 2;
        self.params.homing_move_to_home = o.i30_i43.1 == 1;
        self.params.homing_index_offset = o.i53;
        let (i25, i425, i423) = o.interpolation;
        self.params.feedforward_percent = f32::from(i25);
        self.params.interpolation_i425 = i425;
        self.params.max_extrapolation_ns = ms_to_ns(i423);
        self.params.position_window_time_ns = ms_to_ns(o.i87);
        let [i10, c40, i44] = o.speeds.map(|x| x as f32);
        // the motor data (issue 34), prepared for the cycle: I10 is capped
        // by the motor's 6080h
        self.motor = o.motor;
        self.i2t.configure(&o.motor, dt_ns);
        self.params.cascade.max_velocity_inc_per_s = i10.min(o.motor.max_speed_inc_per_s());
        self.params.velocity_window_inc_per_s = c40;
        self.params.homing_jerk = if i44 > 0.0 { i44 } else { f32::INFINITY };
        let p = self.params;
        self.modulo = if p.limits.endless_axis && o.modulo_length > 0 {
            ModuloAxis::new(i64::from(o.modulo_length)).ok()
        } else {
            None
        };
        // 6076h = kt × 6075h, and the probe values in the (new) units
        od.write_typed(
            slots.rated_torque,
            round_i32(self.motor.rated_torque_nm() * 1000.0).max(0) as u32,
        );
        self.probe_shown = false;
        let opts = self.dc.options_mut();
        if let Ok(q) = QuickStopOption::try_from(o.quick_stop_option) {
            opts.quick_stop = q;
        }
        if let Ok(f) = FaultReaction::try_from(o.fault_reaction_option) {
            opts.fault_reaction = f;
        }
        opts.quick_stop_on_enable_loss = p.quick_stop_on_enable_loss;

        // cycle ratio (C-114): 60C2h over A150; 60C2h is copied into A291
        // when the interpolation's configuration changes (60C2h, A150, at
        // start), not at every configuration change: a master's own A291
        // write stays until then
        let master_ns = interpolation_period_ns(o.period_value, o.period_index).unwrap_or(dt_ns);
        let ratio = CycleRatio::new(master_ns, dt_ns)
            .or_else(|_| CycleRatio::new(dt_ns, dt_ns))
            .ok();
        let key = ratio.map(|r| {
            (
                r,
                p.interpolation_i425,
                p.feedforward_percent.to_bits(),
                p.max_extrapolation_ns,
            )
        });
        if key != self.interp_key || self.interp_master_ns != master_ns {
            if self.window.axis == 0 {
                od.write_typed(slots.a291, master_ns / 1000);
            }
            self.interp_master_ns = master_ns;
            self.interp_key = key;
            self.ratio = ratio;
            self.rebuild_interpolators();
        }

        // cascade: torque limits from 6072h (homing: I28), gains adapted to A150
        let per_mille = if matches!(self.running, Running::Homing) {
            o.max_torque.min(p.homing_torque_limit_per_mille)
        } else {
            o.max_torque
        };
        // the current limit (6073h, 2415h.02, i²t: motor.rs) in ‰ of the
        // rated current is the same ‰ of the rated torque (T = kt·i)
        let per_mille = per_mille.min(self.current_limit_per_mille());
        let max_nm = self.motor.rated_torque_nm() * f32::from(per_mille) * 0.001;
        // G472/G475 (C-039): 0.1 % of the maximum speed I10
        let [g472, g475] = o
            .torque_mode_speed_limit
            .map(|l| p.cascade.max_velocity_inc_per_s * f32::from(l) * 0.001);
        let mut cfg = CascadeConfig {
            torque_limit_positive_nm: max_nm,
            torque_limit_negative_nm: max_nm,
            velocity_feedforward_percent: 100.0,
            position_dead_band_inc: o.dead_band,
            torque_mode_velocity_limit_positive_inc_per_s: g472,
            torque_mode_velocity_limit_negative_inc_per_s: g475,
            ..scaled_gains(&declared_gains(&p.cascade, o), dt_ns)
        };
        if !self.torque_mode_speed_limit.is_nan() {
            cfg.torque_mode_velocity_limit_positive_inc_per_s = self.torque_mode_speed_limit;
            cfg.torque_mode_velocity_limit_negative_inc_per_s = self.torque_mode_speed_limit;
        }
        if let Some(c) = self.cascade.as_mut() {
            if *c.config() != cfg {
                let _ = c.set_config(cfg);
            }
        }

        self.following.set_config(FollowingErrorConfig {
            window_inc: o.following_error_window,
            timeout: ms_to_ns(o.following_error_timeout_ms),
            fault: p.following_error_fault,
            limit_inc: o.position_error_limit,
        });
        self.in_position.set_config(PositionWindowConfig {
            window_inc: o.target_window,
            time: p.position_window_time_ns,
        });
        self.velocity_window.set_config(VelocityWindowConfig {
            window_inc_per_s: p.velocity_window_inc_per_s,
            time: p.velocity_window_time_ns,
        });
        // C-091: jog under velocity control (I26 = 0) quick-stops at a
        // software limit instead of faulting
        self.retained = o.i46 == 5 && o.i02 == 0;
        let soft_limit_reaction = if matches!(self.running, Running::Jog(_)) && !p.jog_position_control {
            SoftLimitReaction::QuickStop
        } else {
            p.limits.soft_limit_reaction
        };
        self.limits.set_config(LimitConfig {
            software_min_inc: o.software_min,
            software_max_inc: o.software_max,
            window_inc: o.target_window,
            switch_polarity: SwitchPolarity::HighActive,
            soft_limit_reaction,
            ..p.limits
        });
    }

    /// A motor action replaced this cycle's command (`crate::actions`): the
    /// drive's own set-point follows the actual position (as with the drive
    /// function off), the profile generator stands there, and the cascade's
    /// integral part and the following-error monitor start from rest, so
    /// that the axis takes over where the action left the shaft, without
    /// the torque its velocity controller wound up against the action's
    /// movement (B301 turns the shaft by some three revolutions, B44 by up
    /// to twelve). The mode stays active; a cyclic mode's set-point is the
    /// master's again from the next cycle on (it follows 6064h meanwhile, as
    /// a master does while the drive does not follow it). Done at the start
    /// of the next cycle, from its actual position, before its set-point is
    /// made: while an action moves the shaft, 60F4h reads 0.
    pub fn overridden(&mut self) {
        self.follow_actual = true;
    }

    /// The set-point state, the profile generator, the speed integral and
    /// the following-error monitor at `actual` (the mode stays active).
    pub(super) fn follow(&mut self, actual: i32) {
        self.sp_pos = actual;
        self.sp_vel = 0.0;
        self.vl_demand = 0.0;
        self.profile.reset(actual);
        self.following.reset();
        if let Some(c) = self.cascade.as_mut() {
            c.reset(actual);
        }
    }

    pub(super) fn rebuild_interpolators(&mut self) {
        let p = self.params;
        let (interp, vinterp) = match (self.ratio, from_i425(p.interpolation_i425)) {
            (Some(ratio), Ok((order, feedforward))) => (
                FineInterpolator::new(InterpolatorConfig {
                    ratio,
                    order,
                    feedforward,
                    velocity_feedforward_percent: p.feedforward_percent,
                    max_extrapolation: p.max_extrapolation_ns,
                })
                .ok(),
                Some(VelocityInterpolator::new(ratio, p.max_extrapolation_ns)),
            ),
            (Some(ratio), Err(_)) => (
                None,
                Some(VelocityInterpolator::new(ratio, p.max_extrapolation_ns)),
            ),
            _ => (None, None),
        };
        self.interp = interp;
        self.vinterp = vinterp;
        // a running cyclic mode restarts from the present set-point
        if let Some(i) = self.interp.as_mut() {
            i.start(self.sp_pos);
        }
        if let Some(v) = self.vinterp.as_mut() {
            v.start(self.sp_vel);
        }
    }
}

/// The cascade of the parameters with the gains of the dictionary: I20 Kv,
/// C31 Kp, C32 Ti (issue 40); with identified mechanics (B45 ≠ 0, issue 35)
/// its inertia for the acceleration feedforward (derived from the set-points
/// where the generator gives none), the friction feedforward of B46/B47 and
/// the speed measurement's lag compensated with J·a's acceleration.
fn declared_gains(c: &CascadeConfig, o: &Snapshot) -> CascadeConfig {
    let (kv, kp, ti) = o.gains;
    let gains = CascadeConfig {
        position_gain_per_s: f32::from(kv) * 0.1,
        velocity_gain_nm_per_rad_per_s: kp as f32 * 1e-6,
        velocity_integral_time_ns: ti.saturating_mul(1000),
        ..*c
    };
    match o.mechanics {
        (0, _, _) => gains,
        (j, fc, b) => CascadeConfig {
            inertia_kg_m2: j as f32 * 1e-7,
            coulomb_friction_nm: fc as f32 * 1e-6,
            viscous_friction_nm_per_rad_per_s: b as f32 * 1e-9,
            derive_acceleration: true,
            compensate_velocity_lag: true,
            ..gains
        },
    }
}
