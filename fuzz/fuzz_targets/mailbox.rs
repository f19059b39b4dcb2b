//! Arbitrary bytes as mailbox requests (mailbox header, CoE, SDO, SDO Info, ...)
//! into SM0 of a drive in PRE-OP, each answer read back from SM1: the slave
//! stack must never panic, whatever the master writes, and each answer it
//! puts into SM1 is a well-formed mailbox (a length that fits the mailbox, a
//! type the stack speaks). Each input starts from a copy of one line.
#![no_main]

#[path = "common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut sim = common::preop_line();
    for chunk in data.chunks(256) {
        let mut buf = [0u8; 256];
        buf[..chunk.len()].copy_from_slice(chunk);
        let mut w = common::frame(5, 0x1000, 0x1000, &buf); // FPWR into SM0
        sim.exchange(&mut w);
        let t = sim.now() + nanos::Nanos::from_us(200);
        sim.advance_to(t);
        let mut r = common::frame(4, 0x1000, 0x1100, &[0u8; 256]); // FPRD of SM1
        sim.exchange(&mut r);
        let (answer, wkc) = common::reply(&r);
        if wkc == 1 {
            // a mailbox was there: header length within the SM, type error/EoE/CoE/FoE
            let len = usize::from(u16::from_le_bytes([answer[0], answer[1]]));
            let kind = answer[5] & 0x0F;
            assert!(len <= 256 - 6, "answer length {len}");
            assert!(matches!(kind, 0 | 2 | 3 | 4), "answer type {kind}");
        }
    }
});
