//! The csp profile of `hil-sim demo`, which the `control`, `plant` and
//! `selftune` benches drive as well: out and back, cosine S-curves of
//! `t_move` cycles each, 150 cycles dwell between and after.

/// Cycles of the whole profile with moves of `t_move` cycles.
pub const fn cycles(t_move: usize) -> usize {
    2 * t_move + 300
}

/// How far out the profile is in cycle `k` (0 at the start, 1 at the far
/// end) with moves of `t_move` cycles.
pub fn fraction(k: usize, t_move: usize) -> f64 {
    let phase = |k: usize| (1.0 - (std::f64::consts::PI * k as f64 / t_move as f64).cos()) / 2.0;
    if k < t_move {
        phase(k)
    } else if k < t_move + 150 {
        1.0
    } else if k < 2 * t_move + 150 {
        1.0 - phase(k - t_move - 150)
    } else {
        0.0
    }
}
