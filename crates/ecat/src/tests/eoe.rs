//! Ethernet over EtherCAT: the test Ethernet port, fragments to and from the master, set-IP and
//! get-IP requests (E-093, E-095..E-098).

use super::*;

/// The application's Ethernet side for the EoE tests.
#[derive(Default)]
struct Port {
    received: Vec<Vec<u8>>,
    to_send: Vec<Vec<u8>>,
    ip_changes: usize,
}

impl crate::eoe::EthernetPort for Port {
    fn receive(&mut self, frame: &[u8]) {
        self.received.push(frame.to_vec());
    }
    fn transmit(&mut self, buf: &mut [u8]) -> Option<usize> {
        if self.to_send.is_empty() {
            return None;
        }
        let f = self.to_send.remove(0);
        buf[..f.len()].copy_from_slice(&f);
        Some(f.len())
    }
    fn ip_changed(&mut self, _: &crate::eoe::IpParams) {
        self.ip_changes += 1;
    }
}

impl Rig {
    fn poll_eth(&mut self, port: &mut Port) {
        self.t += Nanos::from_ms(1);
        let Ok(_) = self.slave.poll_with_eoe(
            &mut self.esc,
            &mut self.app,
            &mut crate::foe::NoFiles,
            port,
            self.t,
        );
    }
    /// Sends one EoE mailbox message (`eoe`: EoE header + data) with `counter`.
    fn eoe(&mut self, port: &mut Port, eoe: &[u8], counter: u8) -> Option<Vec<u8>> {
        let mut req = Vec::from((eoe.len() as u16).to_le_bytes());
        req.extend_from_slice(&[0, 0, 0, 0x02 | (counter << 4)]);
        req.extend_from_slice(eoe);
        self.esc.mbx_write(&req);
        self.poll_eth(port);
        self.esc.mbx_read()
    }
}

/// A test frame of `n` bytes.
fn eth_frame(n: usize) -> Vec<u8> {
    (0..n).map(|i| (i * 13 + 1) as u8).collect()
}

/// EoE fragments of `f` in `chunk`-byte pieces (EoE header + data each).
fn eoe_fragments(f: &[u8], chunk: usize, frame_no: u8) -> Vec<Vec<u8>> {
    crate::eoe::tests::fragments(f, chunk, frame_no)
        .into_iter()
        .map(|(h, c)| {
            let mut m = h.to_bytes().to_vec();
            m.extend_from_slice(&c);
            m
        })
        .collect()
}

/// A set-IP request in the fixed layout, addresses as little-endian
/// UINT32s (the first octet last), as TwinCAT sends it.
fn set_ip_request(ip: [u8; 4]) -> Vec<u8> {
    let le = |a: [u8; 4]| [a[3], a[2], a[1], a[0]];
    let mut b = Vec::from([0x02u8, 0x01, 0, 0]);
    b.extend_from_slice(&0x0Eu32.to_le_bytes()); // IP, mask, gateway
    b.extend_from_slice(&[0; 6]);
    b.extend_from_slice(&le(ip));
    b.extend_from_slice(&le([255, 255, 255, 0]));
    b.extend_from_slice(&le([10, 0, 0, 1]));
    b.extend_from_slice(&[0; 36]);
    b
}

/// A get-IP-parameter request (EoE header only): the master shows that
/// it uses EoE.
const GET_IP: [u8; 4] = [0x06, 0x01, 0x00, 0x00];

#[test]
fn e095_eoe_frames_in_preop_safeop_op_not_in_init() {
    let mut r = Rig::new();
    let mut port = Port::default();
    let f = eth_frame(300);
    // Init: no mailbox at all
    assert!(r.eoe(&mut port, &eoe_fragments(&f, 96, 1)[0], 1).is_none());
    assert_ne!(r.esc.events() & al_event::sm(0), 0, "SM0 not read in Init");
    r.esc.set_events(0);
    let mut counter = 0;
    for (k, state) in [AlState::PreOp, AlState::SafeOp, AlState::Op]
        .into_iter()
        .enumerate()
    {
        r.goto(state);
        for m in eoe_fragments(&f, 96, k as u8) {
            counter = counter % 7 + 1;
            assert!(
                r.eoe(&mut port, &m, counter).is_none(),
                "fragments have no response"
            );
        }
        assert_eq!(port.received.len(), k + 1, "{state:?}");
        assert_eq!(port.received[k], f);
        assert_eq!(r.req(1), (1, 0));
    }
    assert_eq!(r.slave.eoe().stats().frames_received, 3);
    assert_eq!(r.slave.eoe().stats().frames_dropped, 0);
}

#[test]
fn e095_eoe_out_of_order_fragment_drops_the_frame() {
    let mut r = Rig::new();
    let mut port = Port::default();
    r.goto(AlState::PreOp);
    let frags = eoe_fragments(&eth_frame(300), 96, 3);
    r.eoe(&mut port, &frags[0], 1);
    r.eoe(&mut port, &frags[2], 2);
    r.eoe(&mut port, &frags[3], 3);
    assert!(port.received.is_empty());
    assert_eq!(r.slave.eoe().stats().frames_dropped, 2);
    // the next frame arrives whole
    for (i, m) in frags.iter().enumerate() {
        r.eoe(&mut port, m, (i % 7 + 4) as u8 % 8);
    }
    assert_eq!(port.received.len(), 1);
}

#[test]
fn e095_eoe_frames_to_the_master_one_fragment_per_mailbox() {
    let mut r = Rig::new();
    let mut port = Port::default();
    r.goto(AlState::PreOp);
    let resp = r.eoe(&mut port, &GET_IP, 1).unwrap();
    assert_eq!(resp[6], 0x07, "get IP response");
    let f = eth_frame(400);
    port.to_send.push(f.clone());
    port.to_send.push(eth_frame(60));
    let mut got = crate::eoe::Reassembly::new();
    let mut frames = Vec::new();
    let mut messages = 0;
    for _ in 0..20 {
        r.poll_eth(&mut port);
        if let Some(m) = r.esc.mbx_read() {
            messages += 1;
            let len = usize::from(u16::from_le_bytes([m[0], m[1]]));
            assert_eq!(m[5] & 0x0F, 2, "EoE");
            assert!(len <= 128 - 6);
            let h = crate::eoe::EoeHeader::parse(&m[6..]).unwrap();
            if let Some(n) = got.push(&h, &m[10..6 + len]).unwrap() {
                frames.push(got.frame()[..n].to_vec());
            }
        }
    }
    // 118 data bytes per mailbox: 96 + 96 + 96 + 112, and one for the 60-byte frame
    assert_eq!(messages, 5);
    assert_eq!(frames, [f, eth_frame(60)]);
    assert_eq!(r.slave.eoe().stats().frames_sent, 2);
    // leaving for Init drops a frame in transmission
    port.to_send.push(eth_frame(400));
    r.poll_eth(&mut port);
    assert!(r.slave.eoe().sending());
    r.esc.request(1);
    r.poll_eth(&mut port);
    assert!(!r.slave.eoe().sending());
}

/// SDO upload request of 1008h with `counter`, written into SM0.
fn upload_request(counter: u8) -> [u8; 16] {
    [
        10,
        0,
        0,
        0,
        0,
        0x03 | (counter << 4),
        0x00,
        0x20,
        0x40,
        0x08,
        0x10,
        0,
        0,
        0,
        0,
        0,
    ]
}

#[test]
fn e098_no_unasked_eoe_before_the_master_uses_eoe() {
    let mut r = Rig::new();
    let mut port = Port::default();
    r.goto(AlState::PreOp);
    // the IP stack has frames to send (a DHCP DISCOVER, say) from the start
    port.to_send.extend((0..4).map(|_| eth_frame(300)));
    // a master that speaks only CoE: every answer is its SDO response
    for k in 0..2000u32 {
        let counter = (k % 7 + 1) as u8;
        r.esc.mbx_write(&upload_request(counter));
        r.poll_eth(&mut port);
        let m = r.esc.mbx_read().expect("an answer to each upload");
        assert_eq!(
            m[5],
            0x03 | (counter << 4),
            "request {k}: CoE with the request's counter"
        );
        assert_eq!(m[8] >> 5, 2, "request {k}: SDO upload response");
        // and nothing else between the requests
        r.poll_eth(&mut port);
        assert_eq!(r.esc.mbx_read(), None, "request {k}: no unasked message");
    }
    assert_eq!(port.to_send.len(), 4, "not one frame taken");
    assert!(!r.slave.eoe().master_active());
    // the master uses EoE: the frames go out
    r.eoe(&mut port, &GET_IP, 1).unwrap();
    assert!(r.slave.eoe().master_active());
    let mut eoe = 0;
    for _ in 0..40 {
        r.poll_eth(&mut port);
        if let Some(m) = r.esc.mbx_read() {
            assert_eq!(m[5] & 0x0F, 2, "EoE");
            eoe += 1;
        }
    }
    assert!(eoe >= 4, "{eoe} EoE messages");
    assert!(port.to_send.is_empty());
    // back through Init: silent again until the master uses EoE again
    assert_eq!(r.req(1), (1, 0));
    r.goto(AlState::PreOp);
    assert!(!r.slave.eoe().master_active());
    port.to_send.push(eth_frame(100));
    for _ in 0..20 {
        r.poll_eth(&mut port);
        assert_eq!(r.esc.mbx_read(), None);
    }
}

#[test]
fn e096_e097_e093_set_ip_through_the_mailbox() {
    let mut r = Rig::new();
    let mut port = Port::default();
    r.goto(AlState::PreOp);
    let resp = r.eoe(&mut port, &set_ip_request([10, 0, 0, 7]), 1).unwrap();
    // mailbox: 4 bytes EoE, set IP response, last fragment, result 0
    assert_eq!(&resp[..10], &[4, 0, 0, 0, 0, 0x12, 0x03, 0x01, 0x00, 0x00]);
    assert_eq!(r.slave.eoe().params().ip, Some([10, 0, 0, 7]));
    assert_eq!(r.slave.eoe().params().gateway, Some([10, 0, 0, 1]));
    assert_eq!(port.ip_changes, 1);
    // E-097: the last address of the subnet is refused, EMCY FFF0h/23h follows
    let resp = r.eoe(&mut port, &set_ip_request([10, 0, 0, 255]), 2).unwrap();
    assert_eq!(&resp[6..10], &[0x03, 0x01, 0x01, 0x00]);
    assert_eq!(r.slave.eoe().params().ip, Some([10, 0, 0, 7]));
    r.poll_eth(&mut port);
    let emcy = r.esc.mbx_read().unwrap();
    assert_eq!(emcy[5] & 0x0F, 3, "CoE");
    assert_eq!(&emcy[6..11], &[0x00, 0x10, 0xF0, 0xFF, 0x23]);
    // the first address too
    let resp = r.eoe(&mut port, &set_ip_request([10, 0, 0, 0]), 3).unwrap();
    assert_eq!(&resp[8..10], &[0x01, 0x00]);
    assert_eq!(port.ip_changes, 1);
}

#[test]
fn e095_eoe_unsupported_without_the_sii_protocol() {
    static NO_EOE: Device = Device {
        mailbox_protocols: mailbox_protocol::COE,
        ..DEV_DESC
    };
    let mut r = Rig::with(&NO_EOE);
    let mut port = Port::default();
    r.goto(AlState::PreOp);
    let resp = r.eoe(&mut port, &set_ip_request([10, 0, 0, 7]), 1).unwrap();
    assert_eq!(&resp[..10], &[4, 0, 0, 0, 0, 0x10, 0x01, 0x00, 0x02, 0x00]);
}
