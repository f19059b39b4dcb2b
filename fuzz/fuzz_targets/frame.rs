//! Arbitrary bytes as Ethernet frames into a line of two simulated drives
//! (ESC datagram processing, FMMUs, SyncManagers, SII interface, then the
//! slave firmware): nothing may panic.
#![no_main]

#[path = "common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut sim = common::preop_line();
    let mut f = data.to_vec();
    sim.exchange(&mut f);
});
