//! Arbitrary DCP requests (FrameID from the first byte: Identify, Get/Set,
//! Hello, Identify response; to the Identify multicast or to us) into a fresh
//! and into a connected PROFINET device: nothing may panic, and while the AR
//! runs no DCP frame changes the name, the IP or the AR.
#![no_main]

#[path = "pn_common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;
use nanos::Nanos;
use profinet::wire::MacAddr;

fuzz_target!(|data: &[u8]| {
    let Some((&sel, rest)) = data.split_first() else {
        return;
    };
    let id = [0xFEFE, 0xFEFD, 0xFEFC, 0xFEFF][usize::from(sel & 3)];
    let dst = if sel & 4 != 0 {
        MacAddr::DCP_IDENTIFY
    } else {
        common::OUR_MAC
    };
    let frame = common::rt_frame(dst, id, rest);
    let mut fresh = common::device();
    fresh.receive(Nanos::ZERO, &frame, &mut |_: &[u8]| {});
    fresh.poll(Nanos::from_secs(1), &mut |_: &[u8]| {});
    let mut d = common::connected();
    let (name, ip) = (d.dcp().name_of_station().clone(), d.dcp().ip_suite());
    d.receive(Nanos::ZERO, &frame, &mut |_: &[u8]| {});
    d.poll(Nanos::from_ms(1), &mut |_: &[u8]| {});
    assert_eq!(d.dcp().name_of_station(), &name);
    assert_eq!(d.dcp().ip_suite(), ip);
    assert!(d.cm().ar().is_some());
});
