//! One axis of the drive: CiA 402 device control, the motion core and the
//! control cascade composed, stepped once per control cycle (A150) against
//! the object dictionary.
//!
//! [`Axis::cycle`] reads the axis' set-point and configuration objects (axis A
//! at the CiA 402 indices, axis B at +800h; per-axis manufacturer parameters
//! at +8000h), takes the hardware seam [`AxisIo`] (encoder, switches, probe
//! edges, enable signals), steps [`cia402::DeviceControl`], runs the active
//! mode and the cascade and returns the [`AxisCommand`] for the power stage
//! (torque, power stage, brake); the actual values go back into the
//! dictionary (6041h, 6061h, 6064h, 606Ch, 6077h, 6078h, 60F4h, 60B9h–60BDh,
//! 603Fh, 60FDh, 6043h/6044h, E48).
//!
//! # Modes
//!
//! | mode | set-points | generator | cascade entry |
//! |---|---|---|---|
//! | csp (8) | 607Ah, 60B1h, 60B2h | [`FineInterpolator`] | position |
//! | ip (7) | 60C1h:01 while controlword bit 4 | [`FineInterpolator`] | position |
//! | csv (9) | 60FFh + 60B1h, 60B2h | [`VelocityInterpolator`] | velocity |
//! | cst (10) | 6071h + 60B2h | – | torque (speed limiter G472/G475) |
//! | pp (1) | 607Ah, 6081h/607Fh, 6083h, 6084h, 60A4h, 60F2h, bits 4/5/6 | [`ProfileGenerator`] | position |
//! | pv (3) | 60FFh, 6083h, 6084h, 60A4h | [`ProfileGenerator`] | velocity |
//! | pt (4) | 6071h, 6087h, 6072h | torque ramp | torque |
//! | vl (2) | 6042h, 6046h, 6048h, 6049h, bits 4/5/6 | [`ProfileGenerator`] | velocity |
//! | homing (6) | 6098h, 6099h, 609Ah, 607Ch, bit 4, bit 8 | [`Homing`] | position |
//! | jog (−1) | bits 4/5, I12/I13/I45/I18 ([`AxisParams`]) | [`ProfileGenerator`] | position (I26 = 1) / velocity |
//! | no mode (0) | – | holds the set-point | position |
//!
//! The running mode and the state only it keeps (the pp target and its
//! handshake, the pv/vl/jog velocity command, the pt torque ramp, the
//! master's last csp/ip set-point) are one `Running` value (`running.rs`):
//! activating a mode starts its variant fresh and a stop or disable drops
//! it, so no mode reads what another left behind. What the modes share (the
//! set-point, the profile generator, the interpolators, homing, the monitors
//! and limits) stays in [`Axis`].
//!
//! Quick stop, the fault reaction and the disable ramps come from the device
//! control's [`Ramp`]: slow-down (6084h) and quick-stop (6085h; vl: 604Ah)
//! ramps run on the profile generator from the present set-point (fault
//! reaction: from the actual position and velocity); "current limit" and
//! "voltage limit" brake in the velocity entry at the torque limit. A stop
//! counts as finished once the ramp has ended and the axis has stood still
//! (I199) for [`AxisParams::stop_settle_ns`].
//!
//! # Timing and gains
//!
//! `cycle` runs once per A150 (the control cycle it assumes for every
//! integration step). The cascade gains in [`AxisParams::cascade`] are
//! meant for ≤ 250 µs; for a longer A150 they are scaled down
//! ([`scaled_gains`]) so the default 1 ms cycle stays stable with one cycle
//! of actuation delay. A new cyclic set-point enters the interpolators only
//! when the caller says one arrived; 60C2h over A150 gives their ratio N
//! (60C2h is copied into A291, C-114; an invalid ratio falls back to N = 1).
//!
//! Homing uses `motion::homing`: the seam is [`Axis`]'s `run_homing`
//! (config from 6098h/6099h/609Ah/607Ch and [`AxisParams`], inputs from
//! [`AxisIo`], with the latched index pulse and, when the hardware has them,
//! the latched switch changes [`AxisIo::switch_edges`]); the reference event
//! shifts the position offset.
//!
//! pp, pv and vl apply the velocity override A340 (C-030). The switch
//! signals come from the inputs or, with I101/I102/I103 = 2, from I210
//! (C-104); E80 shows a limitation (C-107), A67 is assembled from the
//! sources in A66 (C-143), E47/E49 name the causes of Switch on disabled
//! (C-015), I46 = 5 makes the encoder position the reference (C-112).
//!
//! # Coordinates
//!
//! The axis works in user increments: `actual = polarity · io.position_inc +
//! offset` (607Eh bit 7 inverts; the offset is set by homing at the reference
//! event, C-061, or by [`Axis::set_position_offset`]). The torque command is
//! turned back into motor coordinates. Velocities are inc/s, torques N·m at
//! the seam and 0.1 % of the rated torque (6076h) in the objects.
//!
//! # Faults
//!
//! Following error (6065h/6066h with the reaction I470 = 1, or beyond I21),
//! limit switches (event 53), the extrapolation overrun of the interpolators
//! (event 78 cause 3) and an excessive set-value jump of the master (event 78
//! cause 4, C-148) raise a fault in the device control; on T13 the axis
//! reports the fault ([`FaultChange::Raised`], code and register from
//! [`fault_code_for_event`]) and sets 603Fh and its error register, on T15
//! it reports [`FaultChange::Cleared`].

mod brake;
mod cache;
mod configure;
mod current;
mod fault;
mod feedback;
mod io;
mod modes;
mod monitor;
mod motor;
mod params;
mod record_state;
mod records;
mod running;
mod shift;
mod snapshot;
mod steps;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_current;
#[cfg(test)]
mod tests_records;
mod units;
pub(crate) use units::sqrt;
mod write_back;

use crate::dictionary::DriveObjects;
use crate::faults::{fault_code_for_event, Fault, FaultChange, GENERIC_ERROR};
use cia402::{
    Decel, DeviceControl, FaultEvent, FaultReaction, Inputs, Mode, Options, Outputs, QuickStopOption, Ramp,
    State, Transition, CW_HALT, CW_MODE_BIT4, CW_MODE_BIT5, CW_MODE_BIT6, SW_INTERNAL_LIMIT, SW_MODE_BIT12,
    SW_MODE_BIT13, SW_TARGET_REACHED,
};
use motion::cascade::{Cascade, CascadeConfig, CascadeInput, CascadeOutput, ControlEntry};
use motion::cycle::{application_cycle_ns, interpolation_period_ns};
use motion::homing::{Homing, HomingConfig, HomingInput, SwitchInput};
use motion::interp::from_i425;
use motion::limits::{
    DenialCause, DirectionLock, LimitConfig, LimitInput, Limits, SoftLimitReaction, StopRamp, SwitchPolarity,
};
use motion::scaling::{AxisScaling, ModuloAxis, ModuloDirection};
use motion::touch_probe::{interpolate_position, Edge, PositionSample, TouchProbe, TriggerSignal};
use motion::windows::{
    is_standstill, ms_to_ns, FollowingErrorConfig, FollowingErrorMonitor, PositionWindowConfig,
    TargetReachedMonitor, VelocityWindowConfig, VelocityWindowMonitor,
};
use motion::{
    CycleRatio, Event, FineInterpolator, InterpolatorConfig, MasterSetpoint, PositionTarget,
    ProfileGenerator, ProfileLimits, SetMode, VelocityInterpolator, INCREMENTS_PER_REVOLUTION,
};
use nanos::Nanos;
use od::error_register;
use running::{MasterTrack, PpState, Running, VelocityCommand};
pub(crate) use snapshot::{CyclicSlots, Snapshot, Window};

pub use cache::AxisCache;
use cache::CachedSnapshot;
pub use current::{trip_event, CurrentActual, CurrentControl, CurrentTrip, DAxisMeans, Injection};
pub use io::{AxisCommand, AxisIo, AxisReport, IndexLatch, ProbeEdge, SwitchEdge, SwitchId};
pub use monitor::{LOW_VOLTAGE, MOTOR_ENCODER};
pub use motor::{MotorData, MOTOR_I2T};
pub use params::AxisParams;
pub(crate) use records::RecordTasks;
pub use records::{RecordCommand, RecordStatus, StartRefusal};
pub use units::{e48, scaled_gains, GAIN_REFERENCE_CYCLE_NS};
use units::{jerk, override_factor, ramp_rate, round_i32, sat_i32, sourced};

/// The permitted direction of an endless axis (I04), for [`AxisParams::limits`].
pub use motion::limits::PermittedDirection;

/// Increments per revolution as `f32`.
const REV: f32 = INCREMENTS_PER_REVOLUTION as f32;
/// rpm → inc/s.
const RPM_TO_INC_PER_S: f32 = REV / 60.0;

/// What the mode asks of the cascade in this cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Demand {
    entry: ControlEntry,
    /// Position set-point, inc (position entry).
    position: i32,
    /// Velocity feedforward (position entry) or set-point (velocity entry), inc/s.
    velocity: f32,
    /// Acceleration feedforward, inc/s².
    acceleration: f32,
    /// Torque feedforward or set-point, N·m.
    torque: f32,
    /// Statusword bits 10, 12, 13 of the mode.
    bits: u16,
}

impl Demand {
    const fn hold(position: i32) -> Self {
        Self {
            entry: ControlEntry::Position,
            position,
            velocity: 0.0,
            acceleration: 0.0,
            torque: 0.0,
            bits: 0,
        }
    }
}

/// A running stop of the device control.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stop {
    /// On the profile generator.
    Profile,
    /// Velocity entry at 0 (current/voltage limit).
    Brake,
}

/// One axis. See the [module documentation](self).
#[derive(Debug, Clone)]
pub struct Axis {
    window: Window,
    params: AxisParams,
    dc: DeviceControl,
    ratio: Option<CycleRatio>,
    interp: Option<FineInterpolator>,
    vinterp: Option<VelocityInterpolator>,
    /// (ratio, I425, I25, I423) the interpolators were built with.
    interp_key: Option<(CycleRatio, u8, u32, Nanos)>,
    /// The 60C2h period (ns) last copied into A291.
    interp_master_ns: u32,
    profile: ProfileGenerator,
    cascade: Option<Cascade>,
    following: FollowingErrorMonitor,
    in_position: TargetReachedMonitor,
    velocity_window: VelocityWindowMonitor,
    limits: Limits,
    probe: TouchProbe,
    homing: Homing,
    /// User position = polarity · encoder + offset, inc.
    offset: i32,
    /// Last encoder reading (motor coordinates) for the velocity filter.
    last_raw: Option<i32>,
    /// The cache of [`Axis::cycle`]; the drive keeps its own next to the
    /// axes and calls [`Axis::cycle_cached`], which reads it in place.
    cache: AxisCache,
    /// What [`Self::configure`] last ran for: the configuration generation,
    /// the cycle and the mode class (homing, jog, other); it runs again
    /// only when one of them (or the parameters) changed.
    configured: Option<(u32, u32, u8)>,
    /// The objects show the touch-probe values (60BAh – 60BDh): cleared
    /// when a probe stores a value or the configuration changed, they are
    /// then converted and written again (no compare of the four values
    /// per cycle).
    probe_shown: bool,
    /// A motor action replaced the last cycle's command
    /// ([`overridden`](Self::overridden)): this cycle's set-point starts at
    /// the actual position (60F4h 0 while an action moves the shaft).
    follow_actual: bool,
    /// Filtered actual velocity, inc/s (user coordinates).
    velocity: f32,
    /// Last cycle's actual position sample (user coordinates).
    last_sample: Option<PositionSample>,
    /// Set-point state: position (inc), velocity (inc/s).
    sp_pos: i32,
    sp_vel: f32,
    /// The mode the motion core was set up for, with its own state.
    running: Running,
    /// A device-control stop in progress.
    stop: Option<Stop>,
    /// Previous controlword (edges of bit 4).
    prev_cw: u16,
    /// Last cascade output.
    last_out: Option<CascadeOutput>,
    /// Last cascade entry.
    last_entry: Option<ControlEntry>,
    /// The last drive-generated position set-point and speed ([`shift`]).
    last_setpoint: Option<(i32, f32)>,
    /// Since when I199 (standstill) holds, ns.
    standstill_since: Option<Nanos>,
    /// Direction lock of this cycle.
    lock: DirectionLock,
    /// Event behind the fault being raised / handled.
    event: Option<Event>,
    /// 603Fh and the error register while in a fault.
    error_code: u16,
    error_register: u8,
    /// vl demand (6043h), inc/s: the last vl cycle's, shown until the drive
    /// function goes off.
    vl_demand: f32,
    /// I90 cause of this cycle's direction lock (E80).
    denial: Option<DenialCause>,
    /// I46 = 5 with I02 = 0: the encoder position is the reference (C-112).
    retained: bool,
    /// 6091h/6092h of this cycle (C-109).
    scaling: AxisScaling,
    /// 10^A310 with A213 = 0, else 1 (C-142).
    velocity_decimals: f32,
    /// Endless axis (I00 = 1) with 607Bh:02 > 0, user units (C-111).
    modulo: Option<ModuloAxis>,
    /// pp was (re)activated: the record tasks start afresh (their state is
    /// in the dictionary's image, `records.rs`).
    record_fresh: bool,
    /// The record command ([`Axis::set_record_command`]): 0 none, else
    /// 0x100 | its bits (`record_state.rs`).
    record_command: u16,
    /// The torque-mode speed limit a personality sets
    /// ([`Axis::set_torque_mode_speed_limit`]), inc/s; NaN: none (G472/G475
    /// of the parameters).
    torque_mode_speed_limit: f32,
    /// The torque limit a personality sets
    /// ([`Axis::set_torque_limit_per_mille`]), ‰ of the rated torque;
    /// `u16::MAX`: none.
    torque_limit_per_mille: u16,
    /// The motor data (`motor.rs`) and its i²t model.
    motor: MotorData,
    i2t: motor::MotorI2t,
    /// The power stage's current limit (‰ of 6075h) and i²t warning, as the
    /// current loop last reported them (`motor.rs`).
    stage_limit_per_mille: u16,
    stage_warning: bool,
    /// The record status of the last cycle, packed.
    record_status: u32,
    /// F00 brake control active, F06 release override active (`brake.rs`).
    brake: (bool, bool),
}

impl Axis {
    /// Axis `axis_index` (0 = A at the CiA 402 indices, 1 = B at +800h /
    /// +8000h) with the default [`AxisParams`], in Not ready to switch on.
    pub fn new(axis_index: u8) -> Self {
        Self::with_params(axis_index, AxisParams::default())
    }

    /// Axis `axis_index` with `params`.
    pub fn with_params(axis_index: u8, params: AxisParams) -> Self {
        let options = Options {
            quick_stop_on_enable_loss: params.quick_stop_on_enable_loss,
            ..Options::default()
        };
        Self {
            window: Window { axis: axis_index },
            params,
            dc: DeviceControl::new(options),
            ratio: None,
            interp: None,
            vinterp: None,
            interp_key: None,
            interp_master_ns: 0,
            configured: None,
            probe_shown: false,
            follow_actual: false,
            profile: ProfileGenerator::new(0),
            cascade: Cascade::new(params.cascade, 0)
                .or_else(|_| Cascade::new(CascadeConfig::DEFAULT, 0))
                .ok(),
            following: FollowingErrorMonitor::new(FollowingErrorConfig::default()),
            in_position: TargetReachedMonitor::new(PositionWindowConfig::default()),
            velocity_window: VelocityWindowMonitor::new(VelocityWindowConfig::default()),
            limits: Limits::new(params.limits, 0),
            probe: TouchProbe::new(),
            homing: Homing::new(0),
            offset: 0,
            last_raw: None,
            cache: AxisCache::new(),
            velocity: 0.0,
            last_sample: None,
            sp_pos: 0,
            sp_vel: 0.0,
            running: Running::Idle,
            stop: None,
            prev_cw: 0,
            last_out: None,
            last_entry: None,
            last_setpoint: None,
            standstill_since: None,
            lock: DirectionLock::default(),
            event: None,
            error_code: 0,
            error_register: 0,
            vl_demand: 0.0,
            denial: None,
            retained: false,
            scaling: AxisScaling::INCREMENTAL,
            velocity_decimals: 1.0,
            modulo: None,
            record_fresh: true,
            record_command: 0,
            torque_mode_speed_limit: f32::NAN,
            torque_limit_per_mille: u16::MAX,
            motor: MotorData::default(),
            i2t: motor::MotorI2t::default(),
            stage_limit_per_mille: u16::MAX,
            stage_warning: false,
            record_status: 0,
            brake: (true, false),
        }
    }

    /// The parameters not in the dictionary.
    pub fn params(&self) -> &AxisParams {
        &self.params
    }

    /// The parameters not in the dictionary, to change (next cycle).
    pub fn params_mut(&mut self) -> &mut AxisParams {
        self.configured = None;
        &mut self.params
    }

    /// The device state.
    pub fn state(&self) -> State {
        self.dc.state()
    }

    /// The active mode (6061h).
    pub fn mode(&self) -> Mode {
        self.dc.mode()
    }

    /// The position offset: user position = polarity · encoder + offset, inc.
    pub fn position_offset(&self) -> i32 {
        self.offset
    }

    /// Sets the position offset (a preset, e.g. restored reference), inc.
    pub fn set_position_offset(&mut self, offset_inc: i32) {
        let shift = offset_inc.wrapping_sub(self.offset);
        self.shift_coordinates(shift);
    }

    /// The axis is referenced: homing done since power-on, or reference
    /// retaining I46 = 5 (direct absolute) on the motor encoder (C-112).
    pub fn is_referenced(&self) -> bool {
        self.homing.is_referenced() || self.retained
    }

    /// Deletes the reference (I38 "clear reference", the fieldbus action
    /// E-140): homing's and a retained one; absolute moves need homing again.
    pub fn clear_reference(&mut self) {
        self.homing.clear_reference();
        self.retained = false;
    }

    /// 603Fh error code of the fault being handled (0 = none).
    pub fn error_code(&self) -> u16 {
        self.error_code
    }

    /// CiA 301 error register bits of this axis' fault (0 = none), for 1001h.
    pub fn error_register(&self) -> u8 {
        self.error_register
    }

    /// The filtered actual velocity, inc/s.
    pub fn actual_velocity(&self) -> f32 {
        self.velocity
    }

    /// The cascade's outputs of the last control cycle (the speed
    /// controller's set-point and actual value, the following error);
    /// `None` while the cascade does not run. The scope's internal signals
    /// ([`crate::scope::Signals`]).
    pub fn cascade_output(&self) -> Option<&CascadeOutput> {
        self.last_out.as_ref()
    }

    /// Raises a fault from outside the motion core (e.g. a drive event of
    /// the power stage): T13 in the next cycle, with the EMCY of `event`.
    pub fn raise_event(&mut self, event: Event) {
        self.raise(event);
    }

    /// One control cycle at `now_ns`: reads the objects, steps the device
    /// control, runs the mode and the cascade, writes the actual values.
    /// `new_setpoint`: a new cyclic set-point (RxPDO) arrived since the last
    /// cycle; without one the interpolators extrapolate (C-116).
    pub fn cycle(
        &mut self,
        od: &mut DriveObjects,
        io: &AxisIo,
        now_ns: Nanos,
        new_setpoint: bool,
    ) -> AxisReport {
        let mut cache = core::mem::take(&mut self.cache);
        let report = self.cycle_cached(&mut cache, od, io, now_ns, new_setpoint);
        self.cache = cache;
        report
    }

    /// [`cycle`](Self::cycle) with the snapshot and slots in `cache`, kept
    /// by the caller (one cache per axis, never shared): read in place, no
    /// copy per cycle.
    ///
    /// The steps, in order:
    /// 1. **snapshot**: the cyclic set-points again while the configuration
    ///    generation stands, else the whole snapshot (`snapshot.rs`), in
    ///    increments;
    /// 2. **configure** when the generation, the cycle or the mode class
    ///    changed (`configure.rs`);
    /// 3. **inputs**: the switch signals from their sources ([`AxisIo`] or
    ///    I210);
    /// 4. **feedback**: encoder → user position, velocity filter
    ///    (`feedback.rs`); the encoder and the supply watched
    ///    (`monitor.rs`: events 37, 46);
    /// 5. **limits**: limit switches, software limits, the direction lock
    ///    of this cycle and a limit's stop;
    /// 6. **device control**: the CiA 402 state machine step, a fault
    ///    change on T13/T15 (603Fh, error register);
    /// 7. **touch probe** (`feedback.rs`);
    /// 8. **motion**: the active mode's generator gives the demand
    ///    (`modes.rs`);
    /// 9. **control**: the cascade turns the demand into a torque and the
    ///    mode's status bits;
    /// 10. **write-back**: statusword and actual values, A67, E47/E49,
    ///     60FDh (`write_back.rs`); 6077h/6078h from the current loop's
    ///     measurement ([`AxisIo::current`], `current.rs`), else the demand.
    pub fn cycle_cached(
        &mut self,
        cache: &mut AxisCache,
        od: &mut DriveObjects,
        io: &AxisIo,
        now_ns: Nanos,
        new_setpoint: bool,
    ) -> AxisReport {
        let generation = od.axis_config_generation(usize::from(self.window.axis));
        let cached: &CachedSnapshot = match &mut cache.snapshot {
            Some(cached) if cached.generation == generation => {
                cached.snapshot.refresh_setpoints(od, self.window.axis);
                cached
            }
            stale => stale.insert(self.read_snapshot(od, generation)),
        };
        let (raw, dt_ns) = (&cached.snapshot, cached.dt_ns);
        // converted (a copy) only when user units are not increments
        let converted;
        let o = if cached.in_increments {
            raw
        } else {
            converted = raw.to_increments(&self.scaling);
            &converted
        };
        let key = self.config_key(generation, dt_ns);
        if self.configured != Some(key) {
            // the slots only configure uses, resolved on its first run
            let slots = cache::slots_of(&mut cache.slots, od, self.window);
            self.configure(od, slots, o, dt_ns);
            self.configured = Some(key);
        }
        // the switches from the inputs (I101/I102 ≠ 2, I103 = 1): the
        // hardware inputs as they are, without a copy
        let io_sourced;
        let io = if matches!(o.switch_source, [p, n, 1] if p != 2 && n != 2) {
            io
        } else {
            io_sourced = sourced(io, o);
            &io_sourced
        };

        let mut actual = self.feedback(io, o.polarity, dt_ns, now_ns);
        if self.follow_actual {
            self.follow_actual = false;
            self.follow(actual);
        }
        self.monitor(io, now_ns);
        let i199 = is_standstill(self.velocity, self.params.velocity_window_inc_per_s);

        // limits first: the lock of this cycle filters the set-points
        let homing_active = matches!(self.running, Running::Homing);
        let status = self.limits.update(&LimitInput {
            actual_position_inc: actual,
            position_setpoint_inc: self.sp_pos,
            positive_switch_signal: io.limit_positive,
            negative_switch_signal: io.limit_negative,
            referenced: self.is_referenced(),
            referencing: homing_active && self.homing.is_referencing(),
        });
        self.lock = status.lock;
        self.denial = status.denial;
        if let Some(ev) = status.event {
            self.raise(ev);
        }
        if let Some(stop) = status.stop {
            if stop.ramp == StopRamp::QuickStop {
                self.local_quick_stop(o);
            }
        }

        // a stop counts as done once the ramp has ended and the axis has
        // stood still for the settle time (no coasting out of an overshoot)
        let settled = i199 && {
            let since = *self.standstill_since.get_or_insert(now_ns);
            now_ns.since(since) >= self.params.stop_settle_ns
        };
        if !i199 {
            self.standstill_since = None;
        }
        let stop_done = match self.stop {
            Some(Stop::Profile) => self.profile.is_standstill() && settled,
            Some(Stop::Brake) => settled,
            None => true,
        };
        let inputs = Inputs {
            controlword: o.controlword | self.record_brake_trigger(),
            mode_request: o.mode,
            initialised: true,
            additional_enable: io.additional_enable,
            supply_ok: io.supply_ok,
            sto_active: io.sto_active,
            standstill: i199 && stop_done,
            // a cause that is still there holds the fault (T15, C-017):
            // both limit switches hit (event 53 cause 7, a wiring fault no
            // acknowledge can end)
            // a faulty encoder (event 37) as well
            fault_present: self.limits.both_switches_hit() || !io.encoder_ok,
            motion_command: self.motion_command(o),
            brake_override: self.brake_override(),
            target_reached: false,
            mode_bit12: false,
            mode_bit13: false,
            warning: self.i2t.limiting() || self.stage_warning,
            remote: true,
            internal_limit: false,
            manufacturer_bits: 0,
        };
        let out = self.dc.step(&inputs, now_ns);
        let fault = self.on_transition(out.transition, od);

        self.touch_probe(o, io, actual, now_ns);

        let demand = self.motion(od, o, &out, io, &mut actual, i199, now_ns, dt_ns, new_setpoint);
        let (torque, bits, fe) = self.control(demand, actual, now_ns, dt_ns);

        self.prev_cw = o.controlword;
        let sign = if o.polarity & 0x80 != 0 { -1.0 } else { 1.0 };
        // 6077h/6078h: the current loop's measurement (motor coordinates,
        // turned like the command), or the demand where nothing is measured
        let measured = io.current.map(|m| CurrentActual {
            torque_nm: sign * m.torque_nm,
            current_a: sign * m.current_a,
            ..m
        });
        self.write_back(od, &out, (bits, actual, torque, fe), measured);
        self.user_statusword(od, o);
        self.switch_on_disabled_causes(od, &out, io, o.controlword);
        self.digital_inputs(od, io);

        AxisReport {
            command: AxisCommand {
                torque_nm: sign * torque,
                power_stage: out.power_stage,
                brake_release: self.brake_output(out.brake_release),
                injection: None,
            },
            transition: out.transition,
            fault,
        }
    }
}
