//! Space-vector modulation by min/max (midpoint) injection, over-modulation, and
//! dead-time compensation.

use crate::fmath;
use crate::transform::{inverse_clarke, Abc, AlphaBeta};

/// Duty cycles of the three half bridges, each the fraction of the period the high
/// side conducts, in [0, 1].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Duty {
    /// Phase a.
    pub a: f32,
    /// Phase b.
    pub b: f32,
    /// Phase c.
    pub c: f32,
}

/// The duty cycles that put the stationary voltage `v` (V) on the motor's phases
/// from a DC link of `vdc` (V), with `inv_vdc` = 1/vdc.
///
/// Min/max injection: the phase voltages of the inverse Clarke transform are
/// shifted by −(max + min)/2, so the three legs are centred in the period; this
/// reaches the full hexagon (|v| up to Vdc/√3 in every direction, 15 % more than
/// sine modulation) like the classic sector SVM, without sectors. Over-modulation:
/// a vector beyond the hexagon (max − min > Vdc) is scaled onto it, keeping its
/// angle; the duties then stay in [0, 1]. Returns the duties and whether the vector
/// was scaled.
#[inline]
pub fn svm(v: AlphaBeta, vdc: f32, inv_vdc: f32) -> (Duty, bool) {
    let p = inverse_clarke(v);
    let max = fmath::max(fmath::max(p.a, p.b), p.c);
    let min = fmath::min(fmath::min(p.a, p.b), p.c);
    let span = max - min;
    let mid = 0.5 * (max + min);
    let (k, over) = if span > vdc {
        (1.0 / span, true)
    } else {
        (inv_vdc, false)
    };
    (
        Duty {
            a: 0.5 + (p.a - mid) * k,
            b: 0.5 + (p.b - mid) * k,
            c: 0.5 + (p.c - mid) * k,
        },
        over,
    )
}

/// Dead-time compensation: during the dead time a leg's output follows its
/// current's freewheeling diode, which loses `dead_time_duty`·Vdc of average
/// voltage in the direction of the current. Each leg's duty gains
/// `dead_time_duty`·sign(i) back, linear in the current within ±band
/// (`inv_band` = 1/band) so the zero crossing does not chatter, and the result is
/// kept in [0, 1].
#[inline]
pub fn compensate_dead_time(d: Duty, i: Abc, dead_time_duty: f32, inv_band: f32) -> Duty {
    let c = |x: f32| fmath::clamp(x * inv_band, -1.0, 1.0) * dead_time_duty;
    Duty {
        a: fmath::clamp(d.a + c(i.a), 0.0, 1.0),
        b: fmath::clamp(d.b + c(i.b), 0.0, 1.0),
        c: fmath::clamp(d.c + c(i.c), 0.0, 1.0),
    }
}
