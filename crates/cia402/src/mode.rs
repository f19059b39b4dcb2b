//! Modes of operation 6060h/6061h and supported drive modes 6502h (spec §6.1, §6.2).

/// A mode of operation (6060h values).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Mode {
    /// −1: jog (Pilz-specific).
    Jog,
    /// 0: no mode (MC_DoNothing, no motion generated).
    NoMode,
    /// 1: profile position (pp).
    ProfilePosition,
    /// 2: velocity mode (vl).
    Velocity,
    /// 3: profile velocity (pv).
    ProfileVelocity,
    /// 4: profile torque (pt).
    ProfileTorque,
    /// 6: homing.
    Homing,
    /// 7: interpolated position (ip).
    InterpolatedPosition,
    /// 8: cyclic synchronous position (csp).
    CyclicPosition,
    /// 9: cyclic synchronous velocity (csv).
    CyclicVelocity,
    /// 10: cyclic synchronous torque (cst).
    CyclicTorque,
}

/// Which side generates the set-points (spec §1, §6.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ModeClass {
    /// ip, csp, csv, cst: the master sends cyclic set-points.
    ControllerBased,
    /// pp, vl, pv, pt: the drive's motion core generates the profile.
    DriveBased,
    /// no mode, homing and jog: not restricted by the switching condition.
    Other,
}

/// Why a requested mode was not taken over.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ModeError {
    /// The value is not a mode of 6060h, or the mode is not in 6502h: the old mode stays.
    Unsupported(i8),
}

/// 6502h bit for jog (−1). CiA 402 leaves bits 16..31 to the manufacturer; bit 16 is our
/// choice.
pub const SUPPORTED_JOG_BIT: u32 = 1 << 16;

/// 6502h supported drive modes of this device: pp, vl, pv, pt, homing, ip, csp, csv, cst
/// (bits 0, 1, 2, 3, 5, 6, 7, 8, 9) and jog (bit 16).
pub const SUPPORTED_DRIVE_MODES: u32 = 0x0000_03EF | SUPPORTED_JOG_BIT;

impl Mode {
    /// The default of 6060h (A541): 8, csp (spec §6.1).
    pub const DEFAULT: Mode = Mode::CyclicPosition;

    /// All modes.
    pub const ALL: [Mode; 11] = [
        Mode::Jog,
        Mode::NoMode,
        Mode::ProfilePosition,
        Mode::Velocity,
        Mode::ProfileVelocity,
        Mode::ProfileTorque,
        Mode::Homing,
        Mode::InterpolatedPosition,
        Mode::CyclicPosition,
        Mode::CyclicVelocity,
        Mode::CyclicTorque,
    ];

    /// The mode with the 6060h value `v`, if there is one (5 and values outside −1..10 are
    /// not modes).
    pub const fn from_i8(v: i8) -> Option<Mode> {
        match v {
            -1 => Some(Mode::Jog),
            0 => Some(Mode::NoMode),
            1 => Some(Mode::ProfilePosition),
            2 => Some(Mode::Velocity),
            3 => Some(Mode::ProfileVelocity),
            4 => Some(Mode::ProfileTorque),
            6 => Some(Mode::Homing),
            7 => Some(Mode::InterpolatedPosition),
            8 => Some(Mode::CyclicPosition),
            9 => Some(Mode::CyclicVelocity),
            10 => Some(Mode::CyclicTorque),
            _ => None,
        }
    }

    /// The 6060h/6061h value.
    pub const fn code(self) -> i8 {
        match self {
            Mode::Jog => -1,
            Mode::NoMode => 0,
            Mode::ProfilePosition => 1,
            Mode::Velocity => 2,
            Mode::ProfileVelocity => 3,
            Mode::ProfileTorque => 4,
            Mode::Homing => 6,
            Mode::InterpolatedPosition => 7,
            Mode::CyclicPosition => 8,
            Mode::CyclicVelocity => 9,
            Mode::CyclicTorque => 10,
        }
    }

    /// The class of the mode for the switching condition.
    pub const fn class(self) -> ModeClass {
        match self {
            Mode::InterpolatedPosition | Mode::CyclicPosition | Mode::CyclicVelocity | Mode::CyclicTorque => {
                ModeClass::ControllerBased
            }
            Mode::ProfilePosition | Mode::Velocity | Mode::ProfileVelocity | Mode::ProfileTorque => {
                ModeClass::DriveBased
            }
            Mode::NoMode | Mode::Homing | Mode::Jog => ModeClass::Other,
        }
    }

    /// The mode's bit in 6502h; 0 for "no mode", which 6502h does not list.
    pub const fn supported_bit(self) -> u32 {
        match self {
            Mode::Jog => SUPPORTED_JOG_BIT,
            Mode::NoMode => 0,
            Mode::ProfilePosition => 1 << 0,
            Mode::Velocity => 1 << 1,
            Mode::ProfileVelocity => 1 << 2,
            Mode::ProfileTorque => 1 << 3,
            Mode::Homing => 1 << 5,
            Mode::InterpolatedPosition => 1 << 6,
            Mode::CyclicPosition => 1 << 7,
            Mode::CyclicVelocity => 1 << 8,
            Mode::CyclicTorque => 1 << 9,
        }
    }

    /// Checks a 6060h value against the supported modes (6502h bits); "no mode" (0) is
    /// always accepted. The OD layer can call this to refuse an SDO write up front.
    pub const fn check(v: i8, supported: u32) -> Result<Mode, ModeError> {
        match Mode::from_i8(v) {
            Some(Mode::NoMode) => Ok(Mode::NoMode),
            Some(m) if m.supported_bit() & supported != 0 => Ok(m),
            _ => Err(ModeError::Unsupported(v)),
        }
    }

    /// `true` if changing from `self` to `to` needs standstill (spec §6.2): a change
    /// between a controller-based and a drive-based mode, in either direction.
    pub fn switch_needs_standstill(self, to: Mode) -> bool {
        matches!(
            (self.class(), to.class()),
            (ModeClass::ControllerBased, ModeClass::DriveBased)
                | (ModeClass::DriveBased, ModeClass::ControllerBased)
        )
    }

    /// Whether controlword bit 8 (halt) acts in this mode: pp, pv and homing (`[std]`,
    /// spec §5.2).
    pub const fn halt_applies(self) -> bool {
        matches!(self, Mode::ProfilePosition | Mode::ProfileVelocity | Mode::Homing)
    }
}
