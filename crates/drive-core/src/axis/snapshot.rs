//! One control cycle's view of an axis' set-point and configuration objects
//! (read from [`DriveObjects`] at the axis' window) and the actual values
//! written back.
//!
//! Every read falls back to the declared default's meaning when an object is
//! missing or unreadable, so a dictionary change never stops the control
//! cycle. Units are the objects' (increments, inc/s, inc/s², inc/s³, 0.1 % of
//! the rated torque, ms, µs).

use core::cell::Cell;

use crate::dictionary::{DriveObjects, Slot, Typed};
use crate::{AXIS_B_CIA402, AXIS_B_MANUFACTURER};
use motion::scaling::AxisScaling;

pub(crate) use crate::params::{
    A150, A213, A291, A310, A311, A340, A44, A66, B45, B46, B47, C31, C32, C40, F00, F06, G472, G475, I00,
    I02, I04, I10, I101, I12, I13, I18, I20, I21, I210, I22, I23, I25, I26, I28, I29, I30, I423, I425, I43,
    I44, I45, I46, I470, I471, I53, I87,
};

/// Entry `index`:`sub`, or 0 with `misses` counted: the dictionary declares
/// every entry the snapshot reads, with its default
/// (`snapshot_reads_only_declared_entries`), so no value of the
/// snapshot is written down twice.
fn read_or_miss(od: &DriveObjects, index: u16, sub: u8, misses: &Cell<u32>) -> i64 {
    od.get(index, sub).unwrap_or_else(|_| {
        misses.set(misses.get().saturating_add(1));
        0
    })
}

/// The object window of one axis: CiA 402 objects at +800h, per-axis
/// manufacturer parameters at +8000h for axis B.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Window {
    /// 0 = axis A, 1 = axis B.
    pub axis: u8,
}

impl Window {
    /// The axis' index of CiA 402 object `index` (axis-A numbering).
    pub const fn cia402(self, index: u16) -> u16 {
        if self.axis == 0 {
            index
        } else {
            index.wrapping_add(AXIS_B_CIA402)
        }
    }

    /// The axis' index of per-axis manufacturer parameter `index` (axis-A
    /// numbering).
    pub const fn manufacturer(self, index: u16) -> u16 {
        if self.axis == 0 {
            index
        } else {
            index.wrapping_add(AXIS_B_MANUFACTURER)
        }
    }

    /// Per-axis manufacturer entry `index`:`sub` ("SDO Info" numbering) of
    /// this axis; 0 when it cannot be read (counted in `misses`).
    pub fn param(self, od: &DriveObjects, index: u16, sub: u8, misses: &Cell<u32>) -> i64 {
        read_or_miss(od, self.manufacturer(index), sub, misses)
    }

    /// CiA 402 entry `index`:`sub` of this axis; 0 when it cannot be read
    /// (counted in `misses`).
    pub fn get(self, od: &DriveObjects, index: u16, sub: u8, misses: &Cell<u32>) -> i64 {
        read_or_miss(od, self.cia402(index), sub, misses)
    }

    /// Writes CiA 402 entry `index`:`sub` of this axis (clamped to the
    /// entry's type by the caller; errors are ignored: a missing actual
    /// value object must not stop the control cycle).
    pub fn put(self, od: &mut DriveObjects, index: u16, sub: u8, value: i64) {
        let _ = od.set(self.cia402(index), sub, value);
    }
}

/// The entries the axis' configuration writes (6076h, A291), resolved once
/// with their types. The entries the control cycle reads and writes every
/// cycle lie at fixed places in the axis' block of the RAM image instead
/// ([`crate::objects::cycle`]). `None`: the entry is not in RAM with the
/// type used (writes are dropped; `cyclic_slots_resolve_every_entry_on_both_axes`
/// keeps this from happening).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct CyclicSlots {
    pub rated_torque: Option<Typed<u32>>,
    /// A291 (global): the copy of 60C2h.
    pub a291: Option<Typed<u32>>,
}

impl CyclicSlots {
    /// The slots of axis `w`.
    pub fn resolve(od: &DriveObjects, w: Window) -> Self {
        Self {
            rated_torque: od.slot(w.cia402(0x6076), 0).and_then(Slot::typed),
            a291: od.slot(A291, 0).and_then(Slot::typed),
        }
    }

    /// Every slot, for the completeness test.
    #[cfg(test)]
    pub fn all(&self) -> [Option<u16>; 2] {
        [self.rated_torque.map(Typed::at), self.a291.map(Typed::at)]
    }
}

/// The objects the control cycle reads, one snapshot per cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Snapshot {
    /// 6040h controlword.
    pub controlword: u16,
    /// 6060h modes of operation.
    pub mode: i8,
    /// 607Ah target position, inc.
    pub target_position: i32,
    /// 60C1h:01 ip set-point, inc.
    pub ip_setpoint: i32,
    /// 60FFh target velocity, inc/s.
    pub target_velocity: i32,
    /// 6071h target torque, 0.1 %.
    pub target_torque: i16,
    /// 60B1h velocity offset, inc/s.
    pub velocity_offset: i32,
    /// 60B2h torque offset, 0.1 %.
    pub torque_offset: i16,
    /// 6072h max torque, 0.1 %.
    pub max_torque: u16,
    /// 6087h torque slope, 0.1 %/s (0 = step).
    pub torque_slope: u32,
    /// 6081h profile velocity, inc/s.
    pub profile_velocity: u32,
    /// 607Fh max profile velocity, inc/s.
    pub max_profile_velocity: u32,
    /// 6083h profile acceleration, inc/s².
    pub acceleration: u32,
    /// 6084h profile deceleration, inc/s².
    pub deceleration: u32,
    /// 6085h quick stop deceleration, inc/s².
    pub quick_stop_deceleration: u32,
    /// 60A4h:01 profile jerk, inc/s³ (0 = no jerk limit).
    pub jerk: u32,
    /// 60F2h positioning option code.
    pub positioning_option: u16,
    /// 605Ah quick stop option code.
    pub quick_stop_option: i16,
    /// 605Eh fault reaction option code.
    pub fault_reaction_option: i16,
    /// 6065h following error window, inc (`u32::MAX` = off).
    pub following_error_window: u32,
    /// 6066h following error time out, ms.
    pub following_error_timeout_ms: u16,
    /// I22 target window, inc.
    pub target_window: u32,
    /// I21 position error limit, inc (`u32::MAX` = off).
    pub position_error_limit: u32,
    /// I23 position controller dead band, inc.
    pub dead_band: u32,
    /// 607Dh:01 / :02 software position limits, inc.
    pub software_min: i32,
    /// 607Dh:02.
    pub software_max: i32,
    /// 607Eh polarity (bit 7: position polarity).
    pub polarity: u8,
    /// 6098h homing method.
    pub homing_method: i8,
    /// 6099h:01 speed during search for switch, inc/s.
    pub homing_fast: u32,
    /// 6099h:02 speed during search for zero, inc/s.
    pub homing_slow: u32,
    /// 609Ah homing acceleration, inc/s².
    pub homing_acceleration: u32,
    /// 607Ch home offset, inc.
    pub home_offset: i32,
    /// 60B8h touch probe function.
    pub probe_function: u16,
    /// 60D0h:01 / :02 touch probe sources (1 = input 1, 2 = input 2).
    pub probe_source: [i16; 2],
    /// 6042h vl target velocity, rpm.
    pub vl_target: i16,
    /// 6046h:01 / :02 vl velocity min / max amount, rpm.
    pub vl_min: u32,
    /// 6046h:02.
    pub vl_max: u32,
    /// 6048h vl acceleration: delta speed (rpm), delta time (s).
    pub vl_acceleration: (u32, u16),
    /// 6049h vl deceleration.
    pub vl_deceleration: (u32, u16),
    /// 604Ah vl quick stop.
    pub vl_quick_stop: (u32, u16),
    /// A150 application (control) cycle, µs.
    pub control_cycle_us: u16,
    /// 60C2h:01 interpolation time period value.
    pub period_value: u8,
    /// 60C2h:02 interpolation time index.
    pub period_index: i8,
    /// A340 velocity override, % (pp, vl, pv).
    pub override_percent: u16,
    /// A66 sources of the A67 bits (index << 16 | sub << 8 | bit, 0 = none).
    pub a66: [u32; 16],
    /// Whether any A66 element names a source (else A67 is 0 without a look).
    pub a66_used: bool,
    /// The cascade's gains: I20 Kv (0.1 /s), C31 Kp (µN·m·s/rad), C32 Ti
    /// (µs).
    pub gains: (u16, u32, u32),
    /// The identified mechanics (B44): B45 inertia (10⁻⁷ kg·m², 0 = not
    /// identified), B46 Coulomb friction (µN·m), B47 viscous friction
    /// (nN·m·s/rad).
    pub mechanics: (u32, u32, u32),
    /// Jog: I12 velocity (user units/s), I13 acceleration, I45
    /// deceleration, I18 jerk (user units/s², /s³; 0 = none).
    pub jog: [u32; 4],
    /// I26 jog control type (1 = position control).
    pub i26: u8,
    /// Homing: I28 torque limit (0.1 % of 6076h), I29 time at it (ms).
    pub homing_torque: (u16, u16),
    /// I30 reference switch type (2 = the limit switches), I43 move to
    /// the reference position after homing (1 = on).
    pub i30_i43: (u8, u8),
    /// I53 index search offset (user position units).
    pub i53: u32,
    /// Interpolation: I25 speed feedforward (%), I425 its interpolation,
    /// I423 maximum extrapolation (ms).
    pub interpolation: (u8, u8, u16),
    /// I87 time in the position window (ms).
    pub i87: u16,
    /// I10 maximal speed and C40 velocity window (user units/s), I44
    /// referencing jerk (user units/s³, 0 = none).
    pub speeds: [u32; 3],
    /// A44 quick stop on the loss of A60 (1 = active).
    pub a44: u8,
    /// F00 brake control (1 = active), F06 release override (1 = active).
    pub brake: (u8, u8),
    /// I470 following error reaction (1 = fault), I471 set-value
    /// monitoring (1 = on).
    pub monitors: (u8, u8),
    /// I00 position range (1 = endless).
    pub i00: u8,
    /// I04 permitted direction (0 both, 1 positive, 2 negative).
    pub i04: u8,
    /// G472 / G475 velocity limits of the torque modes, 0.1 % of I10
    /// (C-039).
    pub torque_mode_speed_limit: [u16; 2],
    /// I02 position encoder (0 = motor encoder).
    pub i02: u8,
    /// I46 reference retaining (5 = direct absolute).
    pub i46: u8,
    /// I101, I102, I103: 0 off, 1 input, 2 parameter I210.
    pub switch_source: [u8; 3],
    /// I210 application control word.
    pub i210: u16,
    /// 6091h:01/:02 gear ratio (motor, shaft revolutions).
    pub gear: (u32, u32),
    /// 6092h:01/:02 feed constant (feed, shaft revolutions).
    pub feed: (u32, u32),
    /// 607Bh:02 revolution length of an endless axis, user units (C-111).
    pub modulo_length: i32,
    /// 607Ah and 60C1h:01 as sent, user units (not converted by
    /// [`Snapshot::to_increments`]; endless axes unwrap them).
    pub target_position_user: i32,
    /// 60C1h:01 as sent.
    pub ip_setpoint_user: i32,
    /// Decimal places of velocities (A310) and of accelerations and jerk
    /// (A311) when A213[0] = 0 "integer with decimal places"; (0, 0) native.
    pub decimals: (u8, u8),
    /// The motor data (group B, 6073h/6075h/6080h, U10/U11), prepared.
    pub motor: super::MotorData,
}

fn sat<T: TryFrom<i64> + Copy>(v: i64, lo: T, hi: T) -> T {
    T::try_from(v).unwrap_or(if v < 0 { lo } else { hi })
}

impl super::Axis {
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
}

impl Snapshot {
    /// Reads the cyclic set-points of axis `w` again (the objects of
    /// `CYCLIC_SETPOINTS` in the dictionary, whose writes do not move its
    /// configuration generation) from axis `axis`' block; the rest of the
    /// snapshot is kept.
    pub fn refresh_setpoints(&mut self, od: &DriveObjects, axis: u8) {
        use crate::objects::cycle as f;
        self.controlword = od.cycle_read(axis, f::CONTROLWORD);
        self.mode = od.cycle_read(axis, f::MODE);
        self.target_position = od.cycle_read(axis, f::TARGET_POSITION);
        self.target_position_user = self.target_position;
        self.ip_setpoint = od.cycle_read(axis, f::IP_SETPOINT);
        self.ip_setpoint_user = self.ip_setpoint;
        self.target_velocity = od.cycle_read(axis, f::TARGET_VELOCITY);
        self.target_torque = od.cycle_read(axis, f::TARGET_TORQUE);
        self.velocity_offset = od.cycle_read(axis, f::VELOCITY_OFFSET);
        self.torque_offset = od.cycle_read(axis, f::TORQUE_OFFSET);
        self.probe_function = od.cycle_read(axis, f::PROBE_FUNCTION);
        self.vl_target = od.cycle_read(axis, f::VL_TARGET);
        self.i210 = od.cycle_read(axis, f::I210);
    }

    /// Reads the snapshot of axis `w`.
    pub fn read(od: &DriveObjects, w: Window) -> Self {
        Self::read_counting(od, w).0
    }

    /// [`read`](Self::read) and how many entries could not be read (they
    /// count as 0; none with the drive's dictionary).
    pub fn read_counting(od: &DriveObjects, w: Window) -> (Self, u32) {
        let misses = Cell::new(0);
        let m = &misses;
        let i32_ = |index: u16, sub: u8| sat(w.get(od, index, sub, m), i32::MIN, i32::MAX);
        let u32_ = |index: u16, sub: u8| sat(w.get(od, index, sub, m), 0u32, u32::MAX);
        let u16_ = |index: u16, sub: u8| sat(w.get(od, index, sub, m), 0u16, u16::MAX);
        let i16_ = |index: u16, sub: u8| sat(w.get(od, index, sub, m), i16::MIN, i16::MAX);
        let i8_ = |index: u16, sub: u8| sat(w.get(od, index, sub, m), i8::MIN, i8::MAX);
        let u8_ = |index: u16, sub: u8| sat(w.get(od, index, sub, m), 0u8, u8::MAX);
        let ramp = |index: u16| (u32_(index, 1), u16_(index, 2));
        let snapshot = Snapshot {
            controlword: u16_(0x6040, 0),
            mode: i8_(0x6060, 0),
            target_position: i32_(0x607A, 0),
            ip_setpoint: i32_(0x60C1, 1),
            target_velocity: i32_(0x60FF, 0),
            target_torque: i16_(0x6071, 0),
            velocity_offset: i32_(0x60B1, 0),
            torque_offset: i16_(0x60B2, 0),
            max_torque: u16_(0x6072, 0),
            torque_slope: u32_(0x6087, 0),
            profile_velocity: u32_(0x6081, 0),
            max_profile_velocity: u32_(0x607F, 0),
            acceleration: u32_(0x6083, 0),
            deceleration: u32_(0x6084, 0),
            quick_stop_deceleration: u32_(0x6085, 0),
            jerk: u32_(0x60A4, 1),
            positioning_option: u16_(0x60F2, 0),
            quick_stop_option: i16_(0x605A, 0),
            fault_reaction_option: i16_(0x605E, 0),
            following_error_window: u32_(0x6065, 0),
            following_error_timeout_ms: u16_(0x6066, 0),
            target_window: sat(w.param(od, I22, 0, m), 0u32, u32::MAX),
            position_error_limit: sat(w.param(od, I21, 0, m), 0u32, u32::MAX),
            dead_band: sat(w.param(od, I23, 0, m), 0u32, u32::MAX),
            software_min: i32_(0x607D, 1),
            software_max: i32_(0x607D, 2),
            polarity: u8_(0x607E, 0),
            homing_method: i8_(0x6098, 0),
            homing_fast: u32_(0x6099, 1),
            homing_slow: u32_(0x6099, 2),
            homing_acceleration: u32_(0x609A, 0),
            home_offset: i32_(0x607C, 0),
            probe_function: u16_(0x60B8, 0),
            probe_source: [i16_(0x60D0, 1), i16_(0x60D0, 2)],
            vl_target: i16_(0x6042, 0),
            vl_min: u32_(0x6046, 1),
            vl_max: u32_(0x6046, 2),
            vl_acceleration: ramp(0x6048),
            vl_deceleration: ramp(0x6049),
            vl_quick_stop: ramp(0x604A),
            control_cycle_us: sat(read_or_miss(od, A150, 0, m), 0u16, u16::MAX),
            period_value: u8_(0x60C2, 1),
            period_index: i8_(0x60C2, 2),
            override_percent: sat(w.param(od, A340, 0, m), 0u16, u16::MAX),
            a66: core::array::from_fn(|k| sat(w.param(od, A66, k as u8 + 1, m), 0u32, u32::MAX)),
            a66_used: (1..=16).any(|sub| w.param(od, A66, sub, m) != 0),
            jog: [
                sat(w.param(od, I12, 0, m), 0u32, u32::MAX),
                sat(w.param(od, I13, 0, m), 0u32, u32::MAX),
                sat(w.param(od, I45, 0, m), 0u32, u32::MAX),
                sat(w.param(od, I18, 0, m), 0u32, u32::MAX),
            ],
            i26: sat(w.param(od, I26, 0, m), 0u8, u8::MAX),
            homing_torque: (
                sat(w.param(od, I28, 0, m), 0u16, u16::MAX),
                sat(w.param(od, I29, 0, m), 0u16, u16::MAX),
            ),
            i30_i43: (
                sat(w.param(od, I30, 0, m), 0u8, u8::MAX),
                sat(w.param(od, I43, 0, m), 0u8, u8::MAX),
            ),
            i53: sat(w.param(od, I53, 0, m), 0u32, u32::MAX),
            interpolation: (
                sat(w.param(od, I25, 0, m), 0u8, u8::MAX),
                sat(w.param(od, I425, 0, m), 0u8, u8::MAX),
                sat(w.param(od, I423, 0, m), 0u16, u16::MAX),
            ),
            i87: sat(w.param(od, I87, 0, m), 0u16, u16::MAX),
            speeds: [
                sat(w.param(od, I10, 0, m), 0u32, u32::MAX),
                sat(w.param(od, C40, 0, m), 0u32, u32::MAX),
                sat(w.param(od, I44, 0, m), 0u32, u32::MAX),
            ],
            a44: sat(w.param(od, A44, 0, m), 0u8, u8::MAX),
            brake: (
                sat(w.param(od, F00, 0, m), 0u8, u8::MAX),
                sat(w.param(od, F06, 0, m), 0u8, u8::MAX),
            ),
            monitors: (
                sat(w.param(od, I470, 0, m), 0u8, u8::MAX),
                sat(w.param(od, I471, 0, m), 0u8, u8::MAX),
            ),
            i00: sat(w.param(od, I00, 0, m), 0u8, u8::MAX),
            i04: sat(w.param(od, I04, 0, m), 0u8, u8::MAX),
            gains: (
                sat(w.param(od, I20, 0, m), 0u16, u16::MAX),
                sat(w.param(od, C31, 0, m), 0u32, u32::MAX),
                sat(w.param(od, C32, 0, m), 0u32, u32::MAX),
            ),
            mechanics: (
                sat(w.param(od, B45, 0, m), 0u32, u32::MAX),
                sat(w.param(od, B46, 0, m), 0u32, u32::MAX),
                sat(w.param(od, B47, 0, m), 0u32, u32::MAX),
            ),
            torque_mode_speed_limit: [
                sat(w.param(od, G472, 0, m), 0u16, u16::MAX),
                sat(w.param(od, G475, 0, m), 0u16, u16::MAX),
            ],
            i02: sat(w.param(od, I02, 0, m), 0u8, u8::MAX),
            i46: sat(w.param(od, I46, 0, m), 0u8, u8::MAX),
            switch_source: [
                sat(w.param(od, I101, 0, m), 0u8, u8::MAX),
                sat(w.param(od, I101 + 1, 0, m), 0u8, u8::MAX),
                sat(w.param(od, I101 + 2, 0, m), 0u8, u8::MAX),
            ],
            i210: sat(w.param(od, I210, 0, m), 0u16, u16::MAX),
            gear: (u32_(0x6091, 1), u32_(0x6091, 2)),
            feed: (u32_(0x6092, 1), u32_(0x6092, 2)),
            modulo_length: i32_(0x607B, 2),
            target_position_user: i32_(0x607A, 0),
            ip_setpoint_user: i32_(0x60C1, 1),
            decimals: if read_or_miss(od, A213, 1, m) == 0 {
                (
                    sat(w.param(od, A310, 0, m), 0u8, 9),
                    sat(w.param(od, A311, 0, m), 0u8, 9),
                )
            } else {
                (0, 0)
            },
            motor: super::MotorData::read(od, w, m),
        };
        (snapshot, misses.get())
    }

    /// The scaling of 6091h/6092h (polarity is applied separately); the
    /// increments themselves when a factor is 0.
    pub fn scaling(&self) -> AxisScaling {
        AxisScaling::new(self.gear.0, self.gear.1, self.feed.0, self.feed.1, 0)
            .unwrap_or(AxisScaling::INCREMENTAL)
    }

    /// 10^A310 and 10^A311 (C-142): velocity / acceleration objects count
    /// in user units / 10^decimals; 1 in native scaling.
    pub fn decimal_factors(&self) -> (f64, f64) {
        let p = |d: u8| (0..d).fold(1.0f64, |f, _| f * 10.0);
        (p(self.decimals.0), p(self.decimals.1))
    }

    /// Whether the objects are in increments already (identity scaling, no
    /// decimals): [`to_increments`](Self::to_increments) changes nothing.
    pub fn in_increments(&self, s: &AxisScaling) -> bool {
        *s == AxisScaling::INCREMENTAL && self.decimals == (0, 0)
    }

    /// The snapshot with every position, velocity, acceleration and jerk
    /// object turned from user units (6091h/6092h, C-109; decimals A310/A311
    /// with A213 = 0, C-142) into increments, the unit the axis works in.
    pub fn to_increments(self, s: &AxisScaling) -> Self {
        if self.in_increments(s) {
            return self;
        }
        let (fv, fa) = self.decimal_factors();
        let pos = |u: i32| {
            s.to_increments(i64::from(u))
                .map_or(if u < 0 { i32::MIN } else { i32::MAX }, |v| v as i32)
        };
        let k = s.user_per_increment().abs();
        // half away from zero; the casts saturate
        let round = |x: f64| if x >= 0.0 { x + 0.5 } else { x - 0.5 };
        let rate = |u: i32| round(f64::from(u) / (k * fv)) as i32;
        let vel = |u: u32| round(f64::from(u) / (k * fv)) as u32;
        let acc = |u: u32| round(f64::from(u) / (k * fa)) as u32;
        let mag = |u: u32| round(f64::from(u) / k) as u32;
        Snapshot {
            target_position: pos(self.target_position),
            ip_setpoint: pos(self.ip_setpoint),
            software_min: pos(self.software_min),
            software_max: pos(self.software_max),
            home_offset: pos(self.home_offset),
            target_velocity: rate(self.target_velocity),
            velocity_offset: rate(self.velocity_offset),
            profile_velocity: vel(self.profile_velocity),
            max_profile_velocity: vel(self.max_profile_velocity),
            acceleration: acc(self.acceleration),
            deceleration: acc(self.deceleration),
            quick_stop_deceleration: acc(self.quick_stop_deceleration),
            jerk: acc(self.jerk),
            homing_fast: vel(self.homing_fast),
            homing_slow: vel(self.homing_slow),
            homing_acceleration: acc(self.homing_acceleration),
            following_error_window: if self.following_error_window == u32::MAX {
                u32::MAX
            } else {
                mag(self.following_error_window)
            },
            target_window: mag(self.target_window),
            position_error_limit: if self.position_error_limit == u32::MAX {
                u32::MAX
            } else {
                mag(self.position_error_limit)
            },
            dead_band: mag(self.dead_band),
            i53: mag(self.i53),
            speeds: {
                let [i10, c40, i44] = self.speeds;
                [vel(i10), vel(c40), acc(i44)]
            },
            jog: {
                let [v, a, d, j] = self.jog;
                [vel(v), acc(a), acc(d), acc(j)]
            },
            ..self
        }
    }
}
