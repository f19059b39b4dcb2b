//! PROFIenergy on the drive (P-015, P-016): the drive's side of
//! [`profinet::profienergy`]. The record protocol is the PROFINET crate's;
//! here are the switch and what a pause means.
//!
//! - A275 (PROFIenergy active, default 0) switches it: with 0 record 0x80A0
//!   is refused with "invalid index" (as any record the device does not
//!   have), and a running pause ends at once.
//! - The one energy-saving mode, PE_Mode_ID 1 "power stage off": both axes'
//!   power stage supply is switched off ([`PnDrive::control_cycle`] passes
//!   the axes `supply_ok = false`, so neither can be switched on; E47 shows
//!   cause 2, supply).
//! - Start_Pause is accepted only while neither axis has its power stage on
//!   (no axis enabled, braking or in a fault reaction): a drive must not
//!   drop a moving or holding axis. Otherwise the answer is the profile's
//!   error 0x53 "no switch to energy saving mode because of state operate".
//! - The pause ends with End_Pause, with the end of the AR that paused (the
//!   controller that would end it is gone), and when A275 is set to 0.
//! - Times ([`MODE_TIMES`]): the supply is switched in one control cycle, so
//!   Time_to_Pause and Regular_Time_to_operate are 0 ms, no minimum pause or
//!   stay, no maximum stay. Power and energy are not measured (0.0); the
//!   measurement services are not offered.

use profinet::profienergy::{ModeTimes, PeApplication, WithProfiEnergy};

#[cfg(doc)]
use crate::PnDrive;

/// The times of the power-stage-off mode, ms.
pub const MODE_TIMES: ModeTimes = ModeTimes {
    min_pause: 0,
    to_pause: 0,
    to_operate: 0,
    min_stay: 0,
    max_stay: 0xFFFF_FFFF,
};

/// The drive as PROFIenergy sees it: a snapshot [`PnDrive`] refreshes
/// before every frame and timer.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DriveEnergy {
    /// A275 = 1.
    pub enabled: bool,
    /// Neither axis has its power stage on.
    pub idle: bool,
}

impl PeApplication for DriveEnergy {
    fn enabled(&self) -> bool {
        self.enabled
    }

    fn may_pause(&self) -> bool {
        self.idle
    }

    fn mode(&self) -> ModeTimes {
        MODE_TIMES
    }
}

/// The records the drive's device serves beyond the CM's own: PROFIenergy,
/// the PROFIdrive parameter record 0xB02E ([`crate::bmp_record`]), the
/// scope's trace ([`crate::scope_record`]), then the application's `H`.
pub type PnRecords<H> =
    WithProfiEnergy<DriveEnergy, crate::bmp_record::WithBmp<crate::scope_record::WithScope<H>>>;
