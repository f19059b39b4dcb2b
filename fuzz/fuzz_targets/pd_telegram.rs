//! The PROFIdrive telegram path: arbitrary bytes as a stored telegram
//! configuration (refused ones must leave the FB defaults in force), then
//! arbitrary frames through receive → PKW → CW1 → response: nothing may
//! panic, a read-only object is never written, a response is exactly the
//! module long and starts with its identifier.
#![no_main]

#[path = "pd_common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;
use profidrive::cw1::{Context, Cw1Decoder, Mode};
use profidrive::pkw::Pkw;
use profidrive::telegram::{TelegramSet, Telegrams, FB_DEFAULTS};

fuzz_target!(|data: &[u8]| {
    let Some((&split, rest)) = data.split_first() else {
        return;
    };
    let (config, frames) = rest.split_at(usize::from(split).min(rest.len()));
    let mut drive = common::Drive::new();
    let mut t = Telegrams::with_defaults(&drive).expect("the defaults configure");
    if let Ok(set) = TelegramSet::from_bytes(config) {
        if t.configure(&set, &drive).is_err() {
            assert_eq!(*t.set(), FB_DEFAULTS, "a refused set changed the configuration");
        }
        let mut buf = [0u8; profidrive::telegram::MAX_SERIAL_BYTES];
        let n = set.to_bytes(&mut buf).expect("fits");
        assert_eq!(TelegramSet::from_bytes(&buf[..n]), Ok(set));
    }
    let mut pkw = Pkw::new();
    let mut cw1 = Cw1Decoder::new();
    for frame in frames.chunks(40) {
        let Some((&len, frame)) = frame.split_first() else {
            continue;
        };
        let rx = t.apply_receive(frame, &mut drive);
        let resp = rx.pkw.map_or([0; 8], |req| pkw.step(req, &mut drive));
        let ctx = Context {
            mode: if len & 1 == 0 { Mode::Positioning } else { Mode::Speed },
            homing_active: len & 2 != 0,
        };
        cw1.decode(rx.cw1, ctx);
        let module = usize::from(len % 40);
        let mut out = [0u8; 40];
        if let Some(n) = rx.response {
            let r = t.build_response(n, &mut drive, resp, &mut out[..module]);
            if let Some(r) = r {
                assert_eq!(r.len, module);
                if module > 0 {
                    assert_eq!(out[0], 0xF0 + n);
                }
            }
        }
    }
});
