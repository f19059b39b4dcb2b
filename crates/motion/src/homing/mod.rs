//! Homing mode 6: the 20 referencing methods of 6098h (A586) (spec §6.5.9,
//! §9; C-058 – C-087).
//!
//! [`Homing`] is stepped once per control cycle with the parameters
//! ([`HomingConfig`]: 6098h, 6099h:01/:02, 609Ah, 607Ch, I43, I44, I53,
//! I29, I30) and what the drive sees ([`HomingInput`]: actual position,
//! limit and reference switches with their latched edges, the latched index
//! pulse, torque at the limit, standstill, controlword bits 4 and 8). It
//! returns a position set-point to follow (with velocity and acceleration
//! feedforward, from the [`ProfileGenerator`]), the homing bits 13/12/10 of
//! the statusword and, once, the [`ReferenceEvent`]: the drive then adds
//! [`ReferenceEvent::shift`] to its position, so the reference point reads
//! 607Ch.
//!
//! # Sequences
//!
//! All switch methods are one procedure: a fast search (6099h:01) towards
//! the switch, reversal, a slow creep (6099h:02) off the switch in the
//! *approach* direction (the opposite of the search), and the reference at
//! the leaving edge of the switch or at the first index pulse after it
//! (beyond the index search offset I53). Started on the switch, the axis
//! creeps off it at once, so the same edge (and index pulse) is found from
//! every start position (CiA 402). A limit switch in the travel direction
//! during the fast search reverses the axis once (§9.3, C-083); the search
//! then continues at fast speed and turns to the creep when the switch is
//! reached. Index methods 33/34 creep from the start; torque methods −1 … −4
//! drive into the mechanical stop until the torque has been at the limit
//! (I28) for I29, and either reference there or creep back to the next index
//! pulse. Method 37 (and 35) references at once.
//!
//! | 6098h | Pilz | search | approach | switch | index |
//! |---|---|---|---|---|---|
//! | 1 | A | − | + | −LS | yes |
//! | 5 | B | − | + | RS (negative side) | yes |
//! | 17 | C | − | + | −LS | no |
//! | 21 | D | − | + | RS (negative side) | no |
//! | 2 | E | + | − | +LS | yes |
//! | 3 | F | + | − | RS (positive side) | yes |
//! | 18 | G | + | − | +LS | no |
//! | 19 | H | + | − | RS (positive side) | no |
//! | 7 | I | + | − | RS (centred) | yes |
//! | 23 | J | + | − | RS (centred) | no |
//! | 11 | K | − | + | RS (centred) | yes |
//! | 27 | L | − | + | RS (centred) | no |
//! | 33 / 34 | M / N | − / + | = | – | yes |
//! | 37, 35 | O | – | – | – | no |
//! | −1 / −2 | P / R | + / − | – | torque stop | no |
//! | −3 / −4 | Q / S | + / − | − / + | torque stop | yes |
//!
//! After the reference event the axis stops with 609Ah (jerk I44) and, with
//! I43 = 1, positions on 607Ch (C-062).
//!
//! Coordinates: every position in and out is in the drive's coordinates
//! (increments, wrapping). From the cycle whose output carries the
//! [`ReferenceEvent`] on, the set-point is in the *new* coordinates, and the
//! drive must give the actual position (and latches) in the new coordinates
//! from the next cycle on.

mod io;
mod method;

pub use io::{
    HomingConfig, HomingError, HomingInput, HomingOutput, HomingStatus, ReferenceEvent, SwitchInput,
};
pub use method::{Direction, HomingMethod};
use method::{Kind, Target};

use crate::profile::{PositionTarget, ProfileError, ProfileGenerator, ProfileLimits, SetMode};
use nanos::Nanos;

/// Statusword bit 10 "target reached" (homing: referencing finished or
/// interrupted).
pub const SW_TARGET_REACHED: u16 = 1 << 10;
/// Statusword bit 12 "homing attained" (reference set).
pub const SW_HOMING_ATTAINED: u16 = 1 << 12;
/// Statusword bit 13 "homing error".
pub const SW_HOMING_ERROR: u16 = 1 << 13;
/// The statusword bits homing mode owns (13, 12, 10).
pub const SW_HOMING_MASK: u16 = SW_TARGET_REACHED | SW_HOMING_ATTAINED | SW_HOMING_ERROR;

/// 6098h codes the drive accepts, in the order of 60E3h:01 … :14 (C-060).
pub const SUPPORTED_METHODS: [i8; 20] = [
    1, 2, 3, 5, 7, 11, 17, 18, 19, 21, 23, 27, 33, 34, 35, 37, -1, -2, -3, -4,
];

/// Where the state machine is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// Not started or interrupted and at standstill.
    Interrupted,
    /// Fast search for the switch.
    Search,
    /// Creep off the switch in the approach direction.
    Leave,
    /// Creep until an index pulse beyond `from` (homing coordinates).
    Index { from: i32 },
    /// Into the mechanical stop.
    Torque,
    /// Braking after halt / bit 4 falling.
    Halting,
    /// Reference set, braking; then to 607Ch if `then_home`.
    Stopping { then_home: bool },
    /// Positioning on 607Ch.
    MoveHome,
    /// Completed.
    Done,
    /// Failed (braking or stopped).
    Failed(HomingError),
}

impl Phase {
    const fn searching(self) -> bool {
        matches!(
            self,
            Phase::Search | Phase::Leave | Phase::Index { .. } | Phase::Torque
        )
    }
}

/// Switch levels of the previous cycle.
#[derive(Debug, Clone, Copy, Default)]
struct Levels {
    neg: bool,
    pos: bool,
    rs: bool,
}

/// The homing state machine of one axis.
///
/// Positions inside are "homing coordinates": the drive's coordinates when
/// the generator was last synchronised; `shift` maps them to the drive's
/// (drive = homing + shift).
#[derive(Debug, Clone)]
pub struct Homing {
    gen: ProfileGenerator,
    cfg: HomingConfig,
    kind: Kind,
    index: bool,
    phase: Phase,
    /// Drive coordinates − homing coordinates, increments.
    shift: i32,
    /// Commanded travel direction.
    travel: Direction,
    /// Reversed once at a limit switch.
    reversed: bool,
    /// Previous controlword bit 4.
    prev_start: bool,
    prev: Levels,
    /// Last set-point, homing coordinates, and its velocity.
    last_position: i32,
    last_velocity: f32,
    /// Travel since the start, increments.
    travelled: u64,
    /// Time the torque has been at the limit.
    torque_time: Nanos,
    referenced: bool,
}

impl Homing {
    /// Not started (status 001), standing at `actual_position`.
    pub fn new(actual_position: i32) -> Self {
        Self {
            gen: ProfileGenerator::new(actual_position),
            cfg: HomingConfig::default(),
            kind: Kind::Current,
            index: false,
            phase: Phase::Interrupted,
            shift: 0,
            travel: Direction::Positive,
            reversed: false,
            prev_start: true,
            prev: Levels::default(),
            last_position: actual_position,
            last_velocity: 0.0,
            travelled: 0,
            torque_time: Nanos::ZERO,
            referenced: false,
        }
    }

    /// Homing mode becomes active (mode 6 in Operation enabled) at
    /// `actual_position`: not started (001); a controlword bit 4 already at
    /// 1 does not start, a 0→1 edge is needed. The referenced state is kept.
    pub fn activate(&mut self, actual_position: i32) {
        let referenced = self.referenced;
        *self = Self::new(actual_position);
        self.referenced = referenced;
    }

    /// The axis is referenced (a reference event since the last start or
    /// [`clear_reference`](Self::clear_reference)); absolute moves need it
    /// (C-050).
    pub const fn is_referenced(&self) -> bool {
        self.referenced
    }

    /// Deletes the reference (I452).
    pub fn clear_reference(&mut self) {
        self.referenced = false;
    }

    /// Referencing motion under way (searching, stopping, positioning on
    /// 607Ch, braking after halt or error): the drive suspends the
    /// limit-switch fault and the software limits (C-083, C-085).
    pub const fn is_referencing(&self) -> bool {
        !matches!(self.phase, Phase::Interrupted | Phase::Done) && !self.stopped_failure()
    }

    const fn stopped_failure(&self) -> bool {
        matches!(self.phase, Phase::Failed(_)) && self.gen.is_standstill()
    }

    /// The current status (as of the last [`step`](Self::step)); `standstill`
    /// is the drive's standstill flag (error at standstill = 110).
    pub fn status(&self, standstill: bool) -> HomingStatus {
        match self.phase {
            Phase::Interrupted => HomingStatus::Interrupted,
            Phase::Search | Phase::Leave | Phase::Index { .. } | Phase::Torque | Phase::Halting => {
                HomingStatus::InProgress
            }
            Phase::Stopping { .. } | Phase::MoveHome => HomingStatus::Attained,
            Phase::Done => HomingStatus::Completed,
            Phase::Failed(error) => HomingStatus::Error {
                error,
                standstill: standstill && self.gen.is_standstill(),
            },
        }
    }

    /// One control cycle of `dt_ns` ns: a 0→1 edge of bit 4 (without halt)
    /// starts the method of `config`; halt or a 1→0 edge of bit 4 interrupts
    /// a running search (braking with 609Ah, then 001) or skips the move to
    /// 607Ch; a start edge while halt is set is ignored.
    pub fn step(&mut self, config: &HomingConfig, input: &HomingInput, dt_ns: u32) -> HomingOutput {
        let mut event = None;
        let rising = input.start && !self.prev_start;
        let falling = !input.start && self.prev_start;
        self.prev_start = input.start;
        if rising && !input.halt {
            self.begin(config, input, &mut event);
        } else if falling || input.halt {
            self.interrupt();
        }
        if self.phase.searching() {
            self.supervise(input, dt_ns, &mut event);
        }
        self.settle(input);
        self.prev = Levels {
            neg: input.negative_limit.active,
            pos: input.positive_limit.active,
            rs: input.reference_switch.active,
        };
        let s = self.gen.step(dt_ns);
        if self.phase.searching() {
            let d = i64::from(s.position.wrapping_sub(self.last_position)).unsigned_abs();
            self.travelled = self.travelled.saturating_add(d);
            let max = self.cfg.max_search_distance;
            if max > 0 && self.travelled > u64::from(max) {
                self.fail(HomingError::TravelExceeded);
            }
        }
        self.last_position = s.position;
        self.last_velocity = s.velocity;
        HomingOutput {
            position: s.position.wrapping_add(self.shift),
            velocity: s.velocity,
            acceleration: s.acceleration,
            status: self.status(input.standstill),
            reference: event,
        }
    }

    fn limits(&self, speed: f32) -> ProfileLimits {
        ProfileLimits {
            velocity: speed,
            acceleration: self.cfg.acceleration,
            deceleration: self.cfg.acceleration,
            jerk: self.cfg.jerk,
        }
    }

    /// Drive → homing coordinates.
    fn local(&self, drive: i32) -> i32 {
        drive.wrapping_sub(self.shift)
    }

    fn switch<'a>(&self, input: &'a HomingInput, target: Target) -> (&'a SwitchInput, bool) {
        match target {
            Target::NegativeLimit => (&input.negative_limit, self.prev.neg),
            Target::PositiveLimit => (&input.positive_limit, self.prev.pos),
            Target::Reference => (&input.reference_switch, self.prev.rs),
        }
    }

    /// The switch a switch method watches (I30 = 2: the search-side limit
    /// switch instead of the reference switch).
    fn target(&self) -> Option<Target> {
        match self.kind {
            Kind::Switch { target, search } => Some(match (target, self.cfg.limit_as_reference) {
                (Target::Reference, true) => match search {
                    Direction::Negative => Target::NegativeLimit,
                    Direction::Positive => Target::PositiveLimit,
                },
                (t, _) => t,
            }),
            _ => None,
        }
    }

    fn run(&mut self, dir: Direction, speed: f32) -> Result<(), ProfileError> {
        self.travel = dir;
        self.gen.run_velocity(dir.signf() * speed, self.limits(speed))
    }

    /// Start edge: takes the parameters and starts the method.
    fn begin(&mut self, config: &HomingConfig, input: &HomingInput, event: &mut Option<ReferenceEvent>) {
        self.cfg = *config;
        if self.gen.is_standstill() {
            self.shift = 0;
            self.gen.reset(input.actual_position);
            self.last_position = input.actual_position;
        }
        self.referenced = false;
        self.reversed = false;
        self.travelled = 0;
        self.torque_time = Nanos::ZERO;
        self.prev = Levels {
            neg: input.negative_limit.active,
            pos: input.positive_limit.active,
            rs: input.reference_switch.active,
        };
        self.phase = Phase::Search;
        let Some(method) = HomingMethod::from_code(config.method) else {
            return self.fail(HomingError::InvalidMethod);
        };
        self.kind = method.kind();
        self.index = method.uses_index();
        let fast = matches!(self.kind, Kind::Switch { .. } | Kind::Torque(_));
        let moves = !matches!(self.kind, Kind::Current);
        let params_ok = (!moves || self.limits(config.slow_speed).validate().is_ok())
            && (!fast || self.limits(config.fast_speed).validate().is_ok())
            && (!config.move_to_home || self.limits(self.home_speed()).validate().is_ok());
        if !params_ok {
            return self.fail(HomingError::InvalidParameters);
        }
        if input.negative_limit.active && input.positive_limit.active {
            return self.fail(HomingError::BothLimits);
        }
        let started = match self.kind {
            Kind::Current => {
                let at = self.local(input.actual_position);
                self.set_reference(at, event);
                Ok(())
            }
            Kind::Switch { search, .. } => {
                let on = self.target().is_some_and(|t| self.switch(input, t).0.active);
                if on {
                    self.phase = Phase::Leave;
                    self.run(search.reverse(), config.slow_speed)
                } else {
                    self.run(search, config.fast_speed)
                }
            }
            Kind::Index(dir) => {
                self.phase = Phase::Index {
                    from: self.local(input.actual_position),
                };
                self.run(dir, config.slow_speed)
            }
            Kind::Torque(dir) => {
                self.phase = Phase::Torque;
                self.run(dir, config.fast_speed)
            }
        };
        if started.is_err() {
            self.fail(HomingError::InvalidParameters);
        }
    }

    /// Speed of the positioning on 607Ch: 6099h:01, or 6099h:02 if that is 0.
    fn home_speed(&self) -> f32 {
        if self.cfg.fast_speed > 0.0 {
            self.cfg.fast_speed
        } else {
            self.cfg.slow_speed
        }
    }

    /// Halt or controlword bit 4 falling.
    fn interrupt(&mut self) {
        match self.phase {
            p if p.searching() => {
                self.brake();
                self.phase = Phase::Halting;
            }
            Phase::Stopping { .. } => self.phase = Phase::Stopping { then_home: false },
            Phase::MoveHome => {
                self.brake();
                self.phase = Phase::Stopping { then_home: false };
            }
            _ => {}
        }
    }

    /// Ramps to standstill with 609Ah and I44; if those are unusable, stops
    /// at once on the last set-point.
    fn brake(&mut self) {
        if self.gen.stop(self.cfg.acceleration, self.cfg.jerk).is_err() {
            let at = self.last_position;
            self.gen.reset(at);
        }
    }

    fn fail(&mut self, error: HomingError) {
        self.brake();
        self.phase = Phase::Failed(error);
    }

    /// Reference point `at` (homing coordinates) found.
    fn set_reference(&mut self, at: i32, event: &mut Option<ReferenceEvent>) {
        let shift = self.cfg.home_offset.wrapping_sub(at);
        *event = Some(ReferenceEvent {
            shift: shift.wrapping_sub(self.shift),
            reference_position: at.wrapping_add(self.shift),
        });
        self.shift = shift;
        self.referenced = true;
        self.brake();
        self.phase = Phase::Stopping {
            then_home: self.cfg.move_to_home,
        };
    }

    /// Phases that wait for standstill.
    fn settle(&mut self, input: &HomingInput) {
        let still = self.gen.is_standstill() && input.standstill;
        match self.phase {
            Phase::Halting if still => self.phase = Phase::Interrupted,
            Phase::Stopping { then_home } if still => {
                if then_home {
                    let target = self.local(self.cfg.home_offset);
                    let limits = self.limits(self.home_speed());
                    if self
                        .gen
                        .move_to(PositionTarget::Absolute(target), limits, SetMode::Immediate)
                        .is_ok()
                    {
                        self.phase = Phase::MoveHome;
                    } else {
                        self.phase = Phase::Done;
                    }
                } else {
                    self.phase = Phase::Done;
                }
            }
            Phase::MoveHome if still => self.phase = Phase::Done,
            _ => {}
        }
    }

    /// Limit switches, switch edges, index pulses, torque: one searching
    /// cycle.
    fn supervise(&mut self, input: &HomingInput, dt_ns: u32, event: &mut Option<ReferenceEvent>) {
        let neg = input.negative_limit.active;
        let pos = input.positive_limit.active;
        if neg && pos {
            return self.fail(HomingError::BothLimits);
        }
        let target = self.target();
        // The watched limit switch is no limit while it is searched or left.
        let watched = if matches!(self.phase, Phase::Search | Phase::Leave) {
            target
        } else {
            None
        };
        // Limit switches (§9.3).
        for (side, active, was, t) in [
            (Direction::Negative, neg, self.prev.neg, Target::NegativeLimit),
            (Direction::Positive, pos, self.prev.pos, Target::PositiveLimit),
        ] {
            if !active || watched == Some(t) {
                continue;
            }
            if side != self.travel {
                if !was {
                    return self.fail(HomingError::LimitAgainstTravel);
                }
            } else if self.phase == Phase::Search {
                if self.reversed {
                    return self.fail(HomingError::SwitchNotFound);
                }
                self.reversed = true;
                if self.run(side.reverse(), self.cfg.fast_speed).is_err() {
                    return self.fail(HomingError::InvalidParameters);
                }
            } else {
                return self.fail(HomingError::UnexpectedLimit);
            }
        }
        let approach = match self.kind {
            Kind::Switch { search, .. } => search.reverse(),
            Kind::Index(dir) => dir,
            Kind::Torque(dir) => dir.reverse(),
            Kind::Current => self.travel,
        };
        let moving_approach = self.last_velocity * approach.signf() > 0.0;
        match (self.phase, target) {
            (Phase::Search, Some(t)) if self.switch(input, t).0.active => {
                self.phase = Phase::Leave;
                if self.run(approach, self.cfg.slow_speed).is_err() {
                    self.fail(HomingError::InvalidParameters);
                }
            }
            (Phase::Leave, Some(t)) => {
                let (sw, was) = self.switch(input, t);
                if was && !sw.active && moving_approach {
                    let edge = self.local(sw.edge.unwrap_or(input.actual_position));
                    if self.index {
                        self.phase = Phase::Index { from: edge };
                        self.check_index(input, edge, approach, event);
                    } else {
                        self.set_reference(edge, event);
                    }
                }
            }
            (Phase::Index { from }, _) if moving_approach => {
                self.check_index(input, from, approach, event);
            }
            (Phase::Torque, _) => {
                self.torque_time = if input.torque_limit {
                    self.torque_time.saturating_add(Nanos::from_ns(u64::from(dt_ns)))
                } else {
                    Nanos::ZERO
                };
                if input.torque_limit && self.torque_time >= self.cfg.torque_hold {
                    let at = self.local(input.actual_position);
                    self.gen.reset(at);
                    self.last_position = at;
                    if self.index {
                        self.phase = Phase::Index { from: at };
                        if self.run(approach, self.cfg.slow_speed).is_err() {
                            self.fail(HomingError::InvalidParameters);
                        }
                    } else {
                        self.set_reference(at, event);
                    }
                }
            }
            _ => {}
        }
    }

    /// Takes an index pulse at least I53 beyond `from` in `dir`.
    fn check_index(
        &mut self,
        input: &HomingInput,
        from: i32,
        dir: Direction,
        event: &mut Option<ReferenceEvent>,
    ) {
        if let Some(q) = input.index {
            let q = self.local(q);
            let ahead = i64::from(q.wrapping_sub(from)) * dir.sign();
            if ahead >= i64::from(self.cfg.index_search_offset) {
                self.set_reference(q, event);
            }
        }
    }
}

#[cfg(test)]
mod tests;
