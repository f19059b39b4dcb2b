//! The BMP request and response through tshark's PROFIdrive dissector
//! (pn_io dissects record 0xB02E): each inside a PNIO record write request
//! and read response over DCE/RPC, as a controller would carry them.

use std::string::String;
use std::vec::Vec;

use profinet::testing::{hex, udp_to_device};

use crate::bmp;
use crate::fake::Fake;
use crate::Addr;

/// DCE/RPC request header (big-endian drep) of a PNIO call: opnum 2 read /
/// 3 write, activity a0…af, sequence `seq`; fragment length patched later.
fn rpc(ptype: u8, opnum: u16, seq: u32) -> Vec<u8> {
    let mut v = hex(
        "04002000000000 00 dea000006c9711d1827100010001fefe dea000016c9711d1827100a02442df7d \
         a0a1a2a3a4a5a6a7a8a9aaabacadaeaf 00000000 00000001",
    )
    .to_vec();
    v[1] = ptype;
    v.extend_from_slice(&seq.to_be_bytes());
    v.extend_from_slice(&opnum.to_be_bytes());
    v.extend_from_slice(&hex("ffff ffff 0000 0000 00 00"));
    v
}

fn finish(mut v: Vec<u8>) -> Vec<u8> {
    let frag = (v.len() - 80) as u16;
    v[74..76].copy_from_slice(&frag.to_be_bytes());
    v
}

/// IODWriteReq / IODReadReq / IODReadRes header block for 0xB02E at 1/1.
fn block(kind: u16, seq: u16, data_len: usize) -> Vec<u8> {
    let mut v = Vec::new();
    v.extend_from_slice(&kind.to_be_bytes());
    v.extend_from_slice(&hex("003c 0100"));
    v.extend_from_slice(&seq.to_be_bytes());
    v.extend_from_slice(&hex(
        "101112131415161718191a1b1c1d1e1f 00000000 0001 0001 0000 b02e",
    ));
    v.extend_from_slice(&(data_len as u32).to_be_bytes());
    v.extend_from_slice(&[0; 24]);
    v
}

/// A PNIO call: the RPC header (`ptype`, `opnum`, `seq`), the NDR
/// arguments (`first`: the maximum or the status, then the length, its
/// maximum, offset and actual count), the record block `kind` for
/// `block_len` bytes, then `data`.
fn call(ptype: u8, opnum: u16, first: u32, seq: u32, kind: u16, block_len: usize, data: &[u8]) -> Vec<u8> {
    let mut v = rpc(ptype, opnum, seq);
    let args = 64 + data.len() as u32;
    for x in [first, args, 4000, 0, args] {
        v.extend_from_slice(&x.to_be_bytes());
    }
    v.extend(block(kind, seq as u16, block_len));
    v.extend_from_slice(data);
    finish(v)
}

fn write_request(seq: u32, data: &[u8]) -> Vec<u8> {
    call(0, 3, 4000, seq, 0x0008, data.len(), data)
}

fn read_request(seq: u32) -> Vec<u8> {
    call(0, 2, 4000, seq, 0x0009, 4000, &[])
}

fn read_response(seq: u32, data: &[u8]) -> Vec<u8> {
    call(2, 2, 0, seq, 0x8009, data.len(), data)
}

fn pcap(frames: &[Vec<u8>]) -> Vec<u8> {
    let mut p = Vec::new();
    for v in [0xa1b2_c3d4u32, 0x0004_0002, 0, 0, 65535, 1] {
        p.extend_from_slice(&v.to_le_bytes());
    }
    for (i, f) in frames.iter().enumerate() {
        let len = f.len() as u32;
        for v in [i as u32, 0, len, len] {
            p.extend_from_slice(&v.to_le_bytes());
        }
        p.extend_from_slice(f);
    }
    p
}

/// `tshark -V` over `frames`, `None` when tshark is not installed.
fn dissect(frames: &[Vec<u8>]) -> Option<String> {
    let path = std::env::temp_dir().join(std::format!("profidrive-tshark-{}.pcap", std::process::id()));
    std::fs::write(&path, pcap(frames)).ok()?;
    let Ok(out) = std::process::Command::new("tshark")
        .args(["-r", &path.to_string_lossy(), "-V"])
        .output()
    else {
        std::eprintln!("tshark not installed");
        return None;
    };
    assert!(out.status.success());
    let _ = std::fs::remove_file(&path);
    Some(String::from_utf8_lossy(&out.stdout).into_owned())
}

fn frame(payload: &[u8]) -> Vec<u8> {
    udp_to_device(payload).to_vec()
}

#[test]
fn p206_bmp_requests_and_responses_dissect_as_profidrive_parameters() {
    let mut f = Fake::drive();
    f.set(Addr::new(1100, 0), -2);
    f.set(Addr::new(1050, 0), 3);
    let mut frames = Vec::new();
    let mut out = [0u8; 240];
    // a read of two parameters (one I32, one I8 with its pad byte), a
    // change of two, and a read with an error
    let reads: [&[u8]; 3] = [
        &hex("01 01 01 02 10 01 044c 0000 10 01 041a 0000"),
        &hex("02 02 01 02 10 01 03e9 0000 10 01 041a 0000 04 01 000004d2 02 01 fd 00"),
        &hex("03 01 01 01 10 01 5555 0000"),
    ];
    for (i, req) in reads.iter().enumerate() {
        let seq = 2 * i as u32 + 1;
        let n = bmp::serve(req, &mut f, &mut out).expect("answered");
        frames.push(frame(&write_request(seq, req)));
        frames.push(frame(&read_request(seq + 1)));
        frames.push(frame(&read_response(seq + 1, &out[..n])));
    }
    let Some(text) = dissect(&frames) else { return };
    let bad: Vec<&str> = text
        .lines()
        .filter(|l| {
            l.contains("Malformed")
                || l.contains("[Severity level: Error")
                || l.contains("Unknown Formatvalue")
                || l.contains("Expert Info")
        })
        .collect();
    // the one pad byte after the odd byte value, which this dissector
    // (tshark 4.0) does not expect: a "long frame" after the last value
    assert_eq!(
        bad,
        ["        [Expert Info (Warning/Protocol): Long frame]"],
        "{text}"
    );
    for want in [
        "PROFIDrive Parameter Request: ReqRef:0x01, ReqId:Read request, DO:1, NoOfParameters:2",
        "Parameter Address 1: Attr:Value, Elems:1, Parameter:1100, Index:0",
        "PROFIDrive Parameter Response: ReqRef:0x01, RspId:Positive read response, DO:1, NoOfParameters:2",
        "Parameter Value 1: Format:Integer32, NoOfVals:1",
        "Value: 0xfffffffe",
        "Parameter Value 2: Format:Integer8, NoOfVals:1",
        "PROFIDrive Parameter Request: ReqRef:0x02, ReqId:Change request, DO:1, NoOfParameters:2",
        "Value: 0x000004d2",
        "Value: 0xfd",
        "PROFIDrive Parameter Response: ReqRef:0x02, RspId:Positive change response, DO:1, NoOfParameters:2",
        "PROFIDrive Parameter Response: ReqRef:0x03, RspId:Negative read response, DO:1, NoOfParameters:1",
        "Error Number: Disallowed parameter number (0x0000)",
    ] {
        assert!(text.contains(want), "{want} missing:\n{text}");
    }
    assert_eq!(f.value(Addr::new(1001, 0)), 1234);
    assert_eq!(f.value(Addr::new(1050, 0)), -3);
}
