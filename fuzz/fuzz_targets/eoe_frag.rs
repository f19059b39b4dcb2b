//! EoE fragment streams (ETG.1000.6 fragmenting, the `ecat::eoe` crate's
//! `Fragmenter` and `Reassembly`), without the simulated line:
//! - round trip: a frame of 14…1536 bytes cut by the fragmenter for a
//!   mailbox room from the input; every fragment follows the rules (all but
//!   the last carry a multiple of 32 bytes; fragment 0 announces the size in
//!   32-byte blocks, the others their offset; one frame number), and the
//!   reassembly gives back exactly the frame after the last one;
//! - arbitrary fragments (header and data from the input): nothing panics,
//!   a finished frame has 14…1536 bytes and reads as long as reported, and a
//!   refused fragment leaves no frame in assembly.
#![no_main]

use ecat::eoe::{EoeHeader, Fragmenter, Reassembly, HEADER_LEN, MAX_FRAME, MIN_FRAME};
use libfuzzer_sys::fuzz_target;

fn round_trip(len: usize, room: usize, fill: &[u8]) {
    let frame: Vec<u8> = (0..len)
        .map(|i| fill.get(i % fill.len().max(1)).copied().unwrap_or(i as u8))
        .collect();
    let mut tx = Fragmenter::new();
    assert!(tx.load(|buf| {
        buf[..len].copy_from_slice(&frame);
        Some(len)
    }));
    let mut rx = Reassembly::new();
    let mut out = vec![0u8; room];
    let (mut sent, mut number, mut frame_number) = (0usize, 0u8, None);
    while let Some(n) = tx.next(&mut out) {
        let h = EoeHeader::parse(&out[..n]).expect("a fragment has its header");
        let data = &out[HEADER_LEN..n];
        assert_eq!(h.fragment_number(), number, "fragment numbers count up");
        let announced = if number == 0 { len.div_ceil(32) } else { sent / 32 };
        assert_eq!(
            usize::from(h.size_or_offset()),
            announced,
            "size/offset of fragment {number}"
        );
        assert_eq!(
            *frame_number.get_or_insert(h.frame_number()),
            h.frame_number(),
            "one frame number"
        );
        if !h.last {
            assert_eq!(
                data.len() % 32,
                0,
                "a fragment but the last carries 32-byte blocks"
            );
        }
        sent += data.len();
        number += 1;
        match rx.push(&h, data) {
            Ok(None) => assert!(!h.last, "the last fragment finished nothing"),
            Ok(Some(got)) => {
                assert!(h.last, "finished before the last fragment");
                assert_eq!(got, len);
                assert_eq!(rx.frame(), &frame[..], "the reassembled frame");
            }
            Err(e) => panic!("fragment {number} of a good frame refused: {e:?}"),
        }
    }
    assert_eq!(sent, len, "every byte sent");
    assert!(!rx.active(), "the frame finished");
}

fuzz_target!(|data: &[u8]| {
    let [a, b, r0, r1, rest @ ..] = data else {
        return;
    };
    let len = MIN_FRAME + usize::from(u16::from_le_bytes([*a, *b])) % (MAX_FRAME - MIN_FRAME + 1);
    // the mailbox data room: a header and at least 32 bytes, at most a big mailbox
    let room = HEADER_LEN + 32 + usize::from(u16::from_le_bytes([*r0, *r1])) % 1500;
    round_trip(len, room, rest);

    let mut rx = Reassembly::new();
    let mut s = rest;
    while let [n, h0, h1, i0, i1, more @ ..] = s {
        let n = usize::from(*n).min(more.len());
        let (payload, next) = more.split_at(n);
        s = next;
        let Some(h) = EoeHeader::parse(&[*h0, *h1, *i0, *i1]) else {
            continue;
        };
        match rx.push(&h, payload) {
            Ok(Some(got)) => {
                assert!(
                    (MIN_FRAME..=MAX_FRAME).contains(&got),
                    "finished frame of {got} bytes"
                );
                assert_eq!(rx.frame().len(), got);
            }
            Ok(None) => assert!(rx.active(), "a fragment taken, a frame in assembly"),
            Err(_) => assert!(!rx.active(), "a refused fragment drops the frame in assembly"),
        }
    }
});
