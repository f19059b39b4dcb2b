use super::tests_connect::{self, dev, dev_with, patch};
use super::tests_vectors::*;
use super::*;
use crate::rpc::tests::hex;

/// The NDR args of a read/write: header offsets.
const INDEX_AT: usize = 34;

const IM0: &str = "0020 0038 0100 fefe
    424c343030302d43202020202020202020202020 534e3030303120202020202020202020
    0001 56010000 0000 f600 0000 0101 001e";

#[test]
fn p039_im0_read_returns_the_identity() {
    let mut d = dev();
    d.call(CONNECT);
    let (status, args) = d.call(READ_IM0);
    assert_eq!(status, PnioStatus::OK);
    let mut head = hex("8009 003c 0100 0000");
    head.extend_from_slice(&tests_connect::AR_UUID.0);
    head.extend_from_slice(&hex("00000000 0000 0001 0000 aff0 0000003c 0000 0000"));
    head.extend_from_slice(&[0; 20]);
    assert_eq!(&args[..64], &head[..]);
    assert_eq!(&args[64..], &hex(IM0)[..]);
}

#[test]
fn p039_im0_implicit_read_needs_no_ar_and_other_subslots_have_none() {
    let mut d = dev();
    let mut r = hex(READ_IM0);
    r[68..70].copy_from_slice(&5u16.to_be_bytes()); // opnum: implicit read
    let r: std::string::String = r.iter().map(|x| std::format!("{x:02x}")).collect();
    let (status, args) = d.call(&r);
    assert_eq!((status, &args[64..]), (PnioStatus::OK, &hex(IM0)[..]));
    // A normal read without the AR: AR UUID unknown, answered with the
    // IODReadRes header naming the record (no record data).
    let (status, args) = d.call(READ_IM0);
    assert_eq!(status, PnioStatus::cmrpc(0xDE, 5));
    assert_eq!(
        (args.len(), &args[..2], &args[34..36]),
        (64, &[0x80, 0x09][..], &[0xAF, 0xF0][..])
    );
    // A write without the AR: the IODWriteRes header with the status in it.
    let (status, args) = d.call(WRITE_IM1);
    assert_eq!(status, PnioStatus::cmrpc(0xDF, 5));
    assert_eq!(args.len(), 64);
    assert_eq!(
        (&args[..2], &args[34..36]),
        (&[0x80, 0x08][..], &[0xAF, 0xF1][..])
    );
    assert_eq!(&args[44..48], &PnioStatus::cmrpc(0xDF, 5).to_bytes());
    assert_eq!(d.cm.im_data(), &ImData::default());
    d.call(CONNECT);
    // I&M0 at the interface subslot: invalid index; at a missing subslot: invalid slot/subslot.
    let at_if = patch(READ_IM0, 30, &[0x80, 0x00]);
    assert_eq!(d.call(&at_if).0, PnioStatus::rw(0xDE, 0xB0));
    let missing = patch(READ_IM0, 28, &[0, 9]);
    assert_eq!(d.call(&missing).0, PnioStatus::rw(0xDE, 0xB2));
    let unknown = patch(READ_IM0, INDEX_AT, &[0x12, 0x34]);
    let (status, args) = d.call(&unknown);
    assert_eq!(
        status,
        PnioStatus {
            code: 0xDE,
            decode: 0x80,
            code1: 0xB0,
            code2: 0
        }
    );
    assert_eq!(args.len(), 64); // the header names the record
}

#[test]
fn p039_im1_im2_writes_from_profinet_py_are_stored_and_reported() {
    let mut d = dev();
    d.call(CONNECT);
    let _ = d.cm.poll_event();
    let (status, args) = d.call(WRITE_IM1);
    assert_eq!(status, PnioStatus::OK);
    assert_eq!(
        (&args[..2], &args[44..48]),
        (&[0x80, 0x08][..], &[0, 0, 0, 0][..])
    );
    assert_eq!(d.cm.poll_event(), Some(CmEvent::ImWritten(ImRecord::Im1)));
    assert_eq!(&d.cm.im_data().tag_function[..8], b"Axis 1  ");
    assert_eq!(&d.cm.im_data().tag_location[..9], b"Cabinet 3");
    assert_eq!(d.call(WRITE_IM2).0, PnioStatus::OK);
    assert_eq!(&d.cm.im_data().date, b"2024-05-28 10:30");
    // Read back in the standard layout (no padding): block 0x0021, length 56.
    let read = patch(READ_IM0, INDEX_AT, &[0xAF, 0xF1]);
    let (status, args) = d.call(&read);
    assert_eq!(status, PnioStatus::OK);
    assert_eq!(&args[64..70], &hex("0021 0038 0100")[..]);
    assert_eq!(&args[70..76], b"Axis 1");
    assert_eq!(args.len(), 64 + 60);
}

#[test]
fn p039_im_writes_of_wrong_length_or_to_im0_are_refused() {
    let mut d = dev();
    d.call(CONNECT);
    let im0 = patch(WRITE_IM1, INDEX_AT, &[0xAF, 0xF0]);
    let (status, args) = d.call(&im0);
    assert_eq!(status, PnioStatus::rw(0xDF, 0xB6));
    assert_eq!(&args[44..48], &[0xDF, 0x80, 0xB6, 0x00]);
    // I&M1 block with its length one short.
    let short = patch(WRITE_IM1, 64 + 2, &[0x00, 0x39]);
    assert_eq!(d.call(&short).0, PnioStatus::rw(0xDF, 0xB1));
    // I&M3 carrying an I&M1 block: invalid parameter.
    let mismatched = patch(WRITE_IM1, INDEX_AT, &[0xAF, 0xF3]);
    assert_eq!(d.call(&mismatched).0, PnioStatus::rw(0xDF, 0xB8));
    assert_eq!(&d.cm.im_data().tag_function, &[b' '; 32]);
}

#[test]
fn p041_write_multiple_answers_each_write() {
    // profinet-py wraps its multiple write into a second E040 header; the
    // nested one is flattened and each sub-write answered: raw bytes are no
    // I&M block, so both get "write length error", and so does the whole.
    let mut d = dev();
    d.call(CONNECT);
    let (status, args) = d.call(WRITE_MULTIPLE);
    assert_eq!(status, PnioStatus::rw(0xDF, 0xB1));
    assert_eq!(&args[INDEX_AT..INDEX_AT + 6], &hex("e040 00000080")[..]);
    assert_eq!(&args[44..48], &[0xDF, 0x80, 0xB1, 0x00]);
    assert_eq!(args.len(), 64 * 3);
    for (k, index) in [(1, 0xAFF3u16), (2, 0xAFF2)] {
        let r = &args[64 * k..64 * (k + 1)];
        assert_eq!(&r[..2], &[0x80, 0x08]);
        assert_eq!(&r[INDEX_AT..INDEX_AT + 2], &index.to_be_bytes());
        assert_eq!(&r[44..48], &[0xDF, 0x80, 0xB1, 0x00]);
    }
}

struct Param(u32);

impl RecordHook for Param {
    fn read(&mut self, addr: RecordAddr, out: &mut [u8]) -> Result<usize, RecordError> {
        match (addr.slot, addr.index) {
            (1, 0x1000) => {
                out[..4].copy_from_slice(&self.0.to_be_bytes());
                Ok(4)
            }
            (_, 0x1000) => Err(RecordError::InvalidSlotSubslot),
            _ => Err(RecordError::InvalidIndex),
        }
    }

    fn write(&mut self, addr: RecordAddr, data: &[u8]) -> Result<(), RecordError> {
        if addr.index != 0x1000 {
            return Err(RecordError::InvalidIndex);
        }
        self.0 = u32::from_be_bytes(data.try_into().map_err(|_| RecordError::WriteLength)?);
        Ok(())
    }
}

#[test]
fn p041_other_records_go_to_the_hook() {
    let mut d = dev_with(Param(0x1122_3344));
    d.call(CONNECT);
    let read = patch(&patch(READ_IM0, INDEX_AT, &[0x10, 0x00]), 28, &[0, 1]);
    let (status, args) = d.call(&read);
    assert_eq!(
        (status, &args[64..]),
        (PnioStatus::OK, &[0x11, 0x22, 0x33, 0x44][..])
    );
    assert_eq!(&args[36..40], &[0, 0, 0, 4]);
    let (status, _) = d.call(&patch(READ_IM0, INDEX_AT, &[0x10, 0x00]));
    assert_eq!(status, PnioStatus::rw(0xDE, 0xB2));
    // ModuleDiff read (0xE002) of a proper AR: no APIs.
    let (status, args) = d.call(&patch(READ_IM0, INDEX_AT, &[0xE0, 0x02]));
    assert_eq!(
        (status, &args[64..]),
        (PnioStatus::OK, &hex("8104 0004 0100 0000")[..])
    );
}

/// A request like `vector`'s (its RPC header, big-endian) with opnum `op`,
/// ArgsMaximum `max` and NDR args `args`; the answer's status and args.
fn call_with(
    d: &mut tests_connect::Dev,
    vector: &str,
    op: u16,
    max: u32,
    args: &[u8],
) -> (PnioStatus, std::vec::Vec<u8>) {
    let mut req = hex(vector)[..80].to_vec();
    req[68..70].copy_from_slice(&op.to_be_bytes());
    req[74..76].copy_from_slice(&((20 + args.len()) as u16).to_be_bytes());
    let n = args.len() as u32;
    for v in [max, n, max.max(n), 0, n] {
        req.extend_from_slice(&v.to_be_bytes());
    }
    req.extend_from_slice(args);
    let out = d.rx(&req);
    let (_, body) = crate::rpc::Header::parse(&out[0].1).unwrap();
    let status = PnioStatus::from_u32(u32::from_be_bytes(body[0..4].try_into().unwrap()));
    let len = u32::from_be_bytes(body[4..8].try_into().unwrap()) as usize;
    assert_eq!(body.len(), 20 + len);
    (status, body[20..].to_vec())
}

#[test]
fn p041_a_small_args_maximum_gets_whole_blocks_or_none_and_changes_nothing() {
    // Found by the pn_seq fuzz target: with an ArgsMaximum below a record
    // header's 64 bytes the answer ended in half an IODReadResHeader, and a
    // multiple write without room for every answer did its first sub-writes
    // and then answered with an error.
    let mut d = dev();
    d.call(CONNECT);
    let no_room = PnioStatus::cmrpc(0xDE, cmrpc::OUT_OF_RESOURCES);
    let read_args = &hex(READ_IM0)[100..];
    assert_eq!(
        call_with(&mut d, READ_IM0, 2, 40, read_args),
        (no_room, std::vec![])
    );
    // the same for a refusal with a header (a read on an unknown AR; found
    // again by pn_seq after the unknown-AR answers got their header)
    let mut unknown_ar = read_args.to_vec();
    unknown_ar[8] ^= 0xFF;
    let (status, args) = call_with(&mut d, READ_IM0, 2, 40, &unknown_ar);
    assert!(!status.is_ok());
    assert_eq!(args.len(), 0, "half an IODReadResHeader: {args:02x?}");
    let im1 = hex(WRITE_IM1)[100..].to_vec();
    let (status, args) = call_with(&mut d, WRITE_IM1, 3, 40, &im1);
    assert_eq!(
        (status, args.len()),
        (PnioStatus::cmrpc(0xDF, cmrpc::OUT_OF_RESOURCES), 0)
    );
    assert_eq!(d.cm.im_data(), &ImData::default());
    // a multiple write of I&M1 and I&M2 with room for two of its three answers
    let im2 = hex(WRITE_IM2)[100..].to_vec();
    let mut subs = im1.clone();
    while subs.len() % 4 != 0 {
        subs.push(0);
    }
    subs.extend_from_slice(&im2);
    let mut multi = im1[..64].to_vec();
    multi[INDEX_AT..INDEX_AT + 2].copy_from_slice(&index::WRITE_MULTIPLE.to_be_bytes());
    multi[36..40].copy_from_slice(&(subs.len() as u32).to_be_bytes());
    multi.extend_from_slice(&subs);
    let (status, args) = call_with(&mut d, WRITE_IM1, 3, 128, &multi);
    assert_eq!(
        (status, args.len()),
        (PnioStatus::cmrpc(0xDF, cmrpc::OUT_OF_RESOURCES), 0)
    );
    assert_eq!(d.cm.im_data(), &ImData::default());
    // with room for all three, both are written
    let (status, args) = call_with(&mut d, WRITE_IM1, 3, 192, &multi);
    assert_eq!((status, args.len()), (PnioStatus::OK, 192));
    assert_ne!(d.cm.im_data(), &ImData::default());
}

/// An IODWriteMultipleReq (args) of the given sub-writes (each a whole
/// IODWriteReq: header and record), padded to 4 bytes between them.
fn multiple(subs: &[&[u8]]) -> std::vec::Vec<u8> {
    let mut body = std::vec::Vec::new();
    for s in subs {
        while body.len() % 4 != 0 {
            body.push(0);
        }
        body.extend_from_slice(s);
    }
    let mut multi = subs[0][..64].to_vec();
    multi[INDEX_AT..INDEX_AT + 2].copy_from_slice(&index::WRITE_MULTIPLE.to_be_bytes());
    multi[36..40].copy_from_slice(&(body.len() as u32).to_be_bytes());
    multi.extend_from_slice(&body);
    multi
}

#[test]
fn p041_write_multiple_with_a_refused_sub_write_is_an_error_and_keeps_the_good_ones() {
    // I&M1 (good), I&M0 (read only: access denied), I&M2 (good): each is
    // answered with its own status; the outer header and the NDR status carry
    // the refusal, and the good ones are written.
    let mut d = dev();
    d.call(CONNECT);
    let im1 = hex(WRITE_IM1)[100..].to_vec();
    let im2 = hex(WRITE_IM2)[100..].to_vec();
    let mut im0 = im1.clone();
    im0[INDEX_AT..INDEX_AT + 2].copy_from_slice(&[0xAF, 0xF0]);
    let (status, args) = call_with(&mut d, WRITE_IM1, 3, 1024, &multiple(&[&im1, &im0, &im2]));
    let denied = PnioStatus::rw(0xDF, 0xB6);
    assert_eq!(status, denied);
    assert_eq!(args.len(), 64 * 4);
    assert_eq!(&args[INDEX_AT..INDEX_AT + 2], &[0xE0, 0x40]);
    assert_eq!(&args[44..48], &denied.to_bytes());
    assert_eq!(&args[36..40], &(64u32 * 3).to_be_bytes());
    let sub = |k: usize| &args[64 * k..64 * (k + 1)];
    assert_eq!(
        (&sub(1)[INDEX_AT..INDEX_AT + 2], &sub(1)[44..48]),
        (&[0xAF, 0xF1][..], &[0u8; 4][..])
    );
    assert_eq!(
        (&sub(2)[INDEX_AT..INDEX_AT + 2], &sub(2)[44..48]),
        (&[0xAF, 0xF0][..], &denied.to_bytes()[..])
    );
    assert_eq!(
        (&sub(3)[INDEX_AT..INDEX_AT + 2], &sub(3)[44..48]),
        (&[0xAF, 0xF2][..], &[0u8; 4][..])
    );
    assert_eq!(&d.cm.im_data().tag_function[..8], b"Axis 1  ");
    assert_eq!(&d.cm.im_data().date, b"2024-05-28 10:30");
    // all good: the outer status is OK
    let (status, args) = call_with(&mut d, WRITE_IM1, 3, 1024, &multiple(&[&im1, &im2]));
    assert_eq!((status, &args[44..48]), (PnioStatus::OK, &[0u8; 4][..]));
}

#[test]
fn p041_refused_writes_answer_with_a_full_iod_write_res_header() {
    // Wireshark marks an IODWriteRes with ArgsLength 0 malformed: every
    // refusal of a write whose header parses names the record in a header.
    let mut d = dev();
    d.call(CONNECT);
    let im1 = hex(WRITE_IM1)[100..].to_vec();
    // a multiple write whose sub-record runs past its end
    let mut cut = multiple(&[&im1]);
    let n = cut.len() as u32 - 64;
    cut[64 + 36..64 + 40].copy_from_slice(&(n + 8).to_be_bytes());
    let (status, args) = call_with(&mut d, WRITE_IM1, 3, 1024, &cut);
    assert_eq!(status, PnioStatus::rw(0xDF, 0xB1));
    assert_eq!(args.len(), 64);
    assert_eq!(
        (&args[..2], &args[INDEX_AT..INDEX_AT + 2], &args[44..48]),
        (&[0x80, 0x08][..], &[0xE0, 0x40][..], &status.to_bytes()[..])
    );
    // a write to an unknown index, one too long for its data, one to a missing subslot
    for (patched, want) in [
        (patch(WRITE_IM1, INDEX_AT, &[0x12, 0x34]), 0xB0),
        (patch(WRITE_IM1, 36, &[0, 0, 0x10, 0]), 0xB1),
        (patch(WRITE_IM1, 28, &[0, 9]), 0xB2),
    ] {
        let (status, args) = d.call(&patched);
        assert_eq!(status, PnioStatus::rw(0xDF, want), "{want:#x}");
        assert_eq!((args.len(), &args[..2]), (64, &[0x80, 0x08][..]));
        assert_eq!(&args[44..48], &status.to_bytes());
    }
    assert_eq!(d.cm.im_data(), &ImData::default());
}

#[test]
fn p040_real_identification_data_without_an_ar_is_the_dap() {
    let mut d = dev();
    let mut r = hex(&patch(READ_IM0, INDEX_AT, &[0xF0, 0x00]));
    r[68..70].copy_from_slice(&5u16.to_be_bytes()); // opnum: implicit read
    let r: std::string::String = r.iter().map(|x| std::format!("{x:02x}")).collect();
    let (status, args) = d.call(&r);
    assert_eq!(status, PnioStatus::OK);
    assert_eq!(
        &args[64..],
        &hex("0013 002a 0101 0001 00000000 0001
              0000 00000001 0004 0001 00000001 8000 00008000 8001 00008001 8002 00008002")[..]
    );
}
