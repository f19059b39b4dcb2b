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

/// The PWM unit's counts the fused modulator ([`compare_values`]) needs, from the
/// board's period and the loop's dead time: computed once when the parameters are
/// set, never per step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PwmCounts {
    /// The period, counts.
    pub period: f32,
    /// The period as the largest compare value.
    pub max: u32,
    /// Half the period plus the rounding's 0.5, counts.
    pub centre: f32,
    /// The dead time's duty, counts (`dead_time_duty`·period), per unit of
    /// Q15 (/32768).
    pub dead_time_q15: f32,
    /// 32768 / dead-time band, 1/A: the current as a Q15 fraction of the band.
    pub inv_band_q15: f32,
}

impl PwmCounts {
    /// For a period of `period` counts, the dead time as a fraction of the period
    /// and 1/band (1/A).
    pub fn new(period: u16, dead_time_duty: f32, inv_band: f32) -> Self {
        let p = f32::from(period);
        Self {
            period: p,
            max: u32::from(period),
            centre: 0.5 * p + 0.5,
            dead_time_q15: dead_time_duty * p * (1.0 / Q15),
            inv_band_q15: inv_band * Q15,
        }
    }
}

/// One in Q15.
const Q15: f32 = 32_768.0;

/// [`svm`], then [`compensate_dead_time`], then the compare values
/// (duty·period rounded, within 0 ..= period), in one pass at the counts' scale:
/// the scale period/Vdc (or period/span when over-modulating) taken once, the
/// centring and the dead time added in counts, and the clamp to [0, 1] done on the
/// integer (`as u32` saturates at 0 and maps NaN to 0 in the FPU's conversion, the
/// period caps it). The dead time's limiter, i/band within ±1, runs in Q15 on the
/// integer side (the FPU's conversion saturates, the clamp to ±2¹⁵ is one `ssat`):
/// its upper end is 1 − 2⁻¹⁵, 0.002 counts short at 72 counts of dead time. The
/// same compare values as the three steps apart up to the rounding of the
/// reordered products (at most one count, where a value falls on a half count;
/// `fused_compare_values_match_the_blocks`).
#[inline]
pub fn compare_values(v: AlphaBeta, vdc: f32, i: Abc, k: &PwmCounts) -> [u16; 3] {
    let p = inverse_clarke(v);
    let max = fmath::max(fmath::max(p.a, p.b), p.c);
    let min = fmath::min(fmath::min(p.a, p.b), p.c);
    let span = max - min;
    // over-modulation: onto the hexagon; else the DC link (at least 1 V)
    let denom = if span > vdc { span } else { fmath::max(vdc, 1.0) };
    let scale = k.period / denom;
    let off = k.centre - 0.5 * (max + min) * scale;
    let dt = |x: f32| {
        // constant bounds: no panic path, one ssat
        let q = ((x * k.inv_band_q15) as i32).clamp(-32_768, 32_767);
        q as f32 * k.dead_time_q15
    };
    let cmp = |x: f32| {
        let n = x as u32;
        (if n > k.max { k.max } else { n }) as u16
    };
    [
        cmp(off + p.a * scale + dt(i.a)),
        cmp(off + p.b * scale + dt(i.b)),
        cmp(off + p.c * scale + dt(i.c)),
    ]
}
