//! Arbitrary datagrams into the UDP parameter service's request handler
//! (`net::param::handle`) over the drive's object dictionary, one request per
//! line of the input; the first byte chooses the policy (writes on or off)
//! and the state (Pre-Op or Op). Nothing may panic, and
//! - every answer is ASCII text of at most `MAX_MESSAGE` bytes, `OK…` or
//!   `ERR …`; `ERR SYNTAX` exactly when the handler says "malformed";
//! - a refused request (`ERR`) changes nothing in the dictionary, and
//!   neither does any request while writes are off, nor a read (`R`) or a
//!   lookup (`M`).
#![no_main]

use drive_ecat::DriveObjects;
use ecat::CommState;
use libfuzzer_sys::fuzz_target;
use net::param::{handle, Outcome, Policy, MAX_MESSAGE};

thread_local! {
    static OBJECTS: DriveObjects = DriveObjects::new();
}

fuzz_target!(|data: &[u8]| {
    let Some((&mode, requests)) = data.split_first() else {
        return;
    };
    let mut dict = OBJECTS.with(|o| o.clone());
    let policy = Policy {
        writes: mode & 1 != 0,
        guard: None,
    };
    let state = if mode & 2 != 0 {
        CommState::Op
    } else {
        CommState::PreOp
    };
    for request in requests.split(|&b| b == b'\n').take(16) {
        let before = dict.clone();
        let mut out = [0u8; MAX_MESSAGE];
        let (n, outcome) = handle(request, &mut out, &mut dict, state, policy);
        let answer = core::str::from_utf8(&out[..n]).expect("the answer is text");
        assert!(answer.is_ascii(), "answer {answer:?}");
        assert!(
            answer.starts_with("OK") || answer.starts_with("ERR "),
            "answer {answer:?}"
        );
        assert_eq!(
            outcome == Outcome::Malformed,
            answer == "ERR SYNTAX",
            "{answer:?} for {outcome:?}"
        );
        let read_only = matches!(request.first(), Some(b'R' | b'r' | b'M' | b'm'));
        if answer.starts_with("ERR") || !policy.writes || read_only {
            assert!(
                dict == before,
                "{:?} changed the dictionary ({answer})",
                String::from_utf8_lossy(request)
            );
        }
    }
});
