//! Arbitrary PROFIdrive parameter requests (record 0xB02E): nothing may
//! panic, a request that is refused or answered as malformed writes
//! nothing, and the response mirrors the request's reference.
#![no_main]

#[path = "pd_common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;
use profidrive::bmp;

fuzz_target!(|data: &[u8]| {
    let mut drive = common::Drive::new();
    let mut out = [0u8; 240];
    let parsed = bmp::Request::parse(data).is_ok();
    match bmp::serve(data, &mut drive, &mut out) {
        Ok(n) => {
            assert!(n >= 4 && n <= out.len());
            assert_eq!(out[0], data[0]);
            if !parsed {
                assert!(drive.values.iter().all(|&v| v == 0), "a malformed request wrote");
            }
        }
        Err(_) => assert!(drive.values.iter().all(|&v| v == 0)),
    }
});
