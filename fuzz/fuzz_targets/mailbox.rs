//! Arbitrary bytes as mailbox requests (mailbox header, CoE, SDO, SDO Info, ...)
//! into SM0 of a drive in PRE-OP, each answer read back from SM1: the slave
//! stack must never panic, whatever the master writes, and
//! - each answer it puts into SM1 is a well-formed mailbox (a length that
//!   fits the mailbox, a type the stack speaks);
//! - no mailbox request changes the AL state;
//! - an SDO answer to an expedited or normal initiate request names the
//!   request's index and subindex (an abort too, CiA 301);
//! - an aborted download leaves the object dictionary as it was.
//!
//! Each input starts from a copy of one line.
#![no_main]

#[path = "common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;

/// CoE SDO request: mailbox type 3, CoE service 2.
fn sdo_request(m: &[u8]) -> bool {
    m[5] & 0x0F == 3 && u16::from_le_bytes([m[6], m[7]]) >> 12 == 2
}

fuzz_target!(|data: &[u8]| {
    let mut sim = common::preop_line();
    // the index/subindex of initiate requests not answered yet, oldest
    // first: the stack queues its answers, so one may come in a later window
    let mut waiting: Vec<[u8; 3]> = Vec::new();
    for chunk in data.chunks(256) {
        let mut buf = [0u8; 256];
        buf[..chunk.len()].copy_from_slice(chunk);
        let state = sim.drives()[0].drive.slave().state();
        // an initiate request (download 0x20, upload 0x40 in the command
        // specifier) whose mailbox length covers the SDO header
        let len_in = usize::from(u16::from_le_bytes([buf[0], buf[1]]));
        let initiate = sdo_request(&buf) && len_in >= 10 && matches!(buf[8] & 0xE0, 0x20 | 0x40);
        let object = [buf[9], buf[10], buf[11]];
        // a download with nothing else outstanding: its abort must leave the dictionary as it was
        let alone = initiate && buf[8] & 0xE0 == 0x20 && waiting.is_empty();
        let before = alone.then(|| sim.drives()[0].drive.objects().clone());
        if initiate {
            waiting.push(object);
            if waiting.len() > 16 {
                waiting.remove(0);
            }
        }
        let mut w = common::frame(5, 0x1000, 0x1000, &buf); // FPWR into SM0
        sim.exchange(&mut w);
        // read SM1 until it is empty (at most 4 answers per request)
        for _ in 0..4 {
            let t = sim.now() + nanos::Nanos::from_us(200);
            sim.advance_to(t);
            let mut r = common::frame(4, 0x1000, 0x1100, &[0u8; 256]); // FPRD of SM1
            sim.exchange(&mut r);
            let (answer, wkc) = common::reply(&r);
            if wkc != 1 {
                break;
            }
            // a mailbox was there: header length within the SM, type error/EoE/CoE/FoE
            let len = usize::from(u16::from_le_bytes([answer[0], answer[1]]));
            let kind = answer[5] & 0x0F;
            assert!(len <= 256 - 6, "answer length {len}");
            assert!(matches!(kind, 0 | 2 | 3 | 4), "answer type {kind}");
            let service = u16::from_le_bytes([answer[6], answer[7]]) >> 12;
            if kind != 3 || !matches!(service, 2 | 3) || len < 10 {
                continue;
            }
            let scs = answer[8] & 0xE0;
            let named = [answer[9], answer[10], answer[11]];
            if matches!(scs, 0x40 | 0x60) {
                // initiate responses come in request order, each for a request made
                let at = waiting.iter().position(|o| *o == named);
                assert!(
                    at.is_some(),
                    "an initiate response ({scs:#04x}) for {named:02x?}, asked {waiting:02x?}"
                );
                waiting.drain(..=at.unwrap_or(0));
            } else if scs == 0x80 {
                if let Some(at) = waiting.iter().position(|o| *o == named) {
                    waiting.drain(..=at);
                    if let Some(before) = &before {
                        if named == object && waiting.is_empty() {
                            assert!(
                                *sim.drives()[0].drive.objects() == *before,
                                "an aborted download changed the dictionary: {:02x?}",
                                &answer[..16]
                            );
                        }
                    }
                }
            }
        }
        assert_eq!(
            sim.drives()[0].drive.slave().state(),
            state,
            "a mailbox request changed the AL state"
        );
    }
});
