//! Arbitrary bytes as mailbox requests (mailbox header, CoE, SDO, SDO Info, ...)
//! into SM0 of a drive in PRE-OP, each answer read back from SM1: the slave
//! stack must never panic, whatever the master writes, and the answers pass
//! the oracles of `mbx_oracle.rs` (well-formed, AL state unchanged, SDO
//! answers for the requests made, an aborted download changes nothing).
//! Each input starts from a copy of one line.
#![no_main]

#[path = "common.rs"]
mod common;
#[path = "mbx_esc.rs"]
mod mbx_esc;
#[path = "mbx_oracle.rs"]
mod mbx_oracle;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut m = mbx_oracle::Checked::new();
    for chunk in data.chunks(256) {
        let mut buf = [0u8; 256];
        buf[..chunk.len()].copy_from_slice(chunk);
        m.request(&buf);
    }
});
