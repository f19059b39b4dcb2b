//! Arbitrary UDP payloads to the RPC port 34964 (DCE/RPC header, fragments,
//! the endpoint mapper, the CM blocks of Connect, Read, Write and Control,
//! the records behind Read and Write: I&M, PDev, PROFIenergy)
//! into a fresh and a connected PROFINET device, two datagrams per input
//! (split at the first byte's value) so fragments and follow-ups are
//! reached: nothing may panic, and a fresh device only gains an AR from a
//! Connect it answered.
#![no_main]

#[path = "pn_common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;
use nanos::Nanos;

fuzz_target!(|data: &[u8]| {
    let Some((&cut, rest)) = data.split_first() else {
        return;
    };
    let (a, b) = rest.split_at(usize::from(cut).min(rest.len()));
    for mut d in [common::device(), common::connected()] {
        for (i, part) in [a, b].into_iter().enumerate() {
            let mut answers = 0;
            let now = Nanos::from_ms(i as u64);
            d.receive(now, &common::udp_to_device(part), &mut |_: &[u8]| answers += 1);
            d.poll(now, &mut |_: &[u8]| {});
        }
        while d.take_event().is_some() {}
    }
});
