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

use crate::profile::{PositionTarget, ProfileError, ProfileGenerator, ProfileLimits, SetMode};

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

/// A travel direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Towards smaller positions.
    Negative,
    /// Towards larger positions.
    Positive,
}

impl Direction {
    /// −1 or +1.
    pub const fn sign(self) -> i64 {
        match self {
            Direction::Negative => -1,
            Direction::Positive => 1,
        }
    }

    /// The other direction.
    pub const fn reverse(self) -> Self {
        match self {
            Direction::Negative => Direction::Positive,
            Direction::Positive => Direction::Negative,
        }
    }

    fn signf(self) -> f32 {
        match self {
            Direction::Negative => -1.0,
            Direction::Positive => 1.0,
        }
    }
}

/// A homing method of 6098h (A586); the discriminant is the 6098h code
/// (spec §9.2, Pilz letters A … S).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(i8)]
pub enum HomingMethod {
    /// A (1): negative limit switch and index pulse.
    NegativeLimitIndex = 1,
    /// E (2): positive limit switch and index pulse.
    PositiveLimitIndex = 2,
    /// F (3): positive home switch and index pulse.
    PositiveHomeIndex = 3,
    /// B (5): negative home switch and index pulse.
    NegativeHomeIndex = 5,
    /// I (7): centred home switch and index pulse, initial positive.
    HomeIndexPositive = 7,
    /// K (11): centred home switch and index pulse, initial negative.
    HomeIndexNegative = 11,
    /// C (17): negative limit switch.
    NegativeLimit = 17,
    /// G (18): positive limit switch.
    PositiveLimit = 18,
    /// H (19): positive home switch.
    PositiveHome = 19,
    /// D (21): negative home switch.
    NegativeHome = 21,
    /// J (23): centred home switch, initial positive.
    HomePositive = 23,
    /// L (27): centred home switch, initial negative.
    HomeNegative = 27,
    /// M (33): index pulse, negative.
    IndexNegative = 33,
    /// N (34): index pulse, positive.
    IndexPositive = 34,
    /// O (35): reserved in CiA 402, treated like 37.
    CurrentPosition35 = 35,
    /// O (37): reference at the current position, no motion.
    CurrentPosition = 37,
    /// P (−1): torque/force limit (mechanical stop), positive.
    TorquePositive = -1,
    /// R (−2): torque/force limit, negative.
    TorqueNegative = -2,
    /// Q (−3): torque/force limit and index pulse, initial positive.
    TorquePositiveIndex = -3,
    /// S (−4): torque/force limit and index pulse, initial negative.
    TorqueNegativeIndex = -4,
}

/// The switch a switch method references on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Target {
    NegativeLimit,
    PositiveLimit,
    Reference,
}

/// What a method does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// Fast search in `search` for `target`, creep off it in the opposite
    /// direction.
    Switch { target: Target, search: Direction },
    /// Creep for the index pulse.
    Index(Direction),
    /// Reference at the actual position.
    Current,
    /// Fast into the mechanical stop.
    Torque(Direction),
}

impl HomingMethod {
    /// The method of a 6098h code; `None` for codes the drive refuses.
    pub const fn from_code(code: i8) -> Option<Self> {
        use HomingMethod::*;
        Some(match code {
            1 => NegativeLimitIndex,
            2 => PositiveLimitIndex,
            3 => PositiveHomeIndex,
            5 => NegativeHomeIndex,
            7 => HomeIndexPositive,
            11 => HomeIndexNegative,
            17 => NegativeLimit,
            18 => PositiveLimit,
            19 => PositiveHome,
            21 => NegativeHome,
            23 => HomePositive,
            27 => HomeNegative,
            33 => IndexNegative,
            34 => IndexPositive,
            35 => CurrentPosition35,
            37 => CurrentPosition,
            -1 => TorquePositive,
            -2 => TorqueNegative,
            -3 => TorquePositiveIndex,
            -4 => TorqueNegativeIndex,
            _ => return None,
        })
    }

    /// The 6098h code.
    pub const fn code(self) -> i8 {
        self as i8
    }

    /// The Pilz letter of §9.2 (`'A'` … `'S'`).
    pub const fn letter(self) -> char {
        use HomingMethod::*;
        match self {
            NegativeLimitIndex => 'A',
            NegativeHomeIndex => 'B',
            NegativeLimit => 'C',
            NegativeHome => 'D',
            PositiveLimitIndex => 'E',
            PositiveHomeIndex => 'F',
            PositiveLimit => 'G',
            PositiveHome => 'H',
            HomeIndexPositive => 'I',
            HomePositive => 'J',
            HomeIndexNegative => 'K',
            HomeNegative => 'L',
            IndexNegative => 'M',
            IndexPositive => 'N',
            CurrentPosition | CurrentPosition35 => 'O',
            TorquePositive => 'P',
            TorquePositiveIndex => 'Q',
            TorqueNegative => 'R',
            TorqueNegativeIndex => 'S',
        }
    }

    /// Whether the reference is an index (zero) pulse.
    pub const fn uses_index(self) -> bool {
        use HomingMethod::*;
        matches!(
            self,
            NegativeLimitIndex
                | PositiveLimitIndex
                | PositiveHomeIndex
                | NegativeHomeIndex
                | HomeIndexPositive
                | HomeIndexNegative
                | IndexNegative
                | IndexPositive
                | TorquePositiveIndex
                | TorqueNegativeIndex
        )
    }

    /// Direction of the first move (started off the switch); `None` for 37/35.
    pub const fn first_direction(self) -> Option<Direction> {
        match self.kind() {
            Kind::Switch { search, .. } => Some(search),
            Kind::Index(d) | Kind::Torque(d) => Some(d),
            Kind::Current => None,
        }
    }

    const fn kind(self) -> Kind {
        const fn sw(target: Target, search: Direction) -> Kind {
            Kind::Switch { target, search }
        }
        use Direction::{Negative as N, Positive as P};
        use HomingMethod::*;
        match self {
            NegativeLimitIndex | NegativeLimit => sw(Target::NegativeLimit, N),
            PositiveLimitIndex | PositiveLimit => sw(Target::PositiveLimit, P),
            NegativeHomeIndex | NegativeHome | HomeIndexNegative | HomeNegative => sw(Target::Reference, N),
            PositiveHomeIndex | PositiveHome | HomeIndexPositive | HomePositive => sw(Target::Reference, P),
            IndexNegative => Kind::Index(N),
            IndexPositive => Kind::Index(P),
            CurrentPosition | CurrentPosition35 => Kind::Current,
            TorquePositive | TorquePositiveIndex => Kind::Torque(P),
            TorqueNegative | TorqueNegativeIndex => Kind::Torque(N),
        }
    }
}

/// Homing parameters, taken at the start edge (controlword bit 4); changes
/// during a homing run take effect at the next start. Units: increments.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HomingConfig {
    /// 6098h (A586) homing method code.
    pub method: i8,
    /// 6099h:01 (A587\[0\]) speed during search for switch, increments/s.
    pub fast_speed: f32,
    /// 6099h:02 (A587\[1\]) speed during search for zero, increments/s.
    pub slow_speed: f32,
    /// 609Ah (A588) homing acceleration, also the deceleration,
    /// increments/s².
    pub acceleration: f32,
    /// I44 referencing jerk, increments/s³ (`f32::INFINITY` = no limit).
    pub jerk: f32,
    /// 607Ch (A569) home offset: the position the reference point gets,
    /// increments.
    pub home_offset: i32,
    /// I43 = 1: after the reference event and the stop, position on 607Ch.
    pub move_to_home: bool,
    /// I53 index search offset, increments: an index pulse counts only this
    /// far (or farther) beyond where the index search starts (the switch
    /// edge, the mechanical stop or the start for 33/34).
    pub index_search_offset: u32,
    /// I29: how long the torque must be at the limit I28 without a break,
    /// ns (torque methods).
    pub torque_hold_ns: u64,
    /// Travel before the reference event after which the search fails
    /// ([`HomingError::TravelExceeded`]), increments; 0 = no limit.
    pub max_search_distance: u32,
    /// I30 = 2: the limit switch on the search side serves as the reference
    /// switch (C-086).
    pub limit_as_reference: bool,
}

impl Default for HomingConfig {
    /// Method 37, 1 rev/s fast, 0.1 rev/s slow, 10 rev/s², no jerk limit,
    /// home offset 0, no move to home, no index offset, 100 ms torque hold,
    /// no travel limit.
    fn default() -> Self {
        const REV: f32 = crate::INCREMENTS_PER_REVOLUTION as f32;
        Self {
            method: 37,
            fast_speed: REV,
            slow_speed: 0.1 * REV,
            acceleration: 10.0 * REV,
            jerk: f32::INFINITY,
            home_offset: 0,
            move_to_home: false,
            index_search_offset: 0,
            torque_hold_ns: 100_000_000,
            max_search_distance: 0,
            limit_as_reference: false,
        }
    }
}

/// One switch input: its level and, optionally, the position latched at its
/// change within this cycle (e.g. a touch probe on the input).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SwitchInput {
    /// The switch is active (after polarity).
    pub active: bool,
    /// Position latched at the switch's change in this cycle, increments;
    /// `None`: the actual position of the cycle that sees the change is
    /// used.
    pub edge: Option<i32>,
}

/// What the drive sees in one control cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct HomingInput {
    /// Actual position 6064h, increments.
    pub actual_position: i32,
    /// Negative hardware limit switch (I102).
    pub negative_limit: SwitchInput,
    /// Positive hardware limit switch (I101).
    pub positive_limit: SwitchInput,
    /// Reference switch (I103).
    pub reference_switch: SwitchInput,
    /// An index (zero) pulse was seen in this cycle, at this latched
    /// position, increments.
    pub index: Option<i32>,
    /// The torque/force is at or beyond the limit I28 in this cycle.
    pub torque_limit: bool,
    /// The axis stands still (actual velocity within the standstill window).
    pub standstill: bool,
    /// Controlword bit 4 "homing operation start" (level; edges are
    /// detected here).
    pub start: bool,
    /// Controlword bit 8 "halt" (level).
    pub halt: bool,
}

/// Why referencing failed (statusword bit 13).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HomingError {
    /// 6098h holds a code the drive does not support (C-060).
    InvalidMethod,
    /// A speed, 609Ah or I44 the method needs is not usable (≤ 0, not
    /// finite).
    InvalidParameters,
    /// Both hardware limit switches are active.
    BothLimits,
    /// A limit switch against the travel direction became active (C-084).
    LimitAgainstTravel,
    /// The second limit switch was reached while searching the switch: it
    /// is not there (after one reversal, C-083).
    SwitchNotFound,
    /// A limit switch was reached where the method expects none: while
    /// creeping off the switch, searching the index pulse or the mechanical
    /// stop.
    UnexpectedLimit,
    /// [`HomingConfig::max_search_distance`] travelled without a reference.
    TravelExceeded,
}

/// Homing state as statusword bits 13/12/10 show it (§6.5.9, C-059).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HomingStatus {
    /// 000: referencing in progress (also braking after a halt).
    InProgress,
    /// 001: referencing interrupted or not started.
    Interrupted,
    /// 010: reference set, referencing motion not yet finished.
    Attained,
    /// 011: referencing completed successfully.
    Completed,
    /// 100 (moving) / 110 (standstill): referencing error.
    Error {
        /// The cause.
        error: HomingError,
        /// Velocity = 0 (bit 12 set).
        standstill: bool,
    },
}

impl HomingStatus {
    /// Statusword bits 13, 12 and 10 (within [`SW_HOMING_MASK`]).
    pub const fn statusword_bits(self) -> u16 {
        match self {
            HomingStatus::InProgress => 0,
            HomingStatus::Interrupted => SW_TARGET_REACHED,
            HomingStatus::Attained => SW_HOMING_ATTAINED,
            HomingStatus::Completed => SW_HOMING_ATTAINED | SW_TARGET_REACHED,
            HomingStatus::Error {
                standstill: false, ..
            } => SW_HOMING_ERROR,
            HomingStatus::Error { standstill: true, .. } => SW_HOMING_ERROR | SW_HOMING_ATTAINED,
        }
    }
}

/// The reference event: the actual position at the reference point becomes
/// 607Ch (C-061).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReferenceEvent {
    /// Add this (wrapping) to the actual position, the position set-point
    /// and every stored position of the old coordinates, increments.
    pub shift: i32,
    /// The reference point (latched edge, index pulse or position) in the
    /// old coordinates, increments; `reference_position + shift` = 607Ch.
    pub reference_position: i32,
}

/// One control cycle's output.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HomingOutput {
    /// Position set-point, increments (new coordinates from the reference
    /// event on).
    pub position: i32,
    /// Velocity set-point (feedforward), increments/s.
    pub velocity: f32,
    /// Acceleration set-point (feedforward), increments/s².
    pub acceleration: f32,
    /// Homing bits of the statusword.
    pub status: HomingStatus,
    /// Set in the one cycle in which the reference is taken.
    pub reference: Option<ReferenceEvent>,
}

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
    /// Time the torque has been at the limit, ns.
    torque_ns: u64,
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
            torque_ns: 0,
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
        self.torque_ns = 0;
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
                self.torque_ns = if input.torque_limit {
                    self.torque_ns.saturating_add(u64::from(dt_ns))
                } else {
                    0
                };
                if input.torque_limit && self.torque_ns >= self.cfg.torque_hold_ns {
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
