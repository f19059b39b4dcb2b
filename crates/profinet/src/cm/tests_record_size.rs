//! Records of MaxSupportedRecordSize (4,068 bytes) whole and in RPC
//! fragments, and what a longer one gets: "write length error" in an
//! IODWriteRes that names the record, however the request arrived.

use super::tests_connect::{dev_with, Dev, CTRL};
use super::tests_vectors::*;
use super::*;
use crate::model::MAX_RECORD_SIZE;
use crate::rpc::header::flags1;
use crate::rpc::tests::hex;
use crate::rpc::{Header, PacketType};
use std::vec::Vec;

const INDEX: u16 = 0x2000;

/// Takes any record at index 0x2000 of slot 1 and keeps it; a read returns
/// MAX_RECORD_SIZE bytes counting up.
#[derive(Default)]
struct Big {
    written: Vec<u8>,
}

impl RecordHook for Big {
    fn read(&mut self, addr: RecordAddr, out: &mut [u8]) -> Result<usize, RecordError> {
        if addr.index != INDEX {
            return Err(RecordError::InvalidIndex);
        }
        for (k, b) in out.iter_mut().take(MAX_RECORD_SIZE).enumerate() {
            *b = k as u8;
        }
        Ok(MAX_RECORD_SIZE.min(out.len()))
    }
    fn write(&mut self, addr: RecordAddr, data: &[u8]) -> Result<(), RecordError> {
        if addr.index != INDEX {
            return Err(RecordError::InvalidIndex);
        }
        self.written = data.to_vec();
        Ok(())
    }
}

/// An IODWrite of `len` bytes (k as u8) to slot 1 subslot 1 index 0x2000, as
/// (RPC header, NDR body) built from profinet-py's I&M1 write.
fn write_request(len: usize) -> (Vec<u8>, Vec<u8>) {
    let v = hex(WRITE_IM1);
    let rpc = v[..80].to_vec();
    let mut head = v[100..164].to_vec();
    head[28..30].copy_from_slice(&1u16.to_be_bytes()); // slot 1
    head[34..36].copy_from_slice(&INDEX.to_be_bytes());
    head[36..40].copy_from_slice(&(len as u32).to_be_bytes());
    let args = 64 + len as u32;
    let mut body = Vec::new();
    for x in [0x4000u32, args, args.max(0x4000), 0, args] {
        body.extend_from_slice(&x.to_be_bytes());
    }
    body.extend_from_slice(&head);
    body.extend((0..len).map(|k| k as u8));
    (rpc, body)
}

/// Sends `body` under `rpc` in fragments of `frag` bytes (one datagram when
/// it fits), with FACKs or without; returns the response's header and body.
fn send(d: &mut Dev<Big>, rpc: &[u8], body: &[u8], frag: usize, nofack: bool) -> (Header, Vec<u8>) {
    d.seq += 1;
    let chunks: Vec<&[u8]> = body.chunks(frag).collect();
    let mut out = [0u8; 1472];
    let mut resp = Vec::new();
    let mut head = None;
    for (n, c) in chunks.iter().enumerate() {
        let mut p = rpc.to_vec();
        p[64..68].copy_from_slice(&d.seq.to_be_bytes());
        p[74..76].copy_from_slice(&(c.len() as u16).to_be_bytes());
        p[76..78].copy_from_slice(&(n as u16).to_be_bytes());
        if chunks.len() > 1 {
            p[2] |= flags1::FRAG;
            if n + 1 == chunks.len() {
                p[2] |= flags1::LASTFRAG;
            }
            if nofack {
                p[2] |= flags1::NOFACK;
            }
        }
        p.extend_from_slice(c);
        d.server.receive(Nanos::ZERO, CTRL, &p, &mut d.cm);
        d.server.poll(Nanos::ZERO, &mut d.cm);
        while let Some((_, n)) = d.server.transmit(Nanos::ZERO, &mut out) {
            let (h, b) = Header::parse(&out[..n]).unwrap();
            if h.ptype != PacketType::Fack {
                head = Some(h);
                resp.extend_from_slice(b);
            }
        }
    }
    (head.expect("an answer"), resp)
}

fn connected() -> Dev<Big> {
    let mut d = dev_with(Big::default());
    assert_eq!(d.call(CONNECT).0, PnioStatus::OK);
    d
}

/// The PNIO status and the IODWriteRes of a write answer.
fn write_res(h: &Header, body: &[u8]) -> (PnioStatus, Vec<u8>) {
    assert_eq!(h.ptype, PacketType::Response);
    let status = PnioStatus::from_u32(u32::from_be_bytes(body[0..4].try_into().unwrap()));
    (status, body[20..].to_vec())
}

#[test]
fn p041_a_4068_byte_record_is_written_whole_and_in_fragments() {
    for (frag, nofack) in [(usize::MAX, false), (1400, false), (1000, true), (333, false)] {
        let mut d = connected();
        let (rpc, body) = write_request(MAX_RECORD_SIZE);
        let (h, resp) = send(&mut d, &rpc, &body, frag, nofack);
        let (status, res) = write_res(&h, &resp);
        assert_eq!(status, PnioStatus::OK, "fragments of {frag}");
        // IODWriteRes: the record's index and length, status OK
        assert_eq!(&res[..2], &[0x80, 0x08]);
        assert_eq!(&res[34..40], &hex("2000 00000fe4")[..]);
        assert_eq!(&res[44..48], &[0; 4]);
        let want: Vec<u8> = (0..MAX_RECORD_SIZE).map(|k| k as u8).collect();
        assert_eq!(d.cm.hook().written, want);
    }
}

#[test]
fn p041_a_4068_byte_record_in_a_write_multiple_fits() {
    let mut d = connected();
    let (rpc, inner) = write_request(MAX_RECORD_SIZE);
    // an IODWriteMultiple (index 0xE040) around the one write
    let (_, outer) = write_request(inner.len() - 20);
    let mut body = outer[..20 + 64].to_vec();
    body[20 + 28..20 + 30].copy_from_slice(&[0xFF, 0xFF]);
    body[20 + 30..20 + 32].copy_from_slice(&[0xFF, 0xFF]);
    body[20 + 34..20 + 36].copy_from_slice(&[0xE0, 0x40]);
    body.extend_from_slice(&inner[20..]);
    assert!(body.len() <= crate::rpc::server::BUF);
    let (h, resp) = send(&mut d, &rpc, &body, 1400, false);
    let (status, res) = write_res(&h, &resp);
    assert_eq!(status, PnioStatus::OK);
    assert_eq!(res.len(), 64 * 2);
    assert_eq!(&res[64 + 44..64 + 48], &[0; 4]);
    assert_eq!(d.cm.hook().written.len(), MAX_RECORD_SIZE);
}

#[test]
fn p041_a_4068_byte_record_is_read_back_in_response_fragments() {
    let mut d = connected();
    let mut read = hex(READ_IM0);
    read[100 + 28..100 + 30].copy_from_slice(&1u16.to_be_bytes());
    read[100 + 34..100 + 36].copy_from_slice(&INDEX.to_be_bytes());
    read[100 + 36..100 + 40].copy_from_slice(&0x4000u32.to_be_bytes());
    read[80..84].copy_from_slice(&0x4000u32.to_be_bytes()); // ArgsMaximum
    let (rpc, body) = (read[..80].to_vec(), read[80..].to_vec());
    let (h, resp) = send(&mut d, &rpc, &body, usize::MAX, false);
    assert_eq!(h.ptype, PacketType::Response);
    assert_eq!(&resp[..4], &[0; 4]);
    let args = &resp[20..];
    assert_eq!(args.len(), 64 + MAX_RECORD_SIZE);
    assert_eq!(&args[36..40], &(MAX_RECORD_SIZE as u32).to_be_bytes());
    assert!(args[64..].iter().enumerate().all(|(k, b)| *b == k as u8));
}

#[test]
fn p041_records_above_the_maximum_get_write_length_error_with_their_header() {
    // just above (fits the RPC buffer) and far above (does not), whole and in
    // fragments: the same answer, the record named, nothing written
    for (len, frag) in [
        (MAX_RECORD_SIZE + 1, usize::MAX),
        (MAX_RECORD_SIZE + 1, 1400),
        (10_000, 1400),
        (10_000, 700),
    ] {
        let mut d = connected();
        let (rpc, body) = write_request(len);
        let (h, resp) = send(&mut d, &rpc, &body, frag, false);
        let (status, res) = write_res(&h, &resp);
        let want = PnioStatus::rw(0xDF, 0xB1);
        assert_eq!(status, want, "{len} bytes in fragments of {frag}");
        assert_eq!(res.len(), 64);
        assert_eq!(&res[..2], &[0x80, 0x08]);
        assert_eq!(&res[34..36], &INDEX.to_be_bytes());
        assert_eq!(&res[44..48], &want.to_bytes());
        assert!(d.cm.hook().written.is_empty());
        // the AR is still there
        assert!(d.cm.ar().is_some());
    }
    // a request beyond any record (over 64 KiB) is an RPC fault (no memory)
    let mut d = connected();
    let (rpc, body) = write_request(70_000);
    let (h, resp) = send(&mut d, &rpc, &body, 1400, true);
    assert_eq!(h.ptype, PacketType::Fault);
    assert_eq!(&resp[..4], &crate::rpc::nca::FAULT_REMOTE_NO_MEMORY.to_be_bytes());
}
