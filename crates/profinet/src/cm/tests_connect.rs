use super::tests_vectors::*;
use super::*;
use crate::ip::{Endpoint, Ipv4Addr};
use crate::rpc::tests::hex;
use crate::rpc::{epm, uuid, Drep, Header, PacketType, Server, ServerConfig};
use std::vec::Vec;

pub(crate) const OUR_MAC: MacAddr = MacAddr([0x02, 0, 0, 0, 0, 0x01]);
pub(crate) const CTRL_MAC: MacAddr = MacAddr([0x02, 0, 0, 0, 0, 0xC0]);
pub(crate) const CTRL: Endpoint = Endpoint {
    ip: Ipv4Addr::new(192, 168, 0, 10),
    port: 50001,
};
pub(crate) const AR_UUID: Uuid = Uuid([
    0x10, 0x11, 0x12, 0x13, 0x14, 0x15, 0x16, 0x17, 0x18, 0x19, 0x1a, 0x1b, 0x1c, 0x1d, 0x1e, 0x1f,
]);

pub(crate) fn im0() -> Im0 {
    Im0 {
        vendor_id: crate::model::VENDOR_ID,
        order_id: record::visible("BL4000-C"),
        serial_number: record::visible("SN0001"),
        hardware_revision: 1,
        software_revision: (b'V', 1, 0, 0),
        revision_counter: 0,
        profile_id: 0xF600,
        profile_specific_type: 0,
        im_version: 0x0101,
        im_supported: 0x001E,
    }
}

/// The device's RPC and CM, wired like the firmware does.
pub(crate) struct Dev<H: RecordHook = NoRecords> {
    pub server: Server,
    pub cm: Cm<H>,
    /// Sequence number given to the next request fed by [`Dev::call`].
    pub seq: u32,
}

pub(crate) fn dev_with<H: RecordHook>(hook: H) -> Dev<H> {
    Dev {
        server: Server::new(ServerConfig {
            boot_time: 1,
            epm: epm::EpmInfo {
                object: uuid::pnio_object(1, crate::model::DEVICE_ID, crate::model::VENDOR_ID),
                ip: Ipv4Addr::new(192, 168, 0, 50),
                port: 34964,
                annotation: epm::annotation(crate::model::STATION_TYPE, "BL4000-C", 1, (b'V', 1, 0, 0)),
            },
        }),
        cm: Cm::new(
            CmConfig {
                mac: OUR_MAC,
                im0: im0(),
            },
            ImData::default(),
            hook,
        ),
        seq: 100,
    }
}

pub(crate) fn dev() -> Dev {
    dev_with(NoRecords)
}

impl<H: RecordHook> Dev<H> {
    /// Feeds one datagram and returns every datagram due. A big-endian
    /// request gets a fresh sequence number (the vectors repeat theirs).
    pub fn rx(&mut self, d: &[u8]) -> Vec<(Endpoint, Vec<u8>)> {
        let mut d = d.to_vec();
        if d[1] == 0 && d[4] == 0 {
            d[64..68].copy_from_slice(&self.seq.to_be_bytes());
            self.seq += 1;
        }
        self.server.receive(Nanos::ZERO, CTRL, &d, &mut self.cm);
        self.server.poll(Nanos::ZERO, &mut self.cm);
        let mut v = Vec::new();
        let mut out = [0u8; 1472];
        while let Some((p, n)) = self.server.transmit(Nanos::ZERO, &mut out) {
            v.push((p, out[..n].to_vec()));
        }
        v
    }

    /// Feeds a request, returns the single response's PNIO status and NDR args.
    /// The request gets a fresh sequence number (the vectors repeat theirs).
    pub fn call(&mut self, req: &str) -> (PnioStatus, Vec<u8>) {
        let out = self.rx(&hex(req));
        let (h, body) = Header::parse(&out[0].1).unwrap();
        assert_eq!((h.ptype, h.drep), (PacketType::Response, Drep::BIG));
        let status = PnioStatus::from_u32(u32::from_be_bytes(body[0..4].try_into().unwrap()));
        let len = u32::from_be_bytes(body[4..8].try_into().unwrap()) as usize;
        assert_eq!(body[16..20], body[4..8]);
        assert_eq!(body.len(), 20 + len);
        (status, body[20..].to_vec())
    }
}

/// Patches the NDR args of a request (offset `at` into the args) with `b`.
pub(crate) fn patch(req: &str, at: usize, b: &[u8]) -> std::string::String {
    let mut d = hex(req);
    d[100 + at..100 + at + b.len()].copy_from_slice(b);
    d.iter().map(|x| std::format!("{x:02x}")).collect()
}

const CONNECT_RES: &str = "8101001e0100 0001 101112131415161718191a1b1c1d1e1f 0101 020000000001 8892
    81020008 0100 0001 0001 c001
    81020008 0100 0002 0002 c102
    81030008 0100 0001 0001 00c8";

#[test]
fn p041_connect_from_profinet_py_is_accepted() {
    let mut d = dev();
    let (status, args) = d.call(CONNECT);
    assert_eq!(status, PnioStatus::OK);
    assert_eq!(args, hex(CONNECT_RES));
    assert_eq!(d.cm.poll_event(), Some(CmEvent::Connected(AR_UUID)));
    let ar = d.cm.ar().unwrap();
    assert_eq!(
        (ar.ar_type, ar.session_key, ar.controller_mac, ar.state),
        (ArType::IoCarSingle, 0x0101, CTRL_MAC, ArState::Parameterising)
    );
    assert_eq!(
        ar.controller_rpc,
        Endpoint {
            ip: CTRL.ip,
            port: 34964
        }
    );
    assert_eq!(&ar.controller_station[..], b"tp");
    assert_eq!(ar.controller_object, uuid::pnio_object(1, 0x7654, 0x3210));
    let i = ar.input_cr.as_ref().unwrap();
    assert_eq!(
        (i.frame_id, i.data_length, i.reduction_ratio, i.phase),
        (0xC001, 42, 8, 1)
    );
    assert_eq!(
        (i.cycle(), i.watchdog(), i.data_hold()),
        (Nanos::from_ms(8), Nanos::from_ms(48), Nanos::from_ms(48))
    );
    assert_eq!(i.vlan_tci, 0xC000);
    // Input CR: IOPS of the four DAP subslots, 36 bytes + IOPS of slot 1, IOCS of slot 2.
    let offs: Vec<_> = i
        .data
        .iter()
        .map(|o| (o.slot, o.subslot, o.frame_offset, o.data_len))
        .collect();
    assert_eq!(
        offs,
        [
            (0, 1, 0, 0),
            (0, 0x8000, 1, 0),
            (0, 0x8001, 2, 0),
            (0, 0x8002, 3, 0),
            (1, 1, 4, 36)
        ]
    );
    assert_eq!(
        i.iocs
            .iter()
            .map(|o| (o.slot, o.frame_offset))
            .collect::<Vec<_>>(),
        [(2, 41)]
    );
    let o = ar.output_cr.as_ref().unwrap();
    assert_eq!((o.frame_id, o.reference), (0xC102, 2));
    assert_eq!(
        o.data
            .iter()
            .map(|o| (o.slot, o.frame_offset, o.data_len))
            .collect::<Vec<_>>(),
        [(2, 0, 36)]
    );
    assert_eq!(o.iocs.len(), 5);
    let a = ar.alarm_cr.unwrap();
    assert_eq!(
        (
            a.controller_ref,
            a.device_ref,
            a.rta_retries,
            a.timeout(),
            a.max_alarm_data_length
        ),
        (1, 1, 3, Nanos::from_ms(100), 200)
    );
    assert!(!ar.has_diff());
}

#[test]
fn p028_ar_reports_the_module_lengths_configured_by_the_controller() {
    let mut d = dev();
    d.call(CONNECT);
    let ar = d.cm.ar().unwrap();
    use crate::model::Direction;
    assert_eq!(
        ar.submodule(1, 1).unwrap().telegram(),
        Some((Direction::FromDrive, 36))
    );
    assert_eq!(
        ar.submodule(2, 1).unwrap().telegram(),
        Some((Direction::ToDrive, 36))
    );
    assert_eq!(ar.submodule(2, 1).unwrap().data, SubmoduleData::Output(36));
    assert_eq!(ar.submodule(0, 0x8001).unwrap().telegram(), None);
}

#[test]
fn p029_wrong_and_unknown_module_idents_give_a_module_diff_and_still_connect() {
    let mut d = dev();
    let (status, args) = d.call(CONNECT_DIFF);
    assert_eq!(status, PnioStatus::OK);
    // After ARBlockRes (34), 2 × IOCRBlockRes (12), AlarmCRBlockRes (12):
    let diff = &args[34 + 36..];
    assert_eq!(
        diff,
        &hex("8104 0040 0100 0001 00000000 0003
              0001 00000202 0001 0001  0001 00000001 9000
              0002 00000000 0000 0001  0001 00000000 9800
              0003 00000000 0000 0001  0001 00000000 9800")[..]
    );
    let ar = d.cm.ar().unwrap();
    let fits: Vec<_> = ar.submodules.iter().map(|s| (s.slot, s.fit)).collect();
    assert_eq!(
        fits[4..],
        [
            (1, Fit::WrongModule),
            (2, Fit::NoModule),
            // the model has data slots 1 and 2 only (the GSDML's PhysicalSlots)
            (3, Fit::NoModule)
        ]
    );
    assert!(ar.submodules.iter().skip(4).all(|s| s.telegram().is_none()));
}

#[test]
fn p041_connect_refusals_name_block_and_field_and_change_nothing() {
    // Offsets into the NDR args: ARBlockReq at 0 (60 bytes), input IOCRBlockReq at 60.
    let cases: [(usize, &[u8], PnioStatus); 9] = [
        (6, &[0x00, 0x02], PnioStatus::connect(1, 4)),        // ARType
        (48, &[0, 0, 0, 0x10], PnioStatus::connect(1, 9)),    // ARProperties state 0
        (54, &[0x08, 0x00], PnioStatus::connect(1, 11)),      // InitiatorUDPRTPort
        (60 + 10, &[0x08, 0x00], PnioStatus::connect(2, 6)),  // LT
        (60 + 22, &[0x00, 0x03], PnioStatus::connect(2, 11)), // ReductionRatio 3
        (60 + 16, &[0x00, 0x10], PnioStatus::connect(2, 8)),  // DataLength 16
        (60 + 36, &[0xC0, 0x05], PnioStatus::connect(2, 17)), // IOCRTagHeader VLAN 5
        (60 + 4, &[0x02], PnioStatus::connect(2, 2)),         // BlockVersionHigh
        (0, &[0x01, 0x99], PnioStatus::cmrpc(0xDB, 1)),       // unknown block type
    ];
    for (at, bytes, want) in cases {
        let mut d = dev();
        let (status, args) = d.call(&patch(CONNECT, at, bytes));
        assert_eq!(status, want, "patch at {at}");
        assert!(args.is_empty());
        assert!(d.cm.ar().is_none());
        assert_eq!(d.cm.poll_event(), None);
    }
    // AlarmCRBlockReq RTARetries 1 -> field 8; its block starts after two IOCRs (90 each).
    let alarm = 60 + 90 + 90;
    let mut d = dev();
    assert_eq!(
        d.call(&patch(CONNECT, alarm + 16, &[0, 1])).0,
        PnioStatus::connect(4, 8)
    );
    // An ExpectedSubmodule data description of LengthIOPS 2 -> field 15.
    let exp = alarm + 26;
    let mut d = dev();
    assert_eq!(
        d.call(&patch(CONNECT, exp + 35, &[2])).0,
        PnioStatus::connect(3, 15)
    );
    assert_eq!(PnioStatus::connect(3, 15).to_u32(), 0xDB81_030F);
}

#[test]
fn p041_a_second_controller_is_refused_and_the_same_one_supersedes() {
    let mut d = dev();
    d.call(CONNECT);
    let _ = d.cm.poll_event();
    // Another AR UUID and session from another MAC: out of AR resources.
    let other = patch(&patch(CONNECT, 8, &[0x77; 16]), 26, &[2, 0, 0, 0, 0, 0xC1]);
    assert_eq!(d.call(&other).0, PnioStatus::cmrpc(0xDB, 4));
    // The same controller with a new AR UUID replaces its old AR.
    assert_eq!(d.call(&patch(CONNECT, 8, &[0x55; 16])).0, PnioStatus::OK);
    assert_eq!(
        d.cm.poll_event(),
        Some(CmEvent::Aborted(AR_UUID, AbortReason::Superseded))
    );
    assert_eq!(d.cm.poll_event(), Some(CmEvent::Connected(Uuid([0x55; 16]))));
}

/// The controller's CControl answer to our ApplicationReady, as profinet-py's
/// `application_ready()` builds it (flags 0x0A, our drep echoed, status 0,
/// IODControlRes 0x8112 with Done).
pub(crate) fn ccontrol_response(req: &[u8]) -> Vec<u8> {
    let (h, body) = Header::parse(req).unwrap();
    let e = h.drep.endian();
    let max_count = match e {
        crate::rpc::Endian::Little => u32::from_le_bytes(body[8..12].try_into().unwrap()),
        crate::rpc::Endian::Big => u32::from_be_bytes(body[8..12].try_into().unwrap()),
    };
    let mut block = hex("8112 001c 0100 0000");
    block.extend_from_slice(&AR_UUID.0);
    block.extend_from_slice(&hex("0101 0000 0008 0000"));
    let mut ndr = Vec::new();
    for v in [0, block.len() as u32, max_count, 0, block.len() as u32] {
        ndr.extend_from_slice(&v.to_le_bytes());
    }
    ndr.extend_from_slice(&block);
    let r = Header {
        ptype: PacketType::Response,
        flags1: 0x0A,
        boot_time: 0,
        body_len: ndr.len() as u16,
        serial: 0,
        ..h
    };
    let mut out = std::vec![0u8; 80];
    r.emit(&mut out).unwrap();
    out.extend_from_slice(&ndr);
    out
}

#[test]
fn p041_prm_end_application_ready_and_release() {
    let mut d = dev();
    d.call(CONNECT);
    let _ = d.cm.poll_event();
    // PrmEnd: IODControlRes 0x8110 with Done, then our ApplicationReady request.
    let out = d.rx(&hex(PRM_END));
    assert_eq!(out.len(), 2);
    let (_, body) = Header::parse(&out[0].1).unwrap();
    let mut want = hex("00000000 20000000 20000000 00000000 20000000 8110 001c 0100 0000");
    want[0..20].copy_from_slice(&hex("00000000 00000020 00000fa0 00000000 00000020"));
    want.extend_from_slice(&AR_UUID.0);
    want.extend_from_slice(&hex("0101 0000 0008 0000"));
    assert_eq!(body, &want[..]);
    assert_eq!(d.cm.poll_event(), Some(CmEvent::PrmEnd(AR_UUID)));
    assert_eq!(d.cm.ar().unwrap().state, ArState::ApplicationReadyPending);
    let (to, req) = &out[1];
    assert_eq!(
        *to,
        Endpoint {
            ip: CTRL.ip,
            port: 34964
        }
    );
    let (h, body) = Header::parse(req).unwrap();
    assert_eq!(
        (h.ptype, h.opnum, h.interface, h.object, h.drep),
        (
            PacketType::Request,
            4,
            uuid::PNIO_CONTROLLER_INTERFACE,
            uuid::pnio_object(1, 0x7654, 0x3210),
            Drep::LITTLE
        )
    );
    // NDR (little-endian) + IODControlReq 0x0112 ApplicationReady; profinet-py looks for
    // the block type at 0 and the command at 28 of the args.
    assert_eq!(
        &body[..20],
        &hex("00010000 20000000 00010000 00000000 20000000")[..]
    );
    assert_eq!(&body[20..28], &hex("0112 001c 0100 0000")[..]);
    assert_eq!(&body[20 + 28..20 + 30], &[0, 2]);
    // The controller confirms (profinet-py's own answer to these bytes): data exchange.
    assert_eq!(ccontrol_response(req), hex(CCONTROL_RESPONSE));
    let out = d.rx(&hex(CCONTROL_RESPONSE));
    assert_eq!(Header::parse(&out[0].1).unwrap().0.ptype, PacketType::Ack);
    assert_eq!(d.cm.poll_event(), Some(CmEvent::Ready(AR_UUID)));
    assert_eq!(d.cm.ar().unwrap().state, ArState::Data);
    // A second PrmEnd is a state conflict.
    assert_eq!(d.call(PRM_END).0, PnioStatus::cmrpc(0xDD, 6));
    // Release: IODReleaseRes 0x8114 with Done, the AR is gone.
    let (status, args) = d.call(RELEASE);
    assert_eq!(status, PnioStatus::OK);
    assert_eq!(&args[..8], &hex("8114 001c 0100 0000")[..]);
    assert_eq!(&args[28..30], &[0, 8]);
    assert_eq!(d.cm.poll_event(), Some(CmEvent::Released(AR_UUID)));
    assert!(d.cm.ar().is_none());
}

#[test]
fn p041_application_ready_without_answer_aborts_the_ar() {
    let mut d = dev();
    d.call(CONNECT);
    d.rx(&hex(PRM_END));
    let _ = (d.cm.poll_event(), d.cm.poll_event());
    let mut t = Nanos::ZERO;
    let mut buf = [0u8; 1472];
    for _ in 0..10 {
        t += crate::rpc::server::CLIENT_RETRY;
        d.server.poll(t, &mut d.cm);
        while d.server.transmit(t, &mut buf).is_some() {}
    }
    assert_eq!(
        d.cm.poll_event(),
        Some(CmEvent::Aborted(
            AR_UUID,
            AbortReason::ApplicationReadyFailed(crate::rpc::ClientError::Timeout)
        ))
    );
    assert!(d.cm.ar().is_none());
}
