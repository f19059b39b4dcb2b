//! The homing methods (6098h, CiA 402 methods 1–37 and the drive's own)
//! decoded once: search direction, what is searched for, how it ends.

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

    pub(super) fn signf(self) -> f32 {
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
pub(super) enum Target {
    NegativeLimit,
    PositiveLimit,
    Reference,
}

/// What a method does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
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

    pub(super) const fn kind(self) -> Kind {
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
