//! The whole exchange with profinet-py's requests as Ethernet frames, written
//! to a pcap and dissected by tshark (when installed): none of the device's
//! frames in `dcerpc || pn_io` is malformed or has an expert warning or error.
//! (profinet-py's own requests have some: its short EPM lookup, the padding of
//! its I&M writes, its nested multiple write.)

use super::tests_connect::{ccontrol_response, dev, CTRL, CTRL_MAC, OUR_MAC};
use super::tests_vectors::*;
use crate::ip::{Endpoint, IpConfig, Ipv4Addr, Received, Stack, UdpTx, RPC_PORT, UDP_PAYLOAD_OFFSET};
use crate::rpc::tests::hex;
use crate::tests_tshark::pcap;
use nanos::Nanos;
use std::vec::Vec;

const PY_EPM_LOOKUP: &str =
    "0400200010000000000000000000000000000000000000000883afe11f5dc91191a408002b14a0fa\
b0b1b2b3b4b5b6b7b8b9babbbcbdbebf0000000003000000000000000200ffffffff340000000000000000000000\
0000000000000000000000000000000000000000000000000000000000000000000000000000000000000064000000";

fn stack(mac: crate::wire::MacAddr, last: u8) -> Stack {
    Stack::new(
        mac,
        IpConfig {
            addr: Ipv4Addr::from([192, 168, 0, last]),
            netmask: Ipv4Addr::new(255, 255, 255, 0),
            gateway: Ipv4Addr::UNSPECIFIED,
        },
    )
}

fn frame(s: &mut Stack, src_port: u16, dst: Endpoint, payload: &[u8]) -> Vec<u8> {
    let mut tx = std::vec![0u8; 1600];
    tx[UDP_PAYLOAD_OFFSET..UDP_PAYLOAD_OFFSET + payload.len()].copy_from_slice(payload);
    match s
        .emit_udp(Nanos::ZERO, &mut tx, src_port, dst, payload.len())
        .unwrap()
    {
        UdpTx::Frame(n) => tx[..n].to_vec(),
        UdpTx::ArpRequest(_) => panic!("neighbour unknown"),
    }
}

#[test]
fn p041_exchange_dissects_without_malformed_packets() {
    let mut d = dev();
    let mut ctrl = stack(CTRL_MAC, 10);
    let mut devs = stack(OUR_MAC, 50);
    let dev_ep = Endpoint {
        ip: Ipv4Addr::new(192, 168, 0, 50),
        port: RPC_PORT,
    };
    ctrl.learn(Nanos::ZERO, dev_ep.ip, OUR_MAC);
    let mut frames = Vec::new();
    let mut responses = Vec::new();
    let unknown_if = {
        let mut r = hex(READ_IM0);
        r[24] = 0x11;
        r
    };
    let bad_connect = {
        let mut r = hex(CONNECT);
        r[100 + 7] = 2; // ARType 2
        r
    };
    let requests: [(&str, Vec<u8>); 11] = [
        ("epm", hex(PY_EPM_LOOKUP)),
        ("connect_refused", bad_connect),
        ("connect", hex(CONNECT)),
        ("read_im0", hex(READ_IM0)),
        ("write_im1", hex(WRITE_IM1)),
        ("write_im2", hex(WRITE_IM2)),
        ("write_multiple", hex(WRITE_MULTIPLE)),
        ("unknown_if", unknown_if),
        ("prm_end", hex(PRM_END)),
        ("ccontrol", Vec::new()),
        ("release", hex(RELEASE)),
    ];
    let mut seq = 100u32;
    let mut last_client_req = Vec::new();
    for (name, mut req) in requests {
        let from_port = if name == "ccontrol" { RPC_PORT } else { CTRL.port };
        if name == "ccontrol" {
            req = ccontrol_response(&last_client_req);
        } else if req[4] == 0 {
            req[64..68].copy_from_slice(&seq.to_be_bytes());
            seq += 1;
        }
        let f = frame(&mut ctrl, from_port, dev_ep, &req);
        let mut tx = [0u8; 64];
        let Received::Rpc(dg) = devs.receive(Nanos::ZERO, &f, &mut tx) else {
            panic!("{name}")
        };
        d.server.receive(Nanos::ZERO, dg.src, dg.payload, &mut d.cm);
        d.server.poll(Nanos::ZERO, &mut d.cm);
        frames.push(f.clone());
        let mut out = [0u8; 1472];
        while let Some((to, n)) = d.server.transmit(Nanos::ZERO, &mut out) {
            if to.port == RPC_PORT && out[1] == 0 {
                last_client_req = out[..n].to_vec();
            }
            responses.push((name, out[..n].to_vec()));
            frames.push(frame(&mut devs, RPC_PORT, to, &out[..n]));
        }
    }
    assert!(d.cm.ar().is_none());
    let dir = std::env::temp_dir();
    let path = dir.join(std::format!("profinet-rpc-{}.pcap", std::process::id()));
    std::fs::write(&path, pcap(&frames)).unwrap();
    if let Ok(dump) = std::env::var("PN_DUMP") {
        let text: Vec<std::string::String> = responses
            .iter()
            .map(|(n, r)| {
                std::format!(
                    "{n} {}",
                    r.iter()
                        .map(|b| std::format!("{b:02x}"))
                        .collect::<std::string::String>()
                )
            })
            .collect();
        std::fs::write(dump, text.join("\n")).unwrap();
    }
    let Ok(out) = std::process::Command::new("tshark")
        .args([
            "-r",
            path.to_str().unwrap(),
            "-Y",
            "(dcerpc || pn_io) && ip.src == 192.168.0.50",
            "-V",
        ])
        .output()
    else {
        std::eprintln!("tshark not installed: pcap left at {}", path.display());
        return;
    };
    let text = std::string::String::from_utf8_lossy(&out.stdout);
    let bad: Vec<&str> = text
        .lines()
        .filter(|l| {
            l.contains("Malformed")
                || l.contains("[Severity level: Warning")
                || l.contains("[Severity level: Error")
        })
        .collect();
    assert!(out.status.success(), "tshark failed");
    assert!(text.contains("PROFINET IO"), "nothing dissected as pn_io");
    let ours = text.lines().filter(|l| l.starts_with("Frame ")).count();
    assert_eq!(ours, responses.len());
    assert!(bad.is_empty(), "{}: {bad:?}", path.display());
    let _ = std::fs::remove_file(&path);
}
