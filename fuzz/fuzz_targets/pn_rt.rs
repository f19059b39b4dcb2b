//! Arbitrary cyclic and alarm frames (the output CR's FrameID, another
//! cyclic FrameID, alarm high/low; with the first byte choosing) into a
//! connected PROFINET device, then its timers: nothing may panic, and a frame
//! for another FrameID changes neither the outputs nor the AR.
#![no_main]

#[path = "pn_common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;
use nanos::Nanos;

fuzz_target!(|data: &[u8]| {
    let Some((&sel, rest)) = data.split_first() else {
        return;
    };
    let mut d = common::connected();
    let out_id = d
        .cm()
        .ar()
        .and_then(|a| a.output_cr.as_ref())
        .map_or(0x8000, |c| c.frame_id);
    let id = match sel & 3 {
        0 => out_id,
        1 => out_id ^ 0x0001,
        2 => 0xFC01,
        _ => 0xFE01,
    };
    let before = d.output_data(2).map(<[u8]>::to_vec);
    d.receive(
        Nanos::ZERO,
        &common::rt_frame(common::OUR_MAC, id, rest),
        &mut |_: &[u8]| {},
    );
    if sel & 3 == 1 {
        assert_eq!(d.output_data(2).map(<[u8]>::to_vec), before);
        assert!(d.cm().ar().is_some());
    }
    for ms in [1u64, 10, 100, 1000] {
        d.poll(Nanos::from_ms(ms), &mut |_: &[u8]| {});
    }
});
