//! Robustness: random requests never panic and every reply is well formed.

use super::*;

// ---------------------------------------------------------------- robustness

/// xorshift64*
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

#[test]
fn random_requests_never_panic_and_replies_are_well_formed() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let commands = [
        0x00, 0x01, 0x0B, 0x10, 0x11, 0x20, 0x21, 0x22, 0x23, 0x2B, 0x2F, 0x31, 0x33, 0x40, 0x50, 0x60, 0x70,
        0x80, 0xA0, 0xC0, 0xE0,
    ];
    let indices = [
        0x1C12u16, 0x2000, 0x2001, 0x2002, 0x2003, 0x2004, 0x2005, 0x2006, 0x3000, 0x6000,
    ];
    let mut t = T::new(64);
    t.dict.many = true;
    for i in 0..5000 {
        if i % 500 == 0 {
            t.cap = [0, 4, 9, 10, 16, 40, 64, 122, 506][rng.below(9) as usize];
            t.state = [AlState::Init, AlState::PreOp, AlState::SafeOp, AlState::Op][rng.below(4) as usize];
        }
        let len = rng.below(48) as usize;
        let mut req: Vec<u8> = (0..len).map(|_| rng.next() as u8).collect();
        // mostly plausible: SDO or SDO Info header, known commands and objects
        if len >= 2 && rng.below(4) != 0 {
            req[0] = 0;
            req[1] = if rng.below(3) == 0 { 0x80 } else { 0x20 };
        }
        if len >= 6 && req[1] == 0x20 && rng.below(4) != 0 {
            req[2] = commands[rng.below(commands.len() as u64) as usize];
            let [a, b] = indices[rng.below(indices.len() as u64) as usize].to_le_bytes();
            req[3] = a;
            req[4] = b;
            req[5] = rng.below(5) as u8;
        }
        if len >= 8 && req[1] == 0x80 {
            req[2] = [1, 3, 5, 0x81, 7][rng.below(5) as usize];
            req[6] = rng.below(7) as u8;
            req[7] = if rng.below(2) == 0 { 0 } else { 0x20 };
        }
        if rng.below(50) == 0 {
            t.now += 2 * SDO_TIMEOUT;
        }
        if let Ok(Some(r)) = t.raw(&req) {
            assert!(r.len() <= t.cap && r.len() >= 2, "{req:x?} -> {r:x?}");
            let h = CoeHeader::parse(&r).unwrap();
            assert_eq!(h.number, 0);
            match h.service {
                service::SDO_REQUEST => {
                    assert_eq!(r.len(), 10);
                    assert_eq!(r[2], 0x80);
                }
                service::SDO_RESPONSE => assert!(r.len() >= 10, "{req:x?} -> {r:x?}"),
                service::SDO_INFO => assert!(r.len() >= 6),
                s => panic!("service {s}"),
            }
        }
        if rng.below(2) == 0 {
            if let Some(f) = t.fragment() {
                assert!(f.len() <= t.cap && f.len() >= 6);
                assert_eq!(f[2] & 0x7F, 0x02);
            }
        }
    }
}
