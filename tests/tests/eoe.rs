//! Ethernet over EtherCAT through a real master's frames (E-095..E-097,
//! E-093): a fragmented Ethernet frame reaches the drive's EoE interface,
//! the set-IP-parameter request is answered and a refused address sends
//! EMCY FFF0h.

use drive_tests::{line, with_sdo, RawMailbox};
use ecat::eoe::{fnv1a, EoeHeader};

/// Mailbox type EoE.
const EOE: u8 = 2;

/// A 600-byte Ethernet frame (broadcast destination, EtherType 0x88B5).
fn ethernet_frame() -> Vec<u8> {
    let mut f = vec![0xFF; 6];
    f.extend_from_slice(&[0x02, 0, 0, 0, 0, 0x10]);
    f.extend_from_slice(&[0x88, 0xB5]);
    f.extend((0..586).map(|i| (i * 31 + 7) as u8));
    f
}

/// The master's EoE fragments of `f`: 224 data bytes each (a 256-byte
/// mailbox holds 246 after the two headers; all but the last carry a
/// multiple of 32).
fn fragments(f: &[u8], frame_no: u8) -> Vec<Vec<u8>> {
    let n = f.len().div_ceil(224);
    f.chunks(224)
        .enumerate()
        .map(|(i, c)| {
            let so = if i == 0 {
                f.len().div_ceil(32)
            } else {
                i * 224 / 32
            };
            let mut m = EoeHeader::fragment(i + 1 == n, i as u8, so as u8, frame_no)
                .to_bytes()
                .to_vec();
            m.extend_from_slice(c);
            m
        })
        .collect()
}

/// Set IP parameter request: IP, mask, gateway at fixed field positions,
/// addresses as little-endian UINT32s (the first octet last), as TwinCAT
/// sends it.
fn set_ip(ip: [u8; 4]) -> Vec<u8> {
    let le = |a: [u8; 4]| [a[3], a[2], a[1], a[0]];
    let mut b = vec![0x02, 0x01, 0, 0];
    b.extend_from_slice(&0x0Eu32.to_le_bytes());
    b.extend_from_slice(&[0; 6]);
    b.extend_from_slice(&le(ip));
    b.extend_from_slice(&le([255, 255, 255, 0]));
    b.extend_from_slice(&le([10, 0, 0, 1]));
    b.extend_from_slice(&[0; 36]);
    b
}

#[test]
fn e095_e096_e097_e093_eoe_through_the_simulator() {
    let sim = line(1);
    let f = ethernet_frame();
    with_sdo(&sim, async |sd, _| {
        let mut mbx = RawMailbox::new();
        // Pre-Op: a frame in three fragments; fragments have no response
        let frags = fragments(&f, 1);
        assert_eq!(frags.len(), 3);
        for m in &frags {
            assert_eq!(mbx.exchange(sd, EOE, m).await, None);
        }
        // set IP parameter: response type 3, last fragment, result 0
        let resp = mbx.exchange(sd, EOE, &set_ip([10, 0, 0, 20])).await;
        assert_eq!(resp, Some((EOE, vec![0x03, 0x01, 0x00, 0x00])));
        // E-097: the subnet's last address is refused (result 0001h) ...
        let resp = mbx.exchange(sd, EOE, &set_ip([10, 0, 0, 255])).await;
        assert_eq!(resp, Some((EOE, vec![0x03, 0x01, 0x01, 0x00])));
        // ... and EMCY FFF0h / 23h follows (E-093)
        let emcy = mbx.receive(sd).await.expect("EMCY");
        assert_eq!(emcy.0, 3, "CoE");
        assert_eq!(&emcy.1[..5], &[0x00, 0x10, 0xF0, 0xFF, 0x23]);
    });
    let s = sim.borrow();
    let drive = &s.drives()[0].drive;
    assert_eq!(drive.eoe().frames, 1);
    assert_eq!(drive.eoe().last_len, f.len());
    assert_eq!(drive.eoe().last_hash, fnv1a(&f));
    let params = drive.slave().eoe().params();
    assert_eq!(params.ip, Some([10, 0, 0, 20]));
    assert_eq!(params.mask, Some([255, 255, 255, 0]));
    assert_eq!(params.gateway, Some([10, 0, 0, 1]));
    assert!(drive.slave().eoe().address_error());
}
