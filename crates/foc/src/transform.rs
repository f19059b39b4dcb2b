//! Clarke and Park transforms (amplitude-invariant: a phase current of amplitude
//! I is a vector of length I, so iq is the phase current's amplitude).

/// 1/√3.
pub const FRAC_1_SQRT_3: f32 = 0.577_350_26;
/// √3/2.
pub const SQRT_3_2: f32 = 0.866_025_4;

/// Three phase quantities a, b, c.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Abc {
    /// Phase a.
    pub a: f32,
    /// Phase b.
    pub b: f32,
    /// Phase c.
    pub c: f32,
}

/// A stationary-frame vector (α along phase a).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AlphaBeta {
    /// α component.
    pub alpha: f32,
    /// β component.
    pub beta: f32,
}

/// A rotor-frame vector (d along the magnet flux).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Dq {
    /// d (flux) component.
    pub d: f32,
    /// q (torque) component.
    pub q: f32,
}

/// Clarke transform of three phases; the common mode (a + b + c)/3 drops out.
#[inline]
pub fn clarke(x: Abc) -> AlphaBeta {
    AlphaBeta {
        alpha: (2.0 * x.a - x.b - x.c) * (1.0 / 3.0),
        beta: (x.b - x.c) * FRAC_1_SQRT_3,
    }
}

/// Clarke transform from two phases (c = −a − b, a star point without neutral).
#[inline]
pub fn clarke2(a: f32, b: f32) -> AlphaBeta {
    AlphaBeta {
        alpha: a,
        beta: (a + 2.0 * b) * FRAC_1_SQRT_3,
    }
}

/// Inverse Clarke transform (no common mode).
#[inline]
pub fn inverse_clarke(v: AlphaBeta) -> Abc {
    let h = -0.5 * v.alpha;
    let s = SQRT_3_2 * v.beta;
    Abc {
        a: v.alpha,
        b: h + s,
        c: h - s,
    }
}

/// Park transform: stationary → rotor frame at the angle whose (sin, cos) is given.
#[inline]
pub fn park(v: AlphaBeta, sin: f32, cos: f32) -> Dq {
    Dq {
        d: v.alpha * cos + v.beta * sin,
        q: -v.alpha * sin + v.beta * cos,
    }
}

/// Inverse Park transform: rotor frame → stationary.
#[inline]
pub fn inverse_park(v: Dq, sin: f32, cos: f32) -> AlphaBeta {
    AlphaBeta {
        alpha: v.d * cos - v.q * sin,
        beta: v.d * sin + v.q * cos,
    }
}
