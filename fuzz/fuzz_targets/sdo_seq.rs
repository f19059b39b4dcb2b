//! Stateful SDO sequences: the input is read as a list of operations, each
//! turned into a well-formed CoE mailbox (header length, counter) so that
//! every request gets past the mailbox checks: expedited and normal
//! download initiates (with or without complete access), download
//! segments with either toggle, upload initiates and segments, aborts from
//! the master and SDO Info list requests, on a table of the drive's real
//! objects (mappings, assignments, records, commands). Segmented transfers
//! are interleaved with aborts and other requests wherever the input says.
//! The answers pass the oracles of `mbx_oracle.rs`.
#![no_main]

#[path = "common.rs"]
mod common;
#[path = "mbx_esc.rs"]
mod mbx_esc;
#[path = "mbx_oracle.rs"]
mod mbx_oracle;

use libfuzzer_sys::fuzz_target;

/// Objects the operations address (index).
const OBJECTS: [u16; 16] = [
    0x1600, 0x1601, 0x1A00, 0x1A01, 0x1C12, 0x1C13, 0x10F3, 0x1018, 0x1010, 0x1011, 0x6040, 0x607A, 0x60C1,
    0xF050, 0x2000, 0x200A,
];

/// Operations per input at most: a sequence long enough for a segmented
/// transfer interleaved with other requests and aborts; longer ones cost
/// executions (an OD list walks the whole dictionary) and reach no more.
const OPS: usize = 8;

/// Takes `n` bytes from the input (fewer at its end).
fn take<'a>(data: &mut &'a [u8], n: usize) -> &'a [u8] {
    let (a, b) = data.split_at(n.min(data.len()));
    *data = b;
    a
}

fn byte(data: &mut &[u8]) -> u8 {
    take(data, 1).first().copied().unwrap_or(0)
}

fuzz_target!(|input: &[u8]| {
    let mut data = input;
    let mut m = mbx_oracle::Checked::new();
    let mut counter = 0u8;
    for _ in 0..OPS {
        if data.is_empty() {
            break;
        }
        let op = byte(&mut data);
        let flags = byte(&mut data);
        let index = OBJECTS[usize::from(byte(&mut data)) % OBJECTS.len()];
        let sub = byte(&mut data) % 5;
        let ca = if flags & 1 != 0 { 0x10 } else { 0 };
        let [i0, i1] = index.to_le_bytes();
        let mut service = 2u16;
        // an OD list walks the whole dictionary: 1 operation in 16 (the
        // `mailbox` target sends them too), its other half uploads
        let kind = match op % 16 {
            14 => 3,
            k => k % 8,
        };
        let sdo: Vec<u8> = match kind {
            // expedited download, size indicated with n = flags bits 1-2
            0 => {
                let n = (flags >> 1) & 3;
                let mut v = vec![0x23 | (n << 2) | ca, i0, i1, sub];
                v.extend_from_slice(take(&mut data, 4));
                v.resize(8, 0);
                v
            }
            // normal download: a declared size and the bytes that follow (segments may complete it)
            1 => {
                let size = u32::from(byte(&mut data));
                let k = usize::from(byte(&mut data));
                let mut v = vec![0x21 | ca, i0, i1, sub];
                v.extend_from_slice(&size.to_le_bytes());
                v.extend_from_slice(take(&mut data, k.min(200)));
                v
            }
            // download segment: toggle bit 4, last (c) bit 0, n from the length
            2 => {
                let k = usize::from(flags >> 4) % 8;
                let c = (flags >> 1) & 1;
                let t = flags & 0x10;
                let mut v = vec![t | (((7 - k.min(7)) as u8) << 1) | c];
                v.extend_from_slice(take(&mut data, k));
                v.resize(8, 0);
                v
            }
            // upload initiate
            3 => vec![0x40 | ca, i0, i1, sub, 0, 0, 0, 0],
            // upload segment with toggle
            4 => vec![0x60 | (flags & 0x10), 0, 0, 0, 0, 0, 0, 0],
            // abort from the master
            5 => {
                let mut v = vec![0x80, i0, i1, sub];
                v.extend_from_slice(take(&mut data, 4));
                v.resize(8, 0);
                v
            }
            // SDO Info: get OD list (list type from the flags)
            6 => {
                service = 8;
                vec![0x01, 0x00, 0x00, 0x00, flags % 6, 0x00]
            }
            // SDO Info: get object / entry description
            _ => {
                service = 8;
                if flags & 1 == 0 {
                    vec![0x03, 0x00, 0x00, 0x00, i0, i1]
                } else {
                    vec![0x05, 0x00, 0x00, 0x00, i0, i1, sub, 0x7F]
                }
            }
        };
        counter = counter % 7 + 1;
        let len = 2 + sdo.len();
        let mut buf = [0u8; 256];
        buf[0..2].copy_from_slice(&(len as u16).to_le_bytes());
        buf[5] = (counter << 4) | 3;
        buf[6..8].copy_from_slice(&(service << 12).to_le_bytes());
        buf[8..8 + sdo.len()].copy_from_slice(&sdo);
        m.request(&buf);
    }
});
