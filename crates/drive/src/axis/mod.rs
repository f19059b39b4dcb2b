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
//! Following error (6065h/6066h with [`AxisParams::following_error_fault`]),
//! limit switches (event 53), the extrapolation overrun of the interpolators
//! (event 78 cause 3) and an excessive set-value jump of the master (event 78
//! cause 4, C-148) raise a fault in the device control; on T13 the axis
//! returns the EMCY ([`for_event`]) and sets 603Fh and its error
//! register, on T15 it returns [`fault_cleared`].

mod snapshot;
#[cfg(test)]
mod tests;

use crate::dictionary::DriveObjects;
use crate::emcy::{device_fault, fault_cleared, fault_code_for_event, for_event};
use cia402::{
    Decel, DeviceControl, FaultEvent, FaultReaction, Inputs, Mode, Options, Outputs, QuickStopOption, Ramp,
    State, Transition, CW_HALT, CW_MODE_BIT4, CW_MODE_BIT5, CW_MODE_BIT6, SW_INTERNAL_LIMIT, SW_MODE_BIT12,
    SW_MODE_BIT13, SW_TARGET_REACHED,
};
use ecat::emcy::{register, Emcy};
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
use snapshot::{CyclicSlots, Snapshot, Window};

/// The permitted direction of an endless axis (I04), for [`AxisParams::limits`].
pub use motion::limits::PermittedDirection;

/// Increments per revolution as `f32`.
const REV: f32 = INCREMENTS_PER_REVOLUTION as f32;
/// rpm → inc/s.
const RPM_TO_INC_PER_S: f32 = REV / 60.0;

/// An encoder zero (index) pulse latched by the hardware in this cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IndexLatch {
    /// Encoder position at the pulse, increments (motor coordinates, like
    /// [`AxisIo::position_inc`]).
    pub position_inc: i32,
    /// Time of the pulse, ns (same clock as `now_ns`).
    pub time_ns: u64,
}

/// An edge of a touch-probe input seen in this cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ProbeEdge {
    /// The physical input: 1 or 2 (60D0h:01/:02 select which probe it feeds).
    pub input: u8,
    /// `true` = rising (0 → 1), `false` = falling.
    pub rising: bool,
    /// Time stamp of the edge, ns (same clock as `now_ns`).
    pub time_ns: u64,
    /// Encoder position latched by the hardware at the edge, increments
    /// (motor coordinates); `None`: interpolated between the last and this
    /// cycle's positions at `time_ns`.
    pub position_inc: Option<i32>,
}

/// A limit or reference switch input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SwitchId {
    /// Positive hardware limit switch (I441).
    PositiveLimit,
    /// Negative hardware limit switch (I442).
    NegativeLimit,
    /// Reference (home) switch.
    Reference,
}

/// A change of a limit or reference switch latched by the hardware in this
/// cycle (time-stamped input, spec §12): homing takes its reference from the
/// latched position instead of the position of the cycle that sees the new
/// level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SwitchEdge {
    /// Which switch changed.
    pub switch: SwitchId,
    /// Encoder position at the change, increments (motor coordinates).
    pub position_inc: i32,
}

/// What the hardware (board driver or simulated motor) reports for one axis
/// at the start of a control cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxisIo {
    /// Encoder position, increments (2^20 per revolution, wrapping), motor
    /// coordinates.
    pub position_inc: i32,
    /// Encoder zero pulse seen since the last cycle.
    pub index: Option<IndexLatch>,
    /// Positive hardware limit switch hit (I441 after the wiring's polarity:
    /// a broken NC wire reads as hit). Evaluated only with
    /// [`LimitConfig::positive_switch`] (I101) set.
    pub limit_positive: bool,
    /// Negative hardware limit switch hit (I442), see `limit_positive`.
    pub limit_negative: bool,
    /// Reference (home) switch active (I103).
    pub reference: bool,
    /// Touch-probe input edges since the last cycle (up to 4).
    pub probe_edges: [Option<ProbeEdge>; 4],
    /// Limit/reference switch changes latched since the last cycle (up to
    /// 4; none: homing uses the position of the cycle that sees the level).
    pub switch_edges: [Option<SwitchEdge>; 4],
    /// Additional enable A60 active.
    pub additional_enable: bool,
    /// Supply and DC link present.
    pub supply_ok: bool,
    /// Safe torque off active.
    pub sto_active: bool,
}

impl AxisIo {
    /// A ready axis at `position_inc`: enable A60 on, supply present, STO
    /// off, no switches or edges (what the simulator passes by default).
    pub const fn ready(position_inc: i32) -> Self {
        Self {
            position_inc,
            index: None,
            limit_positive: false,
            limit_negative: false,
            reference: false,
            probe_edges: [None; 4],
            switch_edges: [None; 4],
            additional_enable: true,
            supply_ok: true,
            sto_active: false,
        }
    }
}

/// What the axis commands to the power stage for the next cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisCommand {
    /// Torque set-point for the current controller, N·m (motor coordinates).
    pub torque_nm: f32,
    /// Power stage on.
    pub power_stage: bool,
    /// Release (open) the holding brake.
    pub brake_release: bool,
}

impl AxisCommand {
    /// Power stage off, brake engaged, no torque.
    pub const OFF: AxisCommand = AxisCommand {
        torque_nm: 0.0,
        power_stage: false,
        brake_release: false,
    };
}

/// One cycle's result of [`Axis::cycle`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisReport {
    /// The command for the power stage.
    pub command: AxisCommand,
    /// The device-control transition taken, if any.
    pub transition: Option<Transition>,
    /// An EMCY to queue: the fault on T13, "fault cleared" on T15.
    pub emcy: Option<Emcy>,
}

/// Parameters of the axis that the dictionary does not (yet) declare
/// (manufacturer groups B–I), with their defaults. Change them through
/// [`Axis::params_mut`]; they take effect in the next cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisParams {
    /// 6076h rated torque, N·m (motor data); 0.1 % torque objects refer to it.
    pub rated_torque_nm: f32,
    /// Cascade gains and limits. The torque limits are replaced by 6072h, the
    /// speed feedforward weight is applied by the interpolator (I25 below);
    /// the inertia (motor data) turns the generators' acceleration into
    /// torque feedforward.
    pub cascade: CascadeConfig,
    /// I25 speed feedforward of ip/csp, % (0 … 100).
    pub feedforward_percent: f32,
    /// I425 speed feedforward – interpolation (0, 1, 3, 4, 5).
    pub interpolation_i425: u8,
    /// I423 maximum extrapolation period, ns (C-117).
    pub max_extrapolation_ns: u64,
    /// C40 velocity window, inc/s (standstill I199, pv window).
    pub velocity_window_inc_per_s: f32,
    /// 606Eh velocity window time, ns.
    pub velocity_window_time_ns: u64,
    /// I22 position (target) window, inc.
    pub position_window_inc: u32,
    /// I87 time in the position window, ns.
    pub position_window_time_ns: u64,
    /// Following error (6065h/6066h) is a fault (event 54), not only
    /// statusword bit 13.
    pub following_error_fault: bool,
    /// Limit switches and axis type (I101/I102, I00, I04, software-limit
    /// reaction). The software limits come from 607Dh, the window from I22;
    /// the switch polarity is the board's (see [`AxisIo::limit_positive`]).
    pub limits: LimitConfig,
    /// C-050: absolute pp moves need a referenced axis.
    pub absolute_needs_reference: bool,
    /// C-148 set-value monitoring: a cyclic position set-point further from
    /// the previous one than twice 607Fh over the time between them trips
    /// event 78 cause 4 "excessive set value jump".
    pub set_value_monitoring: bool,
    /// I12 jog velocity, inc/s.
    pub jog_velocity: f32,
    /// I13 jog acceleration, inc/s².
    pub jog_acceleration: f32,
    /// I45 jog deceleration, inc/s².
    pub jog_deceleration: f32,
    /// I18 jog jerk, inc/s³ (`f32::INFINITY` = none).
    pub jog_jerk: f32,
    /// I26 = 1: jog under position control (stops before a software limit).
    pub jog_position_control: bool,
    /// I44 referencing jerk, inc/s³.
    pub homing_jerk: f32,
    /// I43: after referencing, position on 607Ch.
    pub homing_move_to_home: bool,
    /// I53 index search offset, inc.
    pub homing_index_offset: u32,
    /// I28 torque limit while homing, 0.1 % of the rated torque (also the
    /// "torque at the limit" threshold of the torque methods; 6072h caps it).
    pub homing_torque_limit_per_mille: u16,
    /// I29 time at the torque limit for the torque methods, ns.
    pub homing_torque_hold_ns: u64,
    /// I30 = 2: the limit switch serves as the reference switch.
    pub homing_limit_as_reference: bool,
    /// A44 = 1: losing A60 in Operation enabled gives a quick stop.
    pub quick_stop_on_enable_loss: bool,
    /// How long the axis must stand still (I199) after a stop ramp before
    /// the stop counts as finished (T12, T14, T5/T8 with ramp), ns.
    pub stop_settle_ns: u64,
}

impl Default for AxisParams {
    /// Rated torque 1.3 N·m, the cascade defaults with an inertia of 1e-4
    /// kg·m² (the simulated servo), I25 = 100 %, I425 = 0,
    /// I423 = 10 ms, C40 = 0.1 rev/s, I22 = 1/360 rev, following error as
    /// bit 13 only, no limit switches, jog 1 rev/s with 10 rev/s², I26 = 1,
    /// no jerk limits, stops settle 10 ms.
    fn default() -> Self {
        Self {
            rated_torque_nm: 1.3,
            cascade: CascadeConfig {
                inertia_kg_m2: 1.0e-4,
                ..CascadeConfig::DEFAULT
            },
            feedforward_percent: 100.0,
            interpolation_i425: 0,
            max_extrapolation_ns: 10_000_000,
            velocity_window_inc_per_s: 0.1 * REV,
            velocity_window_time_ns: 0,
            position_window_inc: INCREMENTS_PER_REVOLUTION / 360,
            position_window_time_ns: 0,
            following_error_fault: false,
            limits: LimitConfig::default(),
            absolute_needs_reference: true,
            set_value_monitoring: true,
            jog_velocity: REV,
            jog_acceleration: 10.0 * REV,
            jog_deceleration: 10.0 * REV,
            jog_jerk: f32::INFINITY,
            jog_position_control: true,
            homing_jerk: f32::INFINITY,
            homing_move_to_home: false,
            homing_index_offset: 0,
            homing_torque_limit_per_mille: 1000,
            homing_torque_hold_ns: 100_000_000,
            homing_limit_as_reference: false,
            quick_stop_on_enable_loss: false,
            stop_settle_ns: 10_000_000,
        }
    }
}

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
    interp_key: Option<(CycleRatio, u8, u32, u64)>,
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
    /// The touch-probe values (60BAh – 60BDh, increments) last written to
    /// the objects; they are converted and written again only when one
    /// changed or the configuration did (`None`).
    probe_shown: Option<[i32; 4]>,
    /// Filtered actual velocity, inc/s (user coordinates).
    velocity: f32,
    /// Last cycle's actual position sample (user coordinates).
    last_sample: Option<PositionSample>,
    /// Set-point state: position (inc), velocity (inc/s).
    sp_pos: i32,
    sp_vel: f32,
    /// The mode the motion core was set up for (None: not running).
    running: Option<Mode>,
    /// A device-control stop in progress.
    stop: Option<Stop>,
    /// A halt (bit 8, or a limit quick stop in jog) in progress.
    halting: bool,
    /// Previous controlword (edges of bit 4).
    prev_cw: u16,
    /// pp set-point acknowledge (bit 12).
    pp_ack: bool,
    /// Last commanded profile velocity of pv/vl/jog, inc/s.
    commanded_velocity: Option<f32>,
    /// pt torque ramp output, N·m.
    pt_torque: f32,
    /// Last cascade output.
    last_out: Option<CascadeOutput>,
    /// Last cascade entry.
    last_entry: Option<ControlEntry>,
    /// Since when I199 (standstill) holds, ns.
    standstill_since: Option<u64>,
    /// Direction lock of this cycle.
    lock: DirectionLock,
    /// Event behind the fault being raised / handled.
    event: Option<Event>,
    /// 603Fh and the error register while in a fault.
    error_code: u16,
    error_register: u8,
    /// vl demand (6043h), inc/s.
    vl_demand: f32,
    /// I90 cause of this cycle's direction lock (E80).
    denial: Option<DenialCause>,
    /// I46 = 5 with I02 = 0: the encoder position is the reference (C-112).
    retained: bool,
    /// The pp target being approached (override re-plans, C-030).
    pp_target: Option<i32>,
    /// The A340 override the pp move was planned with, %.
    pp_override: u16,
    /// Last cyclic position set-point of the master (C-148) and the time
    /// since it arrived, ns.
    last_master_sp: Option<i32>,
    sp_age_ns: u64,
    /// 6091h/6092h of this cycle (C-109).
    scaling: AxisScaling,
    /// 10^A310 with A213 = 0, else 1 (C-142).
    velocity_decimals: f32,
    /// Endless axis (I00 = 1) with 607Bh:02 > 0, user units (C-111).
    modulo: Option<ModuloAxis>,
    /// The last cyclic set-point of an endless axis as sent (user units).
    last_master_user: Option<i64>,
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
            configured: None,
            probe_shown: None,
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
            running: None,
            stop: None,
            halting: false,
            prev_cw: 0,
            pp_ack: false,
            commanded_velocity: None,
            pt_torque: 0.0,
            last_out: None,
            last_entry: None,
            standstill_since: None,
            lock: DirectionLock::default(),
            event: None,
            error_code: 0,
            error_register: 0,
            vl_demand: 0.0,
            denial: None,
            retained: false,
            pp_target: None,
            pp_override: 100,
            last_master_sp: None,
            sp_age_ns: 0,
            scaling: AxisScaling::INCREMENTAL,
            velocity_decimals: 1.0,
            modulo: None,
            last_master_user: None,
        }
    }

    /// 0 = axis A, 1 = axis B.
    pub fn index(&self) -> u8 {
        self.window.axis
    }

    /// This axis' index of CiA 402 object `index` (given in axis-A numbering).
    pub fn cia402_index(&self, index: u16) -> u16 {
        self.window.cia402(index)
    }

    /// This axis' index of per-axis manufacturer parameter `index` (axis-A
    /// numbering).
    pub fn manufacturer_index(&self, index: u16) -> u16 {
        self.window.manufacturer(index)
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
        now_ns: u64,
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
    pub fn cycle_cached(
        &mut self,
        cache: &mut AxisCache,
        od: &mut DriveObjects,
        io: &AxisIo,
        now_ns: u64,
        new_setpoint: bool,
    ) -> AxisReport {
        let generation = od.config_generation();
        let window = self.window;
        let slots: &CyclicSlots = cache
            .slots
            .get_or_insert_with(|| CyclicSlots::resolve(od, window));
        let cached: &CachedSnapshot = match &mut cache.snapshot {
            Some(cached) if cached.generation == generation => {
                cached.snapshot.refresh_setpoints(od, slots);
                cached
            }
            stale => {
                let fresh = Snapshot::read(od, window);
                // C-109: user units at the objects, increments inside
                self.scaling = fresh.scaling();
                self.velocity_decimals = fresh.decimal_factors().0 as f32;
                stale.insert(CachedSnapshot {
                    generation,
                    in_increments: fresh.in_increments(&self.scaling),
                    dt_ns: application_cycle_ns(u32::from(fresh.control_cycle_us).saturating_mul(1000))
                        .unwrap_or(1_000_000),
                    snapshot: fresh,
                })
            }
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
        let class = match self.running {
            Some(Mode::Homing) => 1,
            Some(Mode::Jog) => 2,
            _ => 0,
        };
        if self.configured != Some((generation, dt_ns, class)) {
            self.configure(od, slots, o, dt_ns);
            self.configured = Some((generation, dt_ns, class));
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
        let i199 = is_standstill(self.velocity, self.params.velocity_window_inc_per_s);

        // limits first: the lock of this cycle filters the set-points
        let homing_active = self.running == Some(Mode::Homing);
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
            now_ns.saturating_sub(since) >= self.params.stop_settle_ns
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
            controlword: o.controlword,
            mode_request: o.mode,
            initialised: true,
            additional_enable: io.additional_enable,
            supply_ok: io.supply_ok,
            sto_active: io.sto_active,
            standstill: i199 && stop_done,
            fault_present: false,
            motion_command: self.motion_command(o),
            brake_override: false,
            target_reached: false,
            mode_bit12: false,
            mode_bit13: false,
            warning: false,
            remote: true,
            internal_limit: false,
            manufacturer_bits: 0,
        };
        let out = self.dc.step(&inputs, now_ns);
        let emcy = self.on_transition(out.transition, od);

        self.touch_probe(o, io, actual, now_ns);

        let demand = self.motion(o, &out, io, &mut actual, i199, now_ns, dt_ns, new_setpoint);
        let (torque, bits, fe) = self.control(demand, actual, now_ns, dt_ns);

        self.prev_cw = o.controlword;
        self.write_back(od, slots, &out, (bits, actual, torque, fe));
        self.user_statusword(od, slots, o);
        self.switch_on_disabled_causes(od, slots, &out, io, o.controlword);
        self.digital_inputs(od, slots, io);

        let sign = if o.polarity & 0x80 != 0 { -1.0 } else { 1.0 };
        AxisReport {
            command: AxisCommand {
                torque_nm: sign * torque,
                power_stage: out.power_stage,
                brake_release: out.brake_release,
            },
            transition: out.transition,
            emcy,
        }
    }

    /// Applies the configuration objects and parameters.
    fn configure(&mut self, od: &mut DriveObjects, slots: &CyclicSlots, o: &Snapshot, dt_ns: u32) {
        let p = self.params;
        self.modulo = if p.limits.endless_axis && o.modulo_length > 0 {
            ModuloAxis::new(i64::from(o.modulo_length)).ok()
        } else {
            None
        };
        // 6076h from the motor data, and the probe values in the (new) units
        od.write_typed(
            slots.rated_current,
            round_i32(p.rated_torque_nm * 1000.0).max(0) as u32,
        );
        self.probe_shown = None;
        let opts = self.dc.options_mut();
        if let Ok(q) = QuickStopOption::try_from(o.quick_stop_option) {
            opts.quick_stop = q;
        }
        if let Ok(f) = FaultReaction::try_from(o.fault_reaction_option) {
            opts.fault_reaction = f;
        }
        opts.quick_stop_on_enable_loss = p.quick_stop_on_enable_loss;

        // cycle ratio (C-114): 60C2h over A150; 60C2h is copied into A291
        let master_ns = interpolation_period_ns(o.period_value, o.period_index).unwrap_or(dt_ns);
        if self.window.axis == 0 {
            od.write_typed(slots.a291, master_ns / 1000);
        }
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
        if key != self.interp_key {
            self.interp_key = key;
            self.ratio = ratio;
            self.rebuild_interpolators();
        }

        // cascade: torque limits from 6072h (homing: I28), gains adapted to A150
        let per_mille = if self.running == Some(Mode::Homing) {
            o.max_torque.min(p.homing_torque_limit_per_mille)
        } else {
            o.max_torque
        };
        let max_nm = p.rated_torque_nm * f32::from(per_mille) * 0.001;
        let cfg = CascadeConfig {
            torque_limit_positive_nm: max_nm,
            torque_limit_negative_nm: max_nm,
            velocity_feedforward_percent: 100.0,
            ..scaled_gains(&p.cascade, dt_ns)
        };
        if let Some(c) = self.cascade.as_mut() {
            if *c.config() != cfg {
                let _ = c.set_config(cfg);
            }
        }

        self.following.set_config(FollowingErrorConfig {
            window_inc: o.following_error_window,
            timeout_ns: ms_to_ns(o.following_error_timeout_ms),
            fault: p.following_error_fault,
        });
        self.in_position.set_config(PositionWindowConfig {
            window_inc: p.position_window_inc,
            time_ns: p.position_window_time_ns,
        });
        self.velocity_window.set_config(VelocityWindowConfig {
            window_inc_per_s: p.velocity_window_inc_per_s,
            time_ns: p.velocity_window_time_ns,
        });
        // C-091: jog under velocity control (I26 = 0) quick-stops at a
        // software limit instead of faulting
        self.retained = o.i46 == 5 && o.i02 == 0;
        let soft_limit_reaction = if self.running == Some(Mode::Jog) && !p.jog_position_control {
            SoftLimitReaction::QuickStop
        } else {
            p.limits.soft_limit_reaction
        };
        self.limits.set_config(LimitConfig {
            software_min_inc: o.software_min,
            software_max_inc: o.software_max,
            window_inc: p.position_window_inc,
            switch_polarity: SwitchPolarity::HighActive,
            soft_limit_reaction,
            // I101/I102 (C-104) switch the evaluation on as well
            positive_switch: p.limits.positive_switch || o.switch_source[0] != 0,
            negative_switch: p.limits.negative_switch || o.switch_source[1] != 0,
            ..p.limits
        });
    }

    fn rebuild_interpolators(&mut self) {
        let p = self.params;
        let (interp, vinterp) = match (self.ratio, from_i425(p.interpolation_i425)) {
            (Some(ratio), Ok((order, feedforward))) => (
                FineInterpolator::new(InterpolatorConfig {
                    ratio,
                    order,
                    feedforward,
                    velocity_feedforward_percent: p.feedforward_percent,
                    max_extrapolation_ns: p.max_extrapolation_ns,
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

    /// Reads the encoder: user position and the filtered velocity.
    fn feedback(&mut self, io: &AxisIo, polarity: u8, dt_ns: u32, now_ns: u64) -> i32 {
        let inverted = polarity & 0x80 != 0;
        let raw = io.position_inc;
        let dt_s = dt_ns as f32 * 1e-9;
        let v_raw = match self.last_raw {
            Some(last) if dt_ns > 0 => raw.wrapping_sub(last) as f32 / dt_s,
            _ => 0.0,
        };
        let v_user = if inverted { -v_raw } else { v_raw };
        let tau = self.params.cascade.velocity_filter_time_ns as f32;
        let alpha = dt_ns as f32 / (tau + dt_ns as f32);
        if self.last_raw.is_some() && alpha.is_finite() {
            self.velocity += alpha * (v_user - self.velocity);
        }
        if !self.velocity.is_finite() {
            self.velocity = 0.0;
        }
        self.last_raw = Some(raw);
        let actual = self.to_user(raw, polarity);
        if self.last_sample.is_none() {
            self.last_sample = Some(PositionSample {
                time_ns: now_ns,
                position_inc: actual,
            });
            // power-on: the set-point state starts at the actual position
            self.disengage(actual);
            self.limits.restart_computing_limit(actual);
        }
        actual
    }

    /// Encoder position (motor coordinates) → user position.
    fn to_user(&self, raw: i32, polarity: u8) -> i32 {
        let p = if polarity & 0x80 != 0 {
            raw.wrapping_neg()
        } else {
            raw
        };
        p.wrapping_add(self.offset)
    }

    /// Moves every stored position of the user coordinates by `shift`.
    fn shift_coordinates(&mut self, shift: i32) {
        self.offset = self.offset.wrapping_add(shift);
        self.sp_pos = self.sp_pos.wrapping_add(shift);
        if let Some(s) = self.last_sample.as_mut() {
            s.position_inc = s.position_inc.wrapping_add(shift);
        }
        if let Some(i) = self.interp.as_mut() {
            i.start(self.sp_pos);
        }
        self.limits.reference_changed(self.sp_pos);
        self.profile.reset(self.sp_pos);
    }

    /// Whether the mode has an active motion command (brake release, C-021).
    fn motion_command(&self, o: &Snapshot) -> bool {
        match self.dc.mode() {
            Mode::CyclicPosition | Mode::CyclicVelocity | Mode::CyclicTorque => true,
            Mode::ProfileVelocity => o.target_velocity != 0,
            Mode::ProfileTorque => o.target_torque != 0,
            Mode::Velocity => o.vl_target != 0,
            _ => false,
        }
    }

    fn raise(&mut self, ev: Event) {
        if self.dc.state().is_fault() || self.event.is_some() {
            return;
        }
        let code = fault_code_for_event(ev.number.min(255) as u8).map_or(0x1000, |(c, _)| c);
        self.event = Some(ev);
        self.dc.raise_fault(FaultEvent { code, reaction: None });
    }

    /// EMCY, 603Fh and the error register on T13 / T15.
    fn on_transition(&mut self, t: Option<Transition>, od: &mut DriveObjects) -> Option<Emcy> {
        let t = t?;
        let axis = self.window.axis;
        match t.number {
            13 => {
                let emcy = match self.event {
                    Some(ev) => for_event(ev.number.min(255) as u8, ev.cause, axis),
                    None => device_fault(
                        self.dc.fault().map_or(0x1000, |f| f.code),
                        register::GENERIC,
                        0,
                        0,
                        axis,
                    ),
                };
                self.error_code = emcy.code;
                self.error_register = emcy.register | register::GENERIC;
                self.window.put(od, 0x603F, 0, i64::from(emcy.code));
                Some(emcy)
            }
            15 => {
                self.event = None;
                self.error_code = 0;
                self.error_register = 0;
                self.window.put(od, 0x603F, 0, 0);
                Some(fault_cleared(axis))
            }
            _ => None,
        }
    }

    /// Touch probe (C-121 – C-129): 60B8h, the input edges and the index pulse.
    fn touch_probe(&mut self, o: &Snapshot, io: &AxisIo, actual: i32, now_ns: u64) {
        self.probe.set_function(o.probe_function);
        let current = PositionSample {
            time_ns: now_ns,
            position_inc: actual,
        };
        let previous = self.last_sample.replace(current).unwrap_or(current);
        if !self.probe.is_enabled() {
            return; // both probes off: no edge latches anything (C-126)
        }
        let [src1, src2] = o.probe_source;
        for edge in io.probe_edges.iter().flatten() {
            let position = match edge.position_inc {
                Some(p) => self.to_user(p, o.polarity),
                None => interpolate_position(previous, current, edge.time_ns),
            };
            let e = if edge.rising { Edge::Rising } else { Edge::Falling };
            let input = i16::from(edge.input);
            if input == src1 {
                self.probe.latch(TriggerSignal::Input1, e, position);
            }
            if input == src2 {
                self.probe.latch(TriggerSignal::Input2, e, position);
            }
        }
        if let Some(index) = io.index {
            let p = self.to_user(index.position_inc, o.polarity);
            self.probe.latch(TriggerSignal::IndexPulse, Edge::Rising, p);
        }
    }

    /// Drive function off: the set-point state follows the actual position.
    fn disengage(&mut self, actual: i32) {
        self.sp_pos = actual;
        self.sp_vel = 0.0;
        self.running = None;
        self.stop = None;
        self.halting = false;
        self.pp_ack = false;
        self.commanded_velocity = None;
        self.pt_torque = 0.0;
        self.vl_demand = 0.0;
        self.profile.reset(actual);
        self.following.reset();
        if let Some(c) = self.cascade.as_mut() {
            c.reset(actual);
        }
    }

    /// The limits asked for a quick stop without a fault (jog, I26 = 0).
    fn local_quick_stop(&mut self, o: &Snapshot) {
        if self.running.is_some() && self.stop.is_none() {
            let _ = self.profile.stop(o.quick_stop_deceleration as f32, f32::INFINITY);
            self.commanded_velocity = Some(0.0);
        }
    }

    /// The pp limits: 6081h × A340 (C-030), capped by 607Fh.
    fn profile_limits(&self, o: &Snapshot) -> ProfileLimits {
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
    fn motion(
        &mut self,
        o: &Snapshot,
        out: &Outputs,
        io: &AxisIo,
        actual: &mut i32,
        i199: bool,
        now_ns: u64,
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
        if self.running != Some(mode) {
            self.activate(mode, o, *actual);
        }
        let halt = matches!(out.ramp, Ramp::Halt(_));
        let d = match mode {
            Mode::CyclicPosition | Mode::InterpolatedPosition => self.cyclic_position(o, mode, new_setpoint),
            Mode::CyclicVelocity => self.cyclic_velocity(o, new_setpoint),
            Mode::CyclicTorque => Demand {
                entry: ControlEntry::Torque,
                torque: self
                    .lock
                    .filter_torque(self.per_mille(i32::from(o.target_torque) + i32::from(o.torque_offset))),
                bits: SW_MODE_BIT12,
                ..Demand::hold(*actual)
            },
            Mode::ProfilePosition => self.profile_position(o, halt, *actual, now_ns, dt_ns),
            Mode::ProfileVelocity => self.profile_velocity(o, halt, now_ns, dt_ns),
            Mode::ProfileTorque => self.profile_torque(o, dt_ns, *actual),
            Mode::Velocity => self.velocity_mode(o, dt_ns),
            Mode::Homing => self.run_homing(o, io, actual, i199, dt_ns),
            Mode::Jog => self.jog(o, dt_ns),
            Mode::NoMode => Demand::hold(self.sp_pos),
        };
        Some(d)
    }

    /// Sets the generator of `mode` up from the present set-point state
    /// (bumpless mode change and enable).
    fn activate(&mut self, mode: Mode, o: &Snapshot, actual: i32) {
        self.running = Some(mode);
        self.halting = false;
        self.pp_ack = false;
        self.commanded_velocity = None;
        self.following.reset();
        self.in_position.reset();
        self.velocity_window.reset();
        // a bit 4 already set is no edge (pp, homing)
        self.prev_cw = o.controlword;
        self.pp_target = None;
        self.last_master_sp = None;
        self.last_master_user = None;
        self.sp_age_ns = 0;
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
            Mode::ProfileTorque => {
                self.pt_torque = self.last_out.map_or(0.0, |c| c.torque_nm);
            }
            Mode::Homing => self.homing.activate(actual),
            Mode::ProfilePosition => {
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

    fn run_stop(
        &mut self,
        o: &Snapshot,
        d: Decel,
        from_actual: bool,
        actual: i32,
        i199: bool,
        dt_ns: u32,
    ) -> Demand {
        if self.stop.is_none() {
            let vl = self.running == Some(Mode::Velocity);
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
            self.running = None;
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

    fn cyclic_position(&mut self, o: &Snapshot, mode: Mode, new_setpoint: bool) -> Demand {
        let ip = mode == Mode::InterpolatedPosition;
        let enabled = !ip || o.controlword & CW_MODE_BIT4 != 0;
        let torque = self.per_mille(i32::from(o.torque_offset));
        if !enabled {
            if let Some(interp) = self.interp.as_mut() {
                interp.start(self.sp_pos);
            }
            self.last_master_sp = None;
            self.last_master_user = None;
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
                let (base, base_user) = match (self.last_master_sp, self.last_master_user) {
                    (Some(b), Some(u)) => (b, u),
                    _ => (self.sp_pos, self.user_position(self.sp_pos)),
                };
                self.last_master_user = Some(m.wrap(sent));
                base.wrapping_add(self.increments(m.distance(base_user, sent, ModuloDirection::Shortest)))
            }
            Some(_) => self.last_master_sp.unwrap_or(self.sp_pos),
            None if ip => o.ip_setpoint,
            None => o.target_position,
        };
        // C-148: set-value monitoring of the master's steps
        let master_ns = self.ratio.map_or(0, |r| u64::from(r.master_ns()));
        self.sp_age_ns = self
            .sp_age_ns
            .saturating_add(u64::from(self.ratio.map_or(0, |r| r.control_ns())));
        if new_setpoint {
            let from = self.last_master_sp.unwrap_or(self.sp_pos);
            let step = target.wrapping_sub(from).unsigned_abs() as f32;
            let elapsed_ns = self.sp_age_ns.max(master_ns);
            let elapsed_s = motion::float::from_u64(elapsed_ns) * 1e-9;
            let allowed =
                2.0 * o.max_profile_velocity as f32 * elapsed_s + self.params.position_window_inc as f32;
            self.last_master_sp = Some(target);
            self.sp_age_ns = 0;
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

    fn cyclic_velocity(&mut self, o: &Snapshot, new_setpoint: bool) -> Demand {
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

    fn profile_position(&mut self, o: &Snapshot, halt: bool, actual: i32, now_ns: u64, dt_ns: u32) -> Demand {
        let cw = o.controlword;
        let bit4 = cw & CW_MODE_BIT4 != 0;
        let edge = bit4 && self.prev_cw & CW_MODE_BIT4 == 0;
        if halt && !self.halting {
            let _ = self.profile.stop(o.deceleration as f32, jerk(o.jerk));
            self.halting = true;
            self.pp_target = None;
        } else if !halt && self.halting {
            self.halting = false;
        }
        if edge && !halt {
            self.take_pp_target(o, actual);
        }
        if !bit4 {
            self.pp_ack = false;
        }
        // C-030: a changed override re-plans the running move (0 % pauses it)
        if o.override_percent != self.pp_override && !self.halting {
            self.pp_override = o.override_percent;
            if let Some(t) = self.pp_target {
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
        let target = self.pp_target.unwrap_or(self.profile.target());
        if s.done && s.position == target {
            self.pp_target = None;
        }
        let reached = if self.halting {
            s.done
        } else {
            self.in_position.update(target, actual, s.done, now_ns)
        };
        let mut bits = 0;
        if reached {
            bits |= SW_TARGET_REACHED;
        }
        if self.pp_ack {
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
    fn take_pp_target(&mut self, o: &Snapshot, actual: i32) {
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
                self.pp_target.unwrap_or(self.profile.target()).wrapping_add(d),
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
            self.pp_target = Some(resolved);
            self.pp_override = 0;
            self.pp_ack = true;
            self.in_position.reset();
            return;
        }
        if let Ok(true) = self.profile.move_to(target, self.profile_limits(o), mode) {
            self.pp_target = Some(self.profile.target());
            self.pp_override = o.override_percent;
            self.pp_ack = true;
            self.in_position.reset();
        }
    }

    fn profile_velocity(&mut self, o: &Snapshot, halt: bool, now_ns: u64, dt_ns: u32) -> Demand {
        // C-030: 60FFh × A340
        let target = self
            .lock
            .filter_velocity(o.target_velocity as f32 * override_factor(o));
        if halt {
            if !self.halting {
                let _ = self.profile.stop(o.deceleration as f32, jerk(o.jerk));
                self.halting = true;
                self.commanded_velocity = None;
            }
        } else {
            self.halting = false;
            if self.commanded_velocity != Some(target) {
                let limits = ProfileLimits {
                    velocity: o.max_profile_velocity as f32,
                    ..self.profile_limits(o)
                };
                if self.profile.run_velocity(target, limits).is_ok() {
                    self.commanded_velocity = Some(target);
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

    fn profile_torque(&mut self, o: &Snapshot, dt_ns: u32, actual: i32) -> Demand {
        let max = self.per_mille(i32::from(o.max_torque));
        let target = self
            .lock
            .filter_torque(self.per_mille(i32::from(o.target_torque)).max(-max).min(max));
        let slope = self.per_mille(i32::try_from(o.torque_slope).unwrap_or(i32::MAX)) * dt_ns as f32 * 1e-9;
        let diff = target - self.pt_torque;
        self.pt_torque = if o.torque_slope == 0 || diff.abs() <= slope {
            target
        } else {
            self.pt_torque + slope.copysign(diff)
        };
        Demand {
            entry: ControlEntry::Torque,
            torque: self.pt_torque,
            bits: if self.pt_torque == target {
                SW_TARGET_REACHED
            } else {
                0
            },
            ..Demand::hold(actual)
        }
    }

    fn velocity_mode(&mut self, o: &Snapshot, dt_ns: u32) -> Demand {
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
        if (unlocked || !enable) && self.commanded_velocity != Some(target) {
            let limits = ProfileLimits {
                velocity: (max * RPM_TO_INC_PER_S).max(1.0),
                acceleration: ramp_rate(o.vl_acceleration),
                deceleration: ramp_rate(o.vl_deceleration),
                jerk: f32::INFINITY,
            };
            if self.profile.run_velocity(target, limits).is_ok() {
                self.commanded_velocity = Some(target);
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

    fn run_homing(&mut self, o: &Snapshot, io: &AxisIo, actual: &mut i32, i199: bool, dt_ns: u32) -> Demand {
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
            torque_hold_ns: p.homing_torque_hold_ns,
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

    fn jog(&mut self, o: &Snapshot, dt_ns: u32) -> Demand {
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
        let referenced = self.is_referenced();
        let soft = referenced && self.limits.config().software_limits_configured();
        let target = self.lock.filter_velocity(dir * p.jog_velocity);
        if self.commanded_velocity != Some(target) {
            let ok = if target == 0.0 {
                self.profile.stop(p.jog_deceleration, p.jog_jerk).is_ok()
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
                self.commanded_velocity = Some(target);
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
    fn per_mille(&self, v: i32) -> f32 {
        self.params.rated_torque_nm * v as f32 * 0.001
    }

    /// The cascade and the monitors; returns (torque N·m user coordinates,
    /// mode bits incl. bit 11, following error inc).
    fn control(&mut self, demand: Option<Demand>, actual: i32, now_ns: u64, dt_ns: u32) -> (f32, u16, i32) {
        let (Some(d), Some(cascade)) = (demand, self.cascade.as_mut()) else {
            self.last_out = None;
            self.last_entry = None;
            self.following.reset();
            return (0.0, 0, 0);
        };
        let input = CascadeInput {
            entry: d.entry,
            position_setpoint_inc: d.position,
            velocity_inc_per_s: d.velocity,
            acceleration_feedforward_inc_per_s2: d.acceleration,
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
            let fe = self.following.update(d.position, actual, now_ns);
            if let Some(ev) = fe.event {
                self.raise(ev);
            }
            // bit 13 of csp/pp is the monitor's state after this cycle
            if matches!(self.running, Some(Mode::CyclicPosition | Mode::ProfilePosition))
                && fe.following_error
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

    fn write_back(
        &mut self,
        od: &mut DriveObjects,
        c: &CyclicSlots,
        out: &Outputs,
        (bits, actual, torque, fe): (u16, i32, f32, i32),
    ) {
        let mut sw =
            out.statusword & !(SW_TARGET_REACHED | SW_MODE_BIT12 | SW_MODE_BIT13 | SW_INTERNAL_LIMIT);
        let enabled = out.state == State::OperationEnabled;
        if enabled || out.state == State::QuickStopActive {
            sw |= bits & SW_TARGET_REACHED;
        }
        if enabled {
            sw |= bits & (SW_MODE_BIT12 | SW_MODE_BIT13);
        }
        if out.drive_function {
            sw |= bits & SW_INTERNAL_LIMIT;
        }
        od.write_typed(c.statusword, sw);
        let e80 = match self.denial {
            Some(DenialCause::IllegalDirection) => 15,
            Some(
                DenialCause::HardwarePositive
                | DenialCause::HardwareNegative
                | DenialCause::SoftwarePositive
                | DenialCause::SoftwareNegative,
            ) => 20,
            _ => 0u8,
        };
        od.write_typed(c.e80, e80);
        od.write_typed(c.mode_display, out.mode_display);
        let position = self.user_position(actual);
        od.write_typed(c.position, sat_i32(position));
        let v = self.scaling.velocity_to_user(self.velocity) * self.velocity_decimals;
        od.write_typed(c.velocity, round_i32(v));
        let rated = self.params.rated_torque_nm;
        let per_mille = if rated > 0.0 { torque / rated * 1000.0 } else { 0.0 };
        let t = round_i32(per_mille).clamp(i32::from(i16::MIN), i32::from(i16::MAX)) as i16;
        od.write_typed(c.torque, t);
        od.write_typed(c.current, t);
        od.write_typed(c.following_error, sat_i32(self.user(fe)));
        od.write_typed(c.probe_status, self.probe.status());
        let probe = [
            self.probe.value_60ba(),
            self.probe.value_60bb(),
            self.probe.value_60bc(),
            self.probe.value_60bd(),
        ];
        // compared word by word (a compare of the arrays becomes a byte-wise
        // memcmp call)
        let shown = self
            .probe_shown
            .is_some_and(|p| p.iter().zip(probe).fold(0, |d, (a, b)| d | (a ^ b)) == 0);
        if !shown {
            for (slot, value) in c.probe_values.into_iter().zip(probe) {
                od.write_typed(slot, sat_i32(self.user_position(value)));
            }
            self.probe_shown = Some(probe);
        }
        od.write_typed(c.additional_position, sat_i32(position));
        let rpm = |v: f32| round_i32(v / RPM_TO_INC_PER_S).clamp(-32768, 32767) as i16;
        od.write_typed(c.vl_demand, rpm(self.vl_demand));
        od.write_typed(c.vl_actual, rpm(self.velocity));
        od.write_typed(c.e48, e48(out.state));
    }

    /// A position (or distance) in increments as the objects show it: user
    /// units of 6091h/6092h (C-109), wrapped to 32 bits like the counter.
    fn user(&self, increments: i32) -> i64 {
        let u = self
            .scaling
            .to_user(i64::from(increments))
            .unwrap_or(i64::from(increments));
        i64::from(u as i32)
    }

    /// A position in increments as the objects show it: user units,
    /// wrapped into 0 … 607Bh:02 − 1 on an endless axis (C-111).
    #[inline]
    fn user_position(&self, increments: i32) -> i64 {
        match self.modulo {
            Some(m) => m.wrap(
                self.scaling
                    .to_user(i64::from(increments))
                    .unwrap_or(i64::from(increments)),
            ),
            None => self.user(increments),
        }
    }

    /// Increments of a distance in user units (saturating).
    fn increments(&self, user: i64) -> i32 {
        let v = self.scaling.to_increments(user).unwrap_or(user);
        i32::try_from(v).unwrap_or(if v < 0 { i32::MIN } else { i32::MAX })
    }

    /// E47 (first cause) and E49 (all causes) of Switch on disabled
    /// (C-015): STO, supply, additional enable A60, and the controlword
    /// (no Shutdown command). Both 0 outside Switch on disabled.
    fn switch_on_disabled_causes(
        &self,
        od: &mut DriveObjects,
        c: &CyclicSlots,
        out: &Outputs,
        io: &AxisIo,
        cw: u16,
    ) {
        let mut causes = 0u8;
        if out.state == State::SwitchOnDisabled {
            // Shutdown = xxxx x110 (bit 7 clear): anything else keeps SOD
            let shutdown = cw & 0x0087 == 0x0006;
            for (bit, present) in [
                (0, io.sto_active),
                (1, !io.supply_ok),
                (2, !io.additional_enable),
                (3, !shutdown),
            ] {
                if present {
                    causes |= 1 << bit;
                }
            }
        }
        let first = if causes == 0 {
            0
        } else {
            causes.trailing_zeros() as u8 + 1
        };
        od.write_typed(c.e47, first);
        od.write_typed(c.e49, causes);
    }

    /// A67 from the sources in A66 (C-143): bit k is bit `b` of the entry
    /// `index`:`sub` that element k names (index << 16 | sub << 8 | b;
    /// 0 or an unreadable entry: the bit is 0).
    fn user_statusword(&self, od: &mut DriveObjects, c: &CyclicSlots, o: &Snapshot) {
        let mut a67 = 0u16;
        let sources: &[u32] = if o.a66_used { o.a66.as_slice() } else { &[] };
        for (k, &src) in sources.iter().enumerate() {
            let index = (src >> 16) as u16;
            let sub = (src >> 8) as u8;
            let bit = src & 0xFF;
            if src != 0 && bit < 64 && od.get(index, sub).is_ok_and(|v| (v >> bit) & 1 != 0) {
                a67 |= 1 << k;
            }
        }
        od.write_typed(c.a67, a67);
    }

    /// The switch levels in 60FDh (bit 0 negative limit, bit 1 positive
    /// limit, bit 2 home switch, CiA 402).
    fn digital_inputs(&self, od: &mut DriveObjects, c: &CyclicSlots, io: &AxisIo) {
        let bits =
            u32::from(io.limit_negative) | u32::from(io.limit_positive) << 1 | u32::from(io.reference) << 2;
        od.write_typed(c.digital_inputs, bits);
    }
}

/// What an axis keeps between control cycles about the dictionary: the
/// snapshot of its objects with the configuration generation it was read
/// at (while the generation stands only the cyclic set-points are read
/// again) and the resolved slots of its cyclic entries
/// (docs/architecture.md, cycle cost).
#[derive(Debug, Clone, Default)]
pub struct AxisCache {
    snapshot: Option<CachedSnapshot>,
    slots: Option<CyclicSlots>,
}

/// The snapshot with the configuration generation it was read at and what
/// follows from it alone.
#[derive(Debug, Clone)]
struct CachedSnapshot {
    generation: u32,
    snapshot: Snapshot,
    /// The user units are increments (no conversion of the snapshot).
    in_increments: bool,
    /// The control cycle A150, ns (1 ms when A150 is not one of the cycles).
    dt_ns: u32,
}

impl AxisCache {
    /// Empty: the first cycle reads everything.
    pub const fn new() -> Self {
        Self {
            snapshot: None,
            slots: None,
        }
    }
}

/// The control cycle the cascade gains of [`AxisParams::cascade`] are meant
/// for (the [`CascadeConfig::DEFAULT`] range is 62.5 … 250 µs).
pub const GAIN_REFERENCE_CYCLE_NS: u32 = 250_000;

/// The gains of `c` for a control cycle of `dt_ns`: above
/// [`GAIN_REFERENCE_CYCLE_NS`] the velocity gain Kp shrinks by r =
/// reference / cycle and the integral time Ti grows by 1/r, so the velocity
/// loop keeps its phase margin with the longer dead time; the position gain
/// Kv shrinks only by √r (the position loop is slower than the velocity loop
/// by more than √r still) to keep the stiffness against friction (the
/// default A150 is 1 ms: Kv 50 /s, Kp 0.015 N·m·s/rad, Ti 32 ms).
pub fn scaled_gains(c: &CascadeConfig, dt_ns: u32) -> CascadeConfig {
    if dt_ns <= GAIN_REFERENCE_CYCLE_NS {
        return *c;
    }
    let r = GAIN_REFERENCE_CYCLE_NS as f32 / dt_ns as f32;
    CascadeConfig {
        position_gain_per_s: c.position_gain_per_s * sqrt(r),
        velocity_gain_nm_per_rad_per_s: c.velocity_gain_nm_per_rad_per_s * r,
        velocity_integral_time_ns: (c.velocity_integral_time_ns as f32 / r) as u32,
        ..*c
    }
}

/// The A340 velocity override as a factor (C-030).
fn override_factor(o: &Snapshot) -> f32 {
    f32::from(o.override_percent) * 0.01
}

/// The switch signals after their sources (C-104): I101/I102/I103 = 2 take
/// them from I210 bits 0/1/2 (1 = actuated), 0 turns the reference switch
/// off; the limit switches with source 0 stay as wired (their evaluation is
/// off unless [`AxisParams::limits`] switches it on).
fn sourced(io: &AxisIo, o: &Snapshot) -> AxisIo {
    let bit = |n: u16| o.i210 & (1 << n) != 0;
    let [pos, neg, reference] = o.switch_source;
    // latched edges belong to the hardware inputs only
    let mut switch_edges = io.switch_edges;
    for slot in &mut switch_edges {
        let hardware = match slot.map(|e| e.switch) {
            Some(SwitchId::PositiveLimit) => pos != 2,
            Some(SwitchId::NegativeLimit) => neg != 2,
            Some(SwitchId::Reference) => reference == 1,
            None => true,
        };
        if !hardware {
            *slot = None;
        }
    }
    AxisIo {
        switch_edges,
        limit_positive: if pos == 2 { bit(0) } else { io.limit_positive },
        limit_negative: if neg == 2 { bit(1) } else { io.limit_negative },
        reference: match reference {
            0 => false,
            2 => bit(2),
            _ => io.reference,
        },
        ..*io
    }
}

/// 60A4h:01 → jerk (0 = no limit).
fn jerk(v: u32) -> f32 {
    if v == 0 {
        f32::INFINITY
    } else {
        v as f32
    }
}

/// A vl ramp (delta speed rpm, delta time s) in inc/s²; a zero time is a
/// step (very steep ramp).
fn ramp_rate((rpm, s): (u32, u16)) -> f32 {
    let v = rpm as f32 * RPM_TO_INC_PER_S;
    if s == 0 {
        v.max(1.0) * 1000.0
    } else {
        (v / f32::from(s)).max(1.0)
    }
}

/// Round half away from zero, saturating (NaN → 0).
/// `v` saturated to `i32` (positions as the objects hold them: in range
/// by construction, saturated rather than dropped otherwise).
fn sat_i32(v: i64) -> i32 {
    i32::try_from(v).unwrap_or(if v < 0 { i32::MIN } else { i32::MAX })
}

fn round_i32(x: f32) -> i32 {
    (if x >= 0.0 { x + 0.5 } else { x - 0.5 }) as i32
}

/// E48 device state (SC6 numbering, assumed from the dictionary note "2
/// ready to switch on, 4 enabled, 7 quick stop"): 0 not ready (self-test),
/// 1 switch on disabled, 2 ready to switch on, 3 switched on, 4 operation
/// enabled, 5 fault, 6 fault reaction active, 7 quick stop active.
pub const fn e48(state: State) -> u8 {
    match state {
        State::NotReadyToSwitchOn => 0,
        State::SwitchOnDisabled => 1,
        State::ReadyToSwitchOn => 2,
        State::SwitchedOn => 3,
        State::OperationEnabled => 4,
        State::Fault => 5,
        State::FaultReactionActive => 6,
        State::QuickStopActive => 7,
    }
}

/// Square root without `std` (Newton steps from a bit-level first guess);
/// `x` ≤ 0 or not finite gives 0.
fn sqrt(x: f32) -> f32 {
    if !(x.is_finite() && x > 0.0) {
        return 0.0;
    }
    let mut r = f32::from_bits((x.to_bits() >> 1) + 0x1FC0_0000);
    for _ in 0..4 {
        r = 0.5 * (r + x / r);
    }
    r
}
