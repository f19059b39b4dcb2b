//! A small seeded noise source: xorshift64* (Vigna 2016), the generator hil-sim's
//! encoder noise already uses. Our own because it is a dozen lines, needs no
//! dependency, and its sequence is fixed by this file forever (a crate update
//! cannot change a seeded test's numbers).

/// xorshift64* generator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct XorShift64Star(u64);

impl XorShift64Star {
    /// A generator from a seed (0 is replaced by a fixed non-zero constant).
    pub const fn new(seed: u64) -> Self {
        Self(if seed == 0 { 0x9E37_79B9_7F4A_7C15 } else { seed })
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Approximately normal with standard deviation 1: the sum of four uniforms
    /// (Irwin–Hall), centred and scaled; bounded at ±2√3.
    pub fn normal(&mut self) -> f64 {
        let s = self.uniform() + self.uniform() + self.uniform() + self.uniform();
        (s - 2.0) * 1.732_050_807_568_877_2
    }
}
