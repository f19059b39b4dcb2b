//! What a homing run is configured with, reads each cycle and reports:
//! [`HomingConfig`], [`HomingInput`], [`HomingOutput`] and the status bits.

use super::*;

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
    /// I29: how long the torque must be at the limit I28 without a break
    /// (torque methods).
    pub torque_hold: Nanos,
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
            torque_hold: Nanos::from_ms(100),
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
