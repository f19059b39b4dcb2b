use super::*;

/// The 64-bit `wrap_signed` equals the 128-bit reference everywhere,
/// the overflow edges included.
#[test]
fn e111_wrap_signed_matches_128_bit_reference() {
    let reference = |d: i64, p: i64| {
        let p = i128::from(p.max(1));
        i64::try_from((i128::from(d) + p / 2).rem_euclid(p) - p / 2).unwrap()
    };
    for &d in &[
        0,
        1,
        -1,
        499_999,
        500_000,
        -500_001,
        7_123_456_789,
        i64::MAX,
        i64::MIN,
        i64::MAX - 3,
    ] {
        for &p in &[1, 2, 3, 1_000_000, 999_983, i64::MAX] {
            assert_eq!(wrap_signed(d, p), reference(d, p), "{d} {p}");
        }
    }
}

/// The base-2^16 division equals the plain 64-bit one for small and
/// large divisors and refuses 0.
#[test]
fn e111_div_rem_u64_matches_the_library_division() {
    let xs = [
        0u64,
        1,
        17,
        18,
        125,
        65_535,
        65_536,
        1 << 32,
        (1 << 32) - 1,
        123_456_789_012_345,
        u64::MAX,
        u64::MAX - 1,
    ];
    let ds = [1u64, 2, 3, 18, 125, 999, 65_535, 65_536, 1_000_000_000, u64::MAX];
    let mut seed = 0x9E37_79B9_7F4A_7C15u64;
    let more: [u64; 2000] = core::array::from_fn(|_| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed >> (seed % 64)
    });
    for &x in xs.iter().chain(&more) {
        for &d in &ds {
            assert_eq!(div_rem_u64(x, d), Some((x / d, x % d)), "{x} / {d}");
        }
        assert_eq!(div_rem_u64(x, 0), None);
    }
}

/// E-111: the cycle lengths issued in timer ticks add up exactly (the
/// sub-tick carry) for a timer whose ratio to 1 GHz reduces (144 MHz)
/// and for one whose does not (a prime), over 10,000 cycles.
#[test]
fn e111_cycle_ticks_carry_exactly() {
    for hz in [144_000_000u32, 99_999_989] {
        let mut pll = Pll::new(Config::new(1_000_000, 1_000_000, hz)).unwrap();
        let n = 10_000u64;
        let total: u64 = (0..n)
            .map(|i| u64::from(pll.on_cycle_start(Nanos::from_ns(i * 1_000_000)).period_ticks))
            .sum();
        // nominal 1 ms per cycle, no SYNC0: the exact tick count of 10 s
        assert_eq!(total, u64::from(hz) * 10, "{hz} Hz");
        let c = pll.on_cycle_start(Nanos::from_ns(n * 1_000_000));
        // the local length of the issued ticks: within one tick
        let tick_ns = 1_000_000_000 / hz + 1;
        assert!(
            c.period_local_ns.abs_diff(1_000_000) <= tick_ns,
            "{hz} Hz: {}",
            c.period_local_ns
        );
    }
}
