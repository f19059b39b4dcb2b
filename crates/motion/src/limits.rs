//! Limit switches, direction lock and the 31-bit computing limit (spec §7,
//! §8, §13; C-091 – C-106).
//!
//! [`Limits`] evaluates once per control cycle:
//!
//! - **hardware limit switches** I441/I442 (sources I101/I102): reaching one
//!   from the permitted range raises event 53 cause 1/2 at once (fault), the
//!   position of the edge is stored and that direction stays locked until
//!   the axis is back at or behind the stored position with the switch
//!   inactive ("passable" switches, C-097); both switches hit at once is
//!   event 53 cause 7 (wiring);
//! - **software limit switches** 607Dh:01/:02 (A570), only when referenced,
//!   on a limited axis and not referencing (C-099, C-100): beyond the limit
//!   the direction is locked (released with the I22 hysteresis, C-103); more
//!   than I22 beyond it raises event 53 cause 3/4 (C-101), or, in jog with
//!   velocity control, a quick stop at the limit instead (C-091);
//! - **permitted direction** I04 on endless axes (C-105);
//! - the **31-bit computing limit**: the commanded position, summed without
//!   wrap-around, must stay within the `i32` range (±2^31 increments);
//!   beyond it event 53 cause 5 (C-106).
//!
//! The output is the direction lock (I196) with its cause (I90/I91), a stop
//! request with its ramp, and the events. Positions are increments.

use crate::Event;

/// Event 53 "Limit switch".
pub const LIMIT_SWITCH_EVENT: u16 = 53;

/// The causes of event 53 (spec §13).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LimitCause {
    /// 1: hardware limit switch positive.
    HardwarePositive = 1,
    /// 2: hardware limit switch negative.
    HardwareNegative = 2,
    /// 3: software limit switch positive.
    SoftwarePositive = 3,
    /// 4: software limit switch negative.
    SoftwareNegative = 4,
    /// 5: ±31-bit computing limit reached.
    ComputingLimit = 5,
    /// 7: both limit switches not connected.
    BothSwitches = 7,
}

impl LimitCause {
    /// The event 53 with this cause.
    pub const fn event(self) -> Event {
        Event {
            number: LIMIT_SWITCH_EVENT,
            cause: self as u8,
        }
    }
}

/// I90 denial cause (spec §8.3, C-102).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DenialCause {
    /// 1: illegal direction (I04 on endless axes).
    IllegalDirection = 1,
    /// 2: software limit switch positive.
    SoftwarePositive = 2,
    /// 3: software limit switch negative.
    SoftwareNegative = 3,
    /// 10: position not within the circular (modulo) length.
    OutsideModuloLength = 10,
    /// 11: hardware limit switch positive.
    HardwarePositive = 11,
    /// 12: hardware limit switch negative.
    HardwareNegative = 12,
}

impl DenialCause {
    /// The I90 value.
    pub const fn code(self) -> u8 {
        self as u8
    }

    /// The E80 operating state shown for this limitation: 20 "limit switch"
    /// or 15 "illegal direction" (C-107).
    pub const fn e80(self) -> u8 {
        match self {
            DenialCause::IllegalDirection | DenialCause::OutsideModuloLength => 15,
            _ => 20,
        }
    }
}

/// A direction of motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Increasing positions.
    Positive,
    /// Decreasing positions.
    Negative,
}

/// I196 direction blocking: which directions are locked.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DirectionLock {
    /// Motion in the positive direction is refused.
    pub positive: bool,
    /// Motion in the negative direction is refused.
    pub negative: bool,
}

impl DirectionLock {
    /// `true` if motion in `direction` is allowed.
    pub const fn permits(&self, direction: Direction) -> bool {
        match direction {
            Direction::Positive => !self.positive,
            Direction::Negative => !self.negative,
        }
    }

    /// `true` if any direction is locked.
    pub const fn any(&self) -> bool {
        self.positive || self.negative
    }

    /// A velocity set-point (increments/s) with the locked direction removed:
    /// 0 instead of a velocity into a locked direction (csv, pv, jog).
    pub fn filter_velocity(&self, velocity_inc_per_s: f32) -> f32 {
        if (velocity_inc_per_s > 0.0 && self.positive) || (velocity_inc_per_s < 0.0 && self.negative) {
            0.0
        } else {
            velocity_inc_per_s
        }
    }

    /// A torque set-point (N·m) with the locked direction removed (cst, pt).
    pub fn filter_torque(&self, torque_nm: f32) -> f32 {
        self.filter_velocity(torque_nm)
    }

    /// `true` if a move from `from_inc` to `to_inc` (wrap-around distance)
    /// goes into a locked direction; a zero-length move is always allowed.
    pub fn refuses_move(&self, from_inc: i32, to_inc: i32) -> bool {
        let d = to_inc.wrapping_sub(from_inc);
        (d > 0 && self.positive) || (d < 0 && self.negative)
    }
}

/// Electrical polarity of the hardware limit switch signals.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SwitchPolarity {
    /// 0 = switch hit (NC contact, broken wire counts as hit; spec §8.1).
    LowActive,
    /// 1 = switch hit.
    HighActive,
}

/// Reaction to reaching a software limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SoftLimitReaction {
    /// Event 53 cause 3/4 (fault) more than I22 beyond the limit (C-101).
    Fault,
    /// Quick stop on reaching the limit, no fault (jog with I26 = 0, C-091).
    QuickStop,
}

/// I04 permitted direction of an endless axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PermittedDirection {
    /// Both directions.
    Both,
    /// Positive direction only.
    PositiveOnly,
    /// Negative direction only.
    NegativeOnly,
}

/// The ramp a [`StopRequest`] asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopRamp {
    /// Fault: the device control's fault reaction (605Eh) stops the axis.
    FaultReaction,
    /// Quick stop ramp (6085h), no fault.
    QuickStop,
}

/// A request to stop the axis, with its ramp and the direction that caused it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StopRequest {
    /// Ramp to use.
    pub ramp: StopRamp,
    /// Direction of the limit that was reached.
    pub direction: Direction,
}

/// Configuration of [`Limits`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LimitConfig {
    /// I101 positive limit switch source set (0 = switch not evaluated).
    pub positive_switch: bool,
    /// I102 negative limit switch source set.
    pub negative_switch: bool,
    /// Polarity of I441/I442.
    pub switch_polarity: SwitchPolarity,
    /// 607Dh:01 (`A570[0]`) lowest allowed position, increments.
    pub software_min_inc: i32,
    /// 607Dh:02 (`A570[1]`) highest allowed position, increments; equal to
    /// the minimum (or below it) disables the software limits.
    pub software_max_inc: i32,
    /// I22 position window, increments: fault distance and lock hysteresis.
    pub window_inc: u32,
    /// I00 = 1: endless (modulo) axis — no software limits, no computing
    /// limit, I04 applies.
    pub endless_axis: bool,
    /// I04 permitted direction (endless axes only).
    pub permitted_direction: PermittedDirection,
    /// Reaction at a software limit.
    pub soft_limit_reaction: SoftLimitReaction,
}

impl Default for LimitConfig {
    /// No switches, software limits off, I22 = 2 912 increments, limited
    /// axis, low-active switches, fault reaction.
    fn default() -> Self {
        Self {
            positive_switch: false,
            negative_switch: false,
            switch_polarity: SwitchPolarity::LowActive,
            software_min_inc: 0,
            software_max_inc: 0,
            window_inc: crate::INCREMENTS_PER_REVOLUTION / 360,
            endless_axis: false,
            permitted_direction: PermittedDirection::Both,
            soft_limit_reaction: SoftLimitReaction::Fault,
        }
    }
}

impl LimitConfig {
    /// The software limits act (configuration side of C-099/C-100): a
    /// limited axis with min < max.
    pub const fn software_limits_configured(&self) -> bool {
        !self.endless_axis && self.software_min_inc < self.software_max_inc
    }
}

/// One cycle's inputs of [`Limits`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LimitInput {
    /// Actual position 6064h, increments.
    pub actual_position_inc: i32,
    /// Position set-point of this cycle, increments (computing limit).
    pub position_setpoint_inc: i32,
    /// I441 positive limit switch signal level (electrical, before polarity).
    pub positive_switch_signal: bool,
    /// I442 negative limit switch signal level.
    pub negative_switch_signal: bool,
    /// The axis is referenced.
    pub referenced: bool,
    /// Referencing (homing) is running: switches and software limits are not
    /// limits (§9.3), and the switch memory is cleared.
    pub referencing: bool,
}

/// One cycle's result of [`Limits`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LimitStatus {
    /// I196: the locked directions.
    pub lock: DirectionLock,
    /// I90 cause of the lock (I91 = `is_some()`); hardware before software
    /// before illegal direction.
    pub denial: Option<DenialCause>,
    /// Event raised this cycle (53 with its cause).
    pub event: Option<Event>,
    /// Stop requested this cycle.
    pub stop: Option<StopRequest>,
}

/// The position where the 31-bit computing limit trips: outside
/// `i32::MIN ..= i32::MAX` (±2^31 increments).
const COMPUTING_MIN: i64 = i32::MIN as i64;
const COMPUTING_MAX: i64 = i32::MAX as i64;

/// Limit-switch evaluation of one axis.
#[derive(Debug, Clone)]
pub struct Limits {
    config: LimitConfig,
    /// Passable-switch memory: position where the switch edge was seen.
    positive_memory: Option<i32>,
    negative_memory: Option<i32>,
    /// Switch hit in the last cycle (edge detection).
    positive_hit: bool,
    negative_hit: bool,
    both_hit: bool,
    /// Software-limit direction locks (with hysteresis).
    soft_positive_lock: bool,
    soft_negative_lock: bool,
    /// Software-limit fault raised (re-armed when the lock releases).
    soft_positive_fault: bool,
    soft_negative_fault: bool,
    /// Commanded position summed without wrap-around.
    unwrapped_setpoint: i64,
    last_setpoint: i32,
    computing_fault: bool,
}

impl Limits {
    /// Limits with `config` and the set-point at `position_inc` (restart:
    /// empty switch memory).
    pub const fn new(config: LimitConfig, position_inc: i32) -> Self {
        Self {
            config,
            positive_memory: None,
            negative_memory: None,
            positive_hit: false,
            negative_hit: false,
            both_hit: false,
            soft_positive_lock: false,
            soft_negative_lock: false,
            soft_positive_fault: false,
            soft_negative_fault: false,
            unwrapped_setpoint: position_inc as i64,
            last_setpoint: position_inc,
            computing_fault: false,
        }
    }

    /// The configuration.
    pub const fn config(&self) -> &LimitConfig {
        &self.config
    }

    /// Replaces the configuration (e.g. 607Dh written); keeps the state.
    pub fn set_config(&mut self, config: LimitConfig) {
        self.config = config;
    }

    /// Stored positions of the passable-switch memory (positive, negative).
    pub const fn switch_memory(&self) -> (Option<i32>, Option<i32>) {
        (self.positive_memory, self.negative_memory)
    }

    /// I52 "Delete limit switch memory": clears each switch's memory (and
    /// the cause-7 latch) while that switch's signal is inactive (C-098).
    /// Returns `true` if everything was cleared.
    pub fn clear_switch_memory(&mut self) -> bool {
        if !self.positive_hit {
            self.positive_memory = None;
        }
        if !self.negative_hit {
            self.negative_memory = None;
        }
        if !(self.positive_hit && self.negative_hit) {
            self.both_hit = false;
        }
        self.positive_memory.is_none() && self.negative_memory.is_none()
    }

    /// Both hardware limit switches read hit in the last update (the cause
    /// of event 53 cause 7 is still there: its fault cannot be
    /// acknowledged, C-017).
    pub fn both_switches_hit(&self) -> bool {
        self.positive_hit && self.negative_hit
    }

    /// Referencing finished or the reference was deleted (I452): clears the
    /// switch memory (C-098) and restarts the computing limit at the new
    /// position set-point `position_inc`.
    pub fn reference_changed(&mut self, position_inc: i32) {
        self.positive_memory = None;
        self.negative_memory = None;
        self.restart_computing_limit(position_inc);
    }

    /// Restarts the summed commanded position at `position_inc` (e.g. after
    /// a preset), clearing the computing-limit latch.
    pub fn restart_computing_limit(&mut self, position_inc: i32) {
        self.unwrapped_setpoint = i64::from(position_inc);
        self.last_setpoint = position_inc;
        self.computing_fault = false;
    }

    /// The commanded position summed without wrap-around, increments.
    pub const fn unwrapped_setpoint_inc(&self) -> i64 {
        self.unwrapped_setpoint
    }

    /// `true` if a relative move of `distance_inc` from the present
    /// set-point would pass the 31-bit computing limit (check before taking
    /// over a pp/jog target, C-106). Endless axes never do.
    pub fn relative_move_exceeds_computing_limit(&self, distance_inc: i64) -> bool {
        if self.config.endless_axis {
            return false;
        }
        let target = self.unwrapped_setpoint.saturating_add(distance_inc);
        !(COMPUTING_MIN..=COMPUTING_MAX).contains(&target)
    }

    /// Jog with position control (I26 = 1, C-092): `target_inc` clamped into
    /// the software-limit range, so the profile stops at the limit and never
    /// passes it. Unchanged when the software limits do not act.
    pub fn clamp_target(&self, target_inc: i32, referenced: bool) -> i32 {
        if referenced && self.config.software_limits_configured() {
            target_inc
                .max(self.config.software_min_inc)
                .min(self.config.software_max_inc)
        } else {
            target_inc
        }
    }

    /// Evaluates one control cycle.
    pub fn update(&mut self, input: &LimitInput) -> LimitStatus {
        let mut event = None;
        let mut stop = None;
        let mut lock = DirectionLock::default();
        let mut denial = None;
        let actual = input.actual_position_inc;

        // --- Computing limit (C-106) ---
        let step = input.position_setpoint_inc.wrapping_sub(self.last_setpoint);
        self.last_setpoint = input.position_setpoint_inc;
        self.unwrapped_setpoint = self.unwrapped_setpoint.saturating_add(i64::from(step));
        if !self.config.endless_axis {
            let outside = !(COMPUTING_MIN..=COMPUTING_MAX).contains(&self.unwrapped_setpoint);
            if outside && !self.computing_fault {
                self.computing_fault = true;
                event = Some(LimitCause::ComputingLimit.event());
                stop = Some(StopRequest {
                    ramp: StopRamp::FaultReaction,
                    direction: if self.unwrapped_setpoint > 0 {
                        Direction::Positive
                    } else {
                        Direction::Negative
                    },
                });
            } else if !outside {
                self.computing_fault = false;
            }
            if self.computing_fault {
                if self.unwrapped_setpoint > 0 {
                    lock.positive = true;
                } else {
                    lock.negative = true;
                }
            }
        }

        // --- Hardware limit switches (C-093 – C-098) ---
        let level_hit = |signal: bool| match self.config.switch_polarity {
            SwitchPolarity::LowActive => !signal,
            SwitchPolarity::HighActive => signal,
        };
        let pos_hit = self.config.positive_switch && level_hit(input.positive_switch_signal);
        let neg_hit = self.config.negative_switch && level_hit(input.negative_switch_signal);
        if input.referencing {
            // §9.3: not limit switches while referencing; referencing clears
            // the memory.
            self.positive_memory = None;
            self.negative_memory = None;
            self.both_hit = false;
        } else if pos_hit && neg_hit {
            if !self.both_hit {
                self.both_hit = true;
                event = event.or(Some(LimitCause::BothSwitches.event()));
                stop = stop.or(Some(StopRequest {
                    ramp: StopRamp::FaultReaction,
                    direction: Direction::Positive,
                }));
            }
        } else {
            if pos_hit && !self.positive_hit && self.positive_memory.is_none() {
                self.positive_memory = Some(actual);
                event = event.or(Some(LimitCause::HardwarePositive.event()));
                stop = stop.or(Some(StopRequest {
                    ramp: StopRamp::FaultReaction,
                    direction: Direction::Positive,
                }));
            }
            if neg_hit && !self.negative_hit && self.negative_memory.is_none() {
                self.negative_memory = Some(actual);
                event = event.or(Some(LimitCause::HardwareNegative.event()));
                stop = stop.or(Some(StopRequest {
                    ramp: StopRamp::FaultReaction,
                    direction: Direction::Negative,
                }));
            }
            // Passable switch: the memory clears only with the switch
            // inactive and the axis back at or behind the stored position.
            if let Some(p) = self.positive_memory {
                if !pos_hit && actual.wrapping_sub(p) <= 0 {
                    self.positive_memory = None;
                }
            }
            if let Some(p) = self.negative_memory {
                if !neg_hit && actual.wrapping_sub(p) >= 0 {
                    self.negative_memory = None;
                }
            }
        }
        self.positive_hit = pos_hit;
        self.negative_hit = neg_hit;
        if !input.referencing {
            if self.both_hit {
                lock.positive = true;
                lock.negative = true;
            }
            if pos_hit || self.positive_memory.is_some() {
                lock.positive = true;
                denial = denial.or(Some(DenialCause::HardwarePositive));
            }
            if neg_hit || self.negative_memory.is_some() {
                lock.negative = true;
                denial = denial.or(Some(DenialCause::HardwareNegative));
            }
        }

        // --- Software limit switches (C-099 – C-103, C-091) ---
        let soft_active = input.referenced && !input.referencing && self.config.software_limits_configured();
        if soft_active {
            let a = i64::from(actual);
            let max = i64::from(self.config.software_max_inc);
            let min = i64::from(self.config.software_min_inc);
            let w = i64::from(self.config.window_inc);
            // Positive side.
            if a > max {
                if !self.soft_positive_lock && self.config.soft_limit_reaction == SoftLimitReaction::QuickStop
                {
                    stop = stop.or(Some(StopRequest {
                        ramp: StopRamp::QuickStop,
                        direction: Direction::Positive,
                    }));
                }
                self.soft_positive_lock = true;
            } else if a < max - w {
                self.soft_positive_lock = false;
                self.soft_positive_fault = false;
            }
            if self.config.soft_limit_reaction == SoftLimitReaction::Fault
                && a > max + w
                && !self.soft_positive_fault
            {
                self.soft_positive_fault = true;
                event = event.or(Some(LimitCause::SoftwarePositive.event()));
                stop = stop.or(Some(StopRequest {
                    ramp: StopRamp::FaultReaction,
                    direction: Direction::Positive,
                }));
            }
            // Negative side.
            if a < min {
                if !self.soft_negative_lock && self.config.soft_limit_reaction == SoftLimitReaction::QuickStop
                {
                    stop = stop.or(Some(StopRequest {
                        ramp: StopRamp::QuickStop,
                        direction: Direction::Negative,
                    }));
                }
                self.soft_negative_lock = true;
            } else if a > min + w {
                self.soft_negative_lock = false;
                self.soft_negative_fault = false;
            }
            if self.config.soft_limit_reaction == SoftLimitReaction::Fault
                && a < min - w
                && !self.soft_negative_fault
            {
                self.soft_negative_fault = true;
                event = event.or(Some(LimitCause::SoftwareNegative.event()));
                stop = stop.or(Some(StopRequest {
                    ramp: StopRamp::FaultReaction,
                    direction: Direction::Negative,
                }));
            }
            if self.soft_positive_lock {
                lock.positive = true;
                denial = denial.or(Some(DenialCause::SoftwarePositive));
            }
            if self.soft_negative_lock {
                lock.negative = true;
                denial = denial.or(Some(DenialCause::SoftwareNegative));
            }
        } else {
            self.soft_positive_lock = false;
            self.soft_negative_lock = false;
            self.soft_positive_fault = false;
            self.soft_negative_fault = false;
        }

        // --- I04 permitted direction on endless axes (C-105) ---
        if self.config.endless_axis {
            match self.config.permitted_direction {
                PermittedDirection::Both => {}
                PermittedDirection::PositiveOnly => {
                    lock.negative = true;
                    denial = denial.or(Some(DenialCause::IllegalDirection));
                }
                PermittedDirection::NegativeOnly => {
                    lock.positive = true;
                    denial = denial.or(Some(DenialCause::IllegalDirection));
                }
            }
        }

        LimitStatus {
            lock,
            denial,
            event,
            stop,
        }
    }
}

#[cfg(test)]
mod tests;
