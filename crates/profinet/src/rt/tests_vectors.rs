//! Cyclic frames exactly as profinet-py 0.6.6 (the CI controller) sends
//! them, and our frames as it reads them. The vectors were printed by its
//! builders (`rt.build_iocr_configs`, `rt.CyclicDataBuilder`,
//! `rt.build_ethernet_frame`): SCF 32, RR 32, output CR 0x8000, input CR
//! 0xC001, DataLength 42, tag 0xC000.

use super::tests::{input_cr, output_cr, CTL, DEV};
use super::*;
use crate::wire::EthFrame;

/// Decodes a hex string (test helper).
pub(crate) fn hex(s: &str) -> std::vec::Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
        .collect()
}

/// Writes `frames` as a pcap file `name` into `$PROFINET_PCAP_DIR` when that
/// is set (for `tshark -Y "pn_rt || pn_io"`); does nothing otherwise.
pub(crate) fn write_pcap(name: &str, frames: &[std::vec::Vec<u8>]) {
    let Some(dir) = std::env::var_os("PROFINET_PCAP_DIR") else {
        return;
    };
    let mut out = std::vec::Vec::new();
    out.extend_from_slice(&0xA1B2_C3D4u32.to_le_bytes());
    out.extend_from_slice(&2u16.to_le_bytes());
    out.extend_from_slice(&4u16.to_le_bytes());
    out.extend_from_slice(&[0; 8]);
    out.extend_from_slice(&65535u32.to_le_bytes());
    out.extend_from_slice(&1u32.to_le_bytes());
    for (i, f) in frames.iter().enumerate() {
        out.extend_from_slice(&(i as u32).to_le_bytes());
        out.extend_from_slice(&0u32.to_le_bytes());
        out.extend_from_slice(&(f.len() as u32).to_le_bytes());
        out.extend_from_slice(&(f.len() as u32).to_le_bytes());
        out.extend_from_slice(f);
    }
    std::fs::write(std::path::Path::new(&dir).join(name), out).unwrap();
}

/// `CyclicController._send_output_frame`: output data 1…36 for slot 2, IOPS
/// and every IOCS GOOD, counter 1024 (its first frame: 0 + SCF × RR),
/// DataStatus 0x35, priority-tagged 0xC000.
const PY_OUTPUT_FRAME: &str = "0200000000020200000000018100c000889280000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f202122232480808080808004003500";

#[test]
fn p042_consumer_takes_profinet_py_output_frame() {
    let f = hex(PY_OUTPUT_FRAME);
    assert_eq!(f.len(), 66);
    let mut c = Consumer::new(output_cr()).unwrap();
    let r = c.receive(Nanos::ZERO, &EthFrame::parse(&f).unwrap()).unwrap();
    assert_eq!(r.cycle_counter, 1024);
    assert_eq!(r.status, DataStatus::RUNNING);
    let out = r.outputs.unwrap();
    assert_eq!(
        out.data(2, 1).unwrap(),
        &(1..=36).collect::<std::vec::Vec<u8>>()[..]
    );
    for s in [0x0001, 0x8000, 0x8001, 0x8002] {
        assert_eq!(out.iocs(0, s), Some(Ioxs::GOOD));
    }
    assert_eq!(out.iocs(1, 1), Some(Ioxs::GOOD));
    // its stop frames (ProviderState cleared, 0x25) keep the AR but not the data
    let mut stop = f.clone();
    stop[62..64].copy_from_slice(&2048u16.to_be_bytes());
    stop[64] = 0x25;
    let r = c
        .receive(Nanos::from_ms(32), &EthFrame::parse(&stop).unwrap())
        .unwrap();
    assert_eq!(r.outputs.unwrap_err(), Invalid::ProviderStop);
    assert_eq!(r.changed, DataStatus::PROVIDER_RUN);
}

/// What profinet-py requires of our input frames
/// (`CyclicController._process_input_frame`, `RTFrame.from_bytes`): source =
/// the device, EtherType 0x8892 after any tag, the input CR's FrameID, the
/// APDU status in the **last** four bytes (so nothing may follow it), DataValid
/// set and TransferStatus 0, each IOPS with bit 7 for GOOD right after its
/// data; it counts a counter step other than SCF × RR as a gap.
#[test]
fn p042_provider_frames_satisfy_profinet_py_input_parser() {
    let mut p = Provider::new(input_cr(), Nanos::ZERO).unwrap();
    p.set_all_iops(Ioxs::GOOD);
    p.set_all_iocs(Ioxs::GOOD);
    let mut frames = std::vec::Vec::new();
    let mut buf = [0u8; 256];
    for k in 0..4u64 {
        let mut f = p.poll(Nanos::from_ms(32 * k), &mut buf).unwrap().unwrap();
        f.set_data(1, 1, &[k as u8 + 0x10; 36]);
        frames.push(f.bytes().to_vec());
    }
    let want0 = std::format!(
        "{}{}8100c0008892c001{}{}80{}{}",
        "020000000001",
        "020000000002",
        "80808080",
        "10".repeat(36),
        "80",
        "00003500"
    );
    assert_eq!(frames[0], hex(&want0));
    for (k, f) in frames.iter().enumerate() {
        let n = f.len();
        assert_eq!(&f[6..12], &DEV.0);
        assert_eq!(&f[..6], &CTL.0);
        assert_eq!(u16::from_be_bytes([f[n - 4], f[n - 3]]), 1024 * k as u16);
        assert!(f[n - 2] & DataStatus::DATA_VALID != 0);
        assert_eq!(f[n - 1], 0);
        assert!(n >= 60);
    }
    write_pcap("rt_input_cr.pcap", &frames);
    let mut all = frames;
    all.push(hex(PY_OUTPUT_FRAME));
    write_pcap("rt_both.pcap", &all);
}
