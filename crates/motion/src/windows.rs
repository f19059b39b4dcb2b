//! Monitoring windows: following error, target reached, velocity window and
//! standstill (spec §6.2, §6.5.2, §6.5.5, §6.5.7, §7; C-027, C-036, C-043,
//! C-048, C-056).
//!
//! - [`FollowingErrorMonitor`]: 6065h (A546) window, 6066h (A547) timeout →
//!   statusword bit 13 in csp/pp, optionally the fault event
//!   [`FOLLOWING_ERROR_EVENT`].
//! - [`TargetReachedMonitor`]: I22 (6067h) position window, I87 (6068h) time
//!   → statusword bit 10 in pp.
//! - [`VelocityWindowMonitor`]: C40 (606Dh) velocity window, 606Eh time →
//!   pv statusword bits 10, 12, 13.
//! - [`is_standstill`]: I199 = |actual velocity| < C40, the `standstill`
//!   input of the device control.
//!
//! Positions are increments (wrap-around differences), velocities
//! increments/s, times [`Nanos`] (monotonic `now` arguments).

use crate::Event;
use nanos::Nanos;

/// Fault event "Following error" (event 54, cause 1), raised by
/// [`FollowingErrorMonitor`] when configured to fault (the spec names no
/// number; 54 is the device family's following-error event).
pub const FOLLOWING_ERROR_EVENT: Event = Event { number: 54, cause: 1 };

/// Fault event "Position error limit" (event 54, cause 2), raised by
/// [`FollowingErrorMonitor`] the cycle |following error| passes I21
/// (PROFINET PNU 1273, P-160): the second, larger window, without a time.
pub const POSITION_ERROR_LIMIT_EVENT: Event = Event { number: 54, cause: 2 };

/// 6066h following error timeout / 6068h position window time (ms, UINT16)
/// as [`Nanos`].
pub const fn ms_to_ns(ms: u16) -> Nanos {
    Nanos::from_ms(ms as u64)
}

/// Configuration of the following-error monitor.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FollowingErrorConfig {
    /// 6065h (A546) following error window in increments; `u32::MAX`
    /// switches the monitoring off (`[std]`).
    pub window_inc: u32,
    /// 6066h (A547) following error timeout (see [`ms_to_ns`]).
    pub timeout: Nanos,
    /// Raise [`FOLLOWING_ERROR_EVENT`] (fault) when bit 13 comes on;
    /// `false` = statusword bit 13 only (`[std]`).
    pub fault: bool,
    /// I21 position error limit in increments: beyond it
    /// [`POSITION_ERROR_LIMIT_EVENT`] is raised at once (always a fault);
    /// `u32::MAX` switches it off.
    pub limit_inc: u32,
}

impl Default for FollowingErrorConfig {
    /// Window 1/4 revolution (262 144 increments), timeout 10 ms, no fault.
    fn default() -> Self {
        Self {
            window_inc: crate::INCREMENTS_PER_REVOLUTION / 4,
            timeout: ms_to_ns(10),
            fault: false,
            limit_inc: u32::MAX,
        }
    }
}

/// One cycle's result of the [`FollowingErrorMonitor`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FollowingErrorStatus {
    /// 60F4h following error actual value: set-point − actual, increments.
    pub error_inc: i32,
    /// Statusword bit 13 (csp, pp): |error| > 6065h for at least 6066h.
    pub following_error: bool,
    /// [`FOLLOWING_ERROR_EVENT`] on the cycle bit 13 comes on, if configured.
    pub event: Option<Event>,
    /// [`POSITION_ERROR_LIMIT_EVENT`] on the cycle the error passes the
    /// limit (I21).
    pub limit_event: Option<Event>,
}

/// Following-error monitoring of csp and pp (C-036).
#[derive(Debug, Clone)]
pub struct FollowingErrorMonitor {
    config: FollowingErrorConfig,
    /// Time the error left the window.
    outside_since: Option<Nanos>,
    active: bool,
    /// |error| beyond I21 in the last update.
    beyond_limit: bool,
}

impl FollowingErrorMonitor {
    /// A monitor with `config`, bit 13 off.
    pub const fn new(config: FollowingErrorConfig) -> Self {
        Self {
            config,
            outside_since: None,
            active: false,
            beyond_limit: false,
        }
    }

    /// Replaces the configuration (6065h/6066h written); keeps the state.
    pub fn set_config(&mut self, config: FollowingErrorConfig) {
        self.config = config;
    }

    /// Clears bit 13 and the timer (mode change, enable, fault reset).
    pub fn reset(&mut self) {
        self.outside_since = None;
        self.active = false;
        self.beyond_limit = false;
    }

    /// Bit 13 as of the last update.
    pub const fn is_active(&self) -> bool {
        self.active
    }

    /// Evaluates one cycle at `now`. Bit 13 comes on once the error has
    /// stayed outside the window for at least the timeout and goes off as
    /// soon as the error is back inside.
    pub fn update(
        &mut self,
        position_setpoint_inc: i32,
        actual_position_inc: i32,
        now: Nanos,
    ) -> FollowingErrorStatus {
        let error_inc = position_setpoint_inc.wrapping_sub(actual_position_inc);
        let outside = self.config.window_inc != u32::MAX && error_inc.unsigned_abs() > self.config.window_inc;
        let was_active = self.active;
        if outside {
            let since = *self.outside_since.get_or_insert(now);
            self.active = now.since(since) >= self.config.timeout;
        } else {
            self.outside_since = None;
            self.active = false;
        }
        let event = (self.active && !was_active && self.config.fault).then_some(FOLLOWING_ERROR_EVENT);
        let was_beyond = self.beyond_limit;
        self.beyond_limit =
            self.config.limit_inc != u32::MAX && error_inc.unsigned_abs() > self.config.limit_inc;
        let limit_event = (self.beyond_limit && !was_beyond).then_some(POSITION_ERROR_LIMIT_EVENT);
        FollowingErrorStatus {
            error_inc,
            following_error: self.active,
            event,
            limit_event,
        }
    }
}

/// Configuration of the position window (target reached in pp).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PositionWindowConfig {
    /// I22 (6067h) position window in increments; `u32::MAX` switches the
    /// window off: target reached as soon as the set-point is at the target
    /// (`[std]`).
    pub window_inc: u32,
    /// I87 (6068h) time the actual position must stay in the window.
    pub time: Nanos,
}

impl Default for PositionWindowConfig {
    /// Window 1/360 revolution (2 912 increments), time 0.
    fn default() -> Self {
        Self {
            window_inc: crate::INCREMENTS_PER_REVOLUTION / 360,
            time: Nanos::ZERO,
        }
    }
}

/// Target reached of pp, statusword bit 10 (C-048).
#[derive(Debug, Clone)]
pub struct TargetReachedMonitor {
    config: PositionWindowConfig,
    inside_since: Option<Nanos>,
}

impl TargetReachedMonitor {
    /// A monitor with `config`.
    pub const fn new(config: PositionWindowConfig) -> Self {
        Self {
            config,
            inside_since: None,
        }
    }

    /// Replaces the configuration; keeps the state.
    pub fn set_config(&mut self, config: PositionWindowConfig) {
        self.config = config;
    }

    /// Restarts the window time (e.g. on a new set-point).
    pub fn reset(&mut self) {
        self.inside_since = None;
    }

    /// Bit 10 at `now`: the profile has finished at the target
    /// (`setpoint_done`, e.g. [`ProfileSample::done`](crate::ProfileSample))
    /// and |target − actual| ≤ I22 has held for at least I87.
    pub fn update(
        &mut self,
        target_inc: i32,
        actual_position_inc: i32,
        setpoint_done: bool,
        now: Nanos,
    ) -> bool {
        if !setpoint_done {
            self.inside_since = None;
            return false;
        }
        if self.config.window_inc == u32::MAX {
            return true;
        }
        let inside = target_inc.wrapping_sub(actual_position_inc).unsigned_abs() <= self.config.window_inc;
        held(&mut self.inside_since, inside, now, self.config.time)
    }
}

/// Configuration of the velocity window of pv.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VelocityWindowConfig {
    /// C40 (606Dh) velocity window in increments/s.
    pub window_inc_per_s: f32,
    /// 606Eh velocity window time.
    pub time: Nanos,
}

impl Default for VelocityWindowConfig {
    /// Window 0.1 rev/s (104 857.6 increments/s), time 0.
    fn default() -> Self {
        Self {
            window_inc_per_s: 0.1 * crate::INCREMENTS_PER_REVOLUTION as f32,
            time: Nanos::ZERO,
        }
    }
}

/// One cycle's pv statusword bits (C-056).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ProfileVelocityStatus {
    /// Bit 10 target reached: |60FFh target − actual| ≤ C40 for ≥ 606Eh.
    pub target_reached: bool,
    /// Bit 12 "speed": the actual velocity is zero (|actual| < C40).
    pub zero_speed: bool,
    /// Bit 13 max. slippage error: |effective set velocity − actual| > C40.
    pub slippage_error: bool,
}

/// The velocity window of pv (C-056).
#[derive(Debug, Clone)]
pub struct VelocityWindowMonitor {
    config: VelocityWindowConfig,
    inside_since: Option<Nanos>,
}

impl VelocityWindowMonitor {
    /// A monitor with `config`.
    pub const fn new(config: VelocityWindowConfig) -> Self {
        Self {
            config,
            inside_since: None,
        }
    }

    /// Replaces the configuration; keeps the state.
    pub fn set_config(&mut self, config: VelocityWindowConfig) {
        self.config = config;
    }

    /// Restarts the window time.
    pub fn reset(&mut self) {
        self.inside_since = None;
    }

    /// Evaluates one cycle at `now`: `target_inc_per_s` is 60FFh (the
    /// final velocity), `setpoint_inc_per_s` the profile's current
    /// (effective) set velocity, `actual_inc_per_s` 606Ch. Non-finite inputs
    /// count as outside every window.
    pub fn update(
        &mut self,
        target_inc_per_s: f32,
        setpoint_inc_per_s: f32,
        actual_inc_per_s: f32,
        now: Nanos,
    ) -> ProfileVelocityStatus {
        let w = self.config.window_inc_per_s;
        let slip = (setpoint_inc_per_s - actual_inc_per_s).abs();
        let inside = (target_inc_per_s - actual_inc_per_s).abs() <= w;
        let target_reached = held(&mut self.inside_since, inside, now, self.config.time);
        ProfileVelocityStatus {
            target_reached,
            zero_speed: is_standstill(actual_inc_per_s, w),
            slippage_error: slip > w || slip.is_nan(),
        }
    }
}

/// A window time: `true` once `inside` has held without a break for at
/// least `time` up to `now` (`since`: when it began; cleared outside).
fn held(since: &mut Option<Nanos>, inside: bool, now: Nanos, time: Nanos) -> bool {
    if !inside {
        *since = None;
        return false;
    }
    let start = *since.get_or_insert(now);
    now.since(start) >= time
}

/// I199 standstill: |actual velocity 606Ch| < C40 velocity window (both
/// increments/s; C-027, C-043). A non-finite velocity is not standstill.
pub fn is_standstill(actual_inc_per_s: f32, window_c40_inc_per_s: f32) -> bool {
    actual_inc_per_s.abs() < window_c40_inc_per_s
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: Nanos = Nanos::from_ms(1);

    fn fe_config(fault: bool) -> FollowingErrorConfig {
        FollowingErrorConfig {
            window_inc: 1000,
            timeout: ms_to_ns(5),
            fault,
            limit_inc: u32::MAX,
        }
    }

    /// P-160: beyond I21 the limit event comes at once (no timeout), once
    /// per crossing, independent of the window's fault setting.
    #[test]
    fn p160_position_error_limit_raises_54_2_at_once() {
        let mut m = FollowingErrorMonitor::new(FollowingErrorConfig {
            limit_inc: 5000,
            ..fe_config(false)
        });
        assert_eq!(m.update(5000, 0, Nanos::ZERO).limit_event, None, "at the limit");
        let s = m.update(-5001, 0, MS);
        assert_eq!(s.limit_event, Some(POSITION_ERROR_LIMIT_EVENT));
        assert!(!s.following_error, "the window's timeout still runs");
        assert_eq!(m.update(-6000, 0, Nanos::from_ms(2)).limit_event, None, "once");
        assert_eq!(m.update(0, 0, Nanos::from_ms(3)).limit_event, None);
        assert_eq!(
            m.update(0, 5001, Nanos::from_ms(4)).limit_event,
            Some(POSITION_ERROR_LIMIT_EVENT),
            "again after coming back"
        );
        m.reset();
        assert_eq!(
            m.update(0, 5001, Nanos::from_ms(5)).limit_event,
            Some(POSITION_ERROR_LIMIT_EVENT),
            "a reset (fault reset, enable) re-arms it"
        );
        // off: u32::MAX
        let mut off = FollowingErrorMonitor::new(fe_config(true));
        assert_eq!(off.update(i32::MAX, i32::MIN + 1, Nanos::ZERO).limit_event, None);
    }

    #[test]
    fn c036_following_error_sets_bit13_after_timeout() {
        let mut m = FollowingErrorMonitor::new(fe_config(false));
        // Inside the window: nothing.
        let s = m.update(1000, 0, Nanos::ZERO);
        assert_eq!(s.error_inc, 1000);
        assert!(!s.following_error);
        // Outside from t = 1 ms: bit 13 only at ≥ 6 ms.
        assert!(!m.update(1001, 0, MS).following_error);
        assert!(!m.update(1500, 0, Nanos::from_ms(5)).following_error);
        assert!(!m.update(1500, 0, Nanos::from_ns(6_000_000 - 1)).following_error);
        let s = m.update(1500, 0, Nanos::from_ms(6));
        assert!(s.following_error);
        assert_eq!(s.event, None, "no fault unless configured");
        // Back inside: off at once.
        assert!(!m.update(0, -999, Nanos::from_ms(7)).following_error);
    }

    #[test]
    fn c036_following_error_timer_restarts_when_back_inside() {
        let mut m = FollowingErrorMonitor::new(fe_config(false));
        assert!(!m.update(2000, 0, Nanos::ZERO).following_error);
        assert!(!m.update(0, 0, Nanos::from_ms(4)).following_error);
        assert!(!m.update(-2000, 0, Nanos::from_ms(5)).following_error);
        assert!(!m.update(-2000, 0, Nanos::from_ms(9)).following_error);
        assert!(m.update(-2000, 0, Nanos::from_ms(10)).following_error);
    }

    #[test]
    fn c036_following_error_fault_event_once_when_configured() {
        let mut m = FollowingErrorMonitor::new(fe_config(true));
        assert_eq!(m.update(5000, 0, Nanos::ZERO).event, None);
        let s = m.update(5000, 0, Nanos::from_ms(5));
        assert!(s.following_error);
        assert_eq!(s.event, Some(FOLLOWING_ERROR_EVENT));
        assert_eq!(s.event.unwrap().number, 54);
        // Still active: no second event.
        assert_eq!(m.update(5000, 0, Nanos::from_ms(6)).event, None);
        m.reset();
        assert!(!m.is_active());
    }

    #[test]
    fn c036_following_error_wraps_and_can_be_switched_off() {
        let mut m = FollowingErrorMonitor::new(fe_config(false));
        // 20 increments across the i32 wrap: inside the window.
        let s = m.update(i32::MIN + 9, i32::MAX - 10, Nanos::ZERO);
        assert_eq!(s.error_inc, 20);
        assert!(
            !m.update(i32::MIN + 9, i32::MAX - 10, Nanos::from_ms(100))
                .following_error
        );
        let mut off = FollowingErrorMonitor::new(FollowingErrorConfig {
            window_inc: u32::MAX,
            ..fe_config(true)
        });
        assert!(!off.update(i32::MAX, i32::MIN, Nanos::ZERO).following_error);
        assert!(
            !off.update(i32::MAX, i32::MIN, Nanos::from_ms(100))
                .following_error
        );
    }

    #[test]
    fn c048_target_reached_needs_window_and_time() {
        let mut m = TargetReachedMonitor::new(PositionWindowConfig {
            window_inc: 100,
            time: Nanos::from_ms(2),
        });
        // Profile still running: never.
        assert!(!m.update(10_000, 10_000, false, Nanos::ZERO));
        // Done but outside the window.
        assert!(!m.update(10_000, 9_800, true, MS));
        // Inside from 2 ms: reached at ≥ 4 ms.
        assert!(!m.update(10_000, 9_950, true, Nanos::from_ms(2)));
        assert!(!m.update(10_000, 10_050, true, Nanos::from_ms(3)));
        assert!(m.update(10_000, 10_100, true, Nanos::from_ms(4)));
        // Leaves the window: off, and the time restarts.
        assert!(!m.update(10_000, 10_101, true, Nanos::from_ms(5)));
        assert!(!m.update(10_000, 10_000, true, Nanos::from_ms(6)));
        assert!(m.update(10_000, 10_000, true, Nanos::from_ms(8)));
    }

    #[test]
    fn c048_target_reached_without_window() {
        let mut m = TargetReachedMonitor::new(PositionWindowConfig {
            window_inc: u32::MAX,
            time: Nanos::from_ms(2),
        });
        assert!(!m.update(0, 1_000_000, false, Nanos::ZERO));
        assert!(m.update(0, 1_000_000, true, Nanos::ZERO));
    }

    #[test]
    fn c056_pv_velocity_window_bits() {
        let mut m = VelocityWindowMonitor::new(VelocityWindowConfig {
            window_inc_per_s: 1000.0,
            time: MS,
        });
        // Accelerating: set velocity 20 000, actual 18 000 → slippage, not reached.
        let s = m.update(50_000.0, 20_000.0, 18_000.0, Nanos::ZERO);
        assert!(!s.target_reached && !s.zero_speed && s.slippage_error);
        // At the target within the window: reached after 606Eh.
        let s = m.update(50_000.0, 50_000.0, 49_500.0, MS);
        assert!(!s.target_reached && !s.slippage_error);
        let s = m.update(50_000.0, 50_000.0, 50_900.0, Nanos::from_ms(2));
        assert!(s.target_reached);
        // Target 0 and standing: bit 12.
        let mut m = VelocityWindowMonitor::new(VelocityWindowConfig {
            window_inc_per_s: 1000.0,
            time: Nanos::ZERO,
        });
        let s = m.update(0.0, 0.0, 10.0, Nanos::ZERO);
        assert!(s.target_reached && s.zero_speed && !s.slippage_error);
        let s = m.update(0.0, 0.0, f32::NAN, Nanos::ZERO);
        assert!(!s.target_reached && !s.zero_speed && s.slippage_error);
    }

    #[test]
    fn c027_standstill_is_velocity_below_c40() {
        assert!(is_standstill(0.0, 100.0));
        assert!(is_standstill(-99.9, 100.0));
        assert!(!is_standstill(100.0, 100.0));
        assert!(!is_standstill(-150.0, 100.0));
        assert!(!is_standstill(f32::NAN, 100.0));
        assert!(!is_standstill(0.0, 0.0));
    }
}
