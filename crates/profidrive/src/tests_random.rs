//! Random and mutated bus bytes through every entry point (a stand-in for
//! the fuzz targets where cargo-fuzz is not at hand): nothing panics, a
//! malformed BMP request writes nothing, a refused configuration changes
//! nothing.

use crate::bmp;
use crate::fake::Fake;
use crate::pkw::Pkw;
use crate::telegram::{TelegramSet, Telegrams, FB_DEFAULTS, MAX_SERIAL_BYTES};

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    fn byte(&mut self) -> u8 {
        self.next() as u8
    }

    fn bytes(&mut self, max: usize) -> std::vec::Vec<u8> {
        let n = (self.next() as usize) % (max + 1);
        (0..n).map(|_| self.byte()).collect()
    }

    /// `base` with a few bytes changed, dropped or added.
    fn mutate(&mut self, base: &[u8]) -> std::vec::Vec<u8> {
        let mut v = base.to_vec();
        for _ in 0..1 + self.next() % 3 {
            let at = (self.next() as usize) % (v.len() + 1);
            match self.next() % 3 {
                0 if at < v.len() => v[at] = self.byte(),
                1 if at < v.len() => {
                    v.remove(at);
                }
                _ => v.insert(at, self.byte()),
            }
        }
        v
    }
}

#[test]
fn p206_random_and_mutated_bmp_requests_never_panic_and_malformed_ones_write_nothing() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let seeds: [&[u8]; 3] = [
        &[1, 1, 1, 2, 0x10, 1, 0x04, 0x4C, 0, 0, 0x10, 3, 0x03, 0xE9, 0, 0],
        &[
            2, 2, 1, 2, 0x10, 1, 0x03, 0xE9, 0, 0, 0x10, 1, 0x04, 0x1A, 0, 0, 4, 1, 0, 0, 4, 0xD2, 2, 1,
            0xFD, 0,
        ],
        &[
            3, 2, 1, 1, 0x10, 2, 0x03, 0xE9, 0, 1, 0x43, 2, 0, 0, 0, 1, 0, 0, 0, 2,
        ],
    ];
    for i in 0..20_000 {
        let req = if i % 2 == 0 {
            rng.bytes(64)
        } else {
            let s = seeds[i % seeds.len()];
            rng.mutate(s)
        };
        let mut f = Fake::drive();
        let mut out = [0u8; 64];
        let parsed = bmp::Request::parse(&req).is_ok();
        if let Ok(n) = bmp::serve(&req, &mut f, &mut out) {
            assert!((4..=64).contains(&n));
            assert_eq!(out[0], req[0]);
        }
        if !parsed {
            assert!(f.writes.is_empty(), "{req:02x?}");
        }
    }
}

#[test]
fn p069_p075_random_configurations_and_frames_never_panic() {
    let mut rng = Rng(0x2545_F491_4F6C_DD1D);
    let mut stored = [0u8; MAX_SERIAL_BYTES];
    let n = FB_DEFAULTS.to_bytes(&mut stored).expect("fits");
    for i in 0..3_000 {
        let mut f = Fake::drive();
        let mut t = Telegrams::with_defaults(&f).expect("defaults");
        let bytes = if i % 2 == 0 {
            rng.mutate(&stored[..n])
        } else {
            rng.bytes(80)
        };
        if let Ok(set) = TelegramSet::from_bytes(&bytes) {
            if t.configure(&set, &f).is_err() {
                assert_eq!(*t.set(), FB_DEFAULTS);
            }
        }
        let mut pkw = Pkw::new();
        for _ in 0..8 {
            let mut frame = rng.bytes(40);
            if let Some(b) = frame.first_mut() {
                *b = 0xE0 | (*b & 7);
            }
            let rx = t.apply_receive(&frame, &mut f);
            let resp = rx.pkw.map_or([0; 8], |r| pkw.step(r, &mut f));
            let module = (rng.next() % 40) as usize;
            let mut out = [0u8; 40];
            if let Some(n) = rx.response {
                if let Some(r) = t.build_response(n, &mut f, resp, &mut out[..module]) {
                    assert_eq!(r.len, module);
                }
            }
        }
    }
}
