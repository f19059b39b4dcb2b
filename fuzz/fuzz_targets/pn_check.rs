//! The oracles of `pn_seq` on what the device sends: every frame decodes
//! with the crate's own parsers (Ethernet, IPv4/UDP, the DCE/RPC header, the
//! NDR response and its blocks, RTA headers and alarm notifications, DCP),
//! no cyclic frame while no AR exists, alarm sequence numbers as IEC
//! 61158-6-10 numbers them (0xFFFF, 0, 1, … 0x7FFF, 0; a new DATA only
//! after the last one was acknowledged, a repeat keeps its number), no
//! alarm notification longer than the AR's negotiated maximum and no
//! response longer than the request's ArgsMaximum.
#![allow(dead_code)]

use profinet::alarm::RtaHeader;
use profinet::cm::ndr::Blocks;
use profinet::cm::PnioStatus;
use profinet::dcp::pdu;
use profinet::rpc::{Header, PacketType, Uuid};
use profinet::wire::{split_frame_id, EthFrame, FrameKind};

/// A response of the device to one of our calls.
#[derive(Clone, Debug)]
pub struct Answer {
    pub seq: u32,
    pub ptype: PacketType,
    /// PNIO status and NDR args (responses only).
    pub status: Option<PnioStatus>,
    pub args: Vec<u8>,
}

/// Per alarm priority: what the device sent and what we acknowledged.
#[derive(Clone, Copy, Debug, Default)]
pub struct AlarmChannel {
    /// SendSeqNum of the device's last DATA-RTA.
    pub last: Option<u16>,
    /// Whether the controller acknowledged `last` (ACK or DATA with that AckSeqNum).
    pub acked: bool,
    /// The controller's next SendSeqNum on this channel.
    pub ctrl_send: u16,
    /// The last DATA of the device: (slot, subslot, alarm type, specifier, module, submodule).
    pub pending: Option<[u32; 6]>,
}

impl AlarmChannel {
    pub fn new() -> Self {
        AlarmChannel {
            last: None,
            acked: false,
            ctrl_send: 0xFFFF,
            pending: None,
        }
    }
}

/// What the oracles keep between operations.
#[derive(Debug)]
pub struct Seen {
    pub answers: Vec<Answer>,
    /// The device's own RPC request (ApplicationReady), header as received.
    pub app_ready: Option<Header>,
    pub alarms: [AlarmChannel; 2],
    /// A fragmented response being collected: (seq, next fragment, body).
    frag: Option<(u32, u16, Vec<u8>)>,
}

impl Seen {
    pub fn new() -> Self {
        Seen {
            answers: Vec::new(),
            app_ready: None,
            alarms: [AlarmChannel::new(), AlarmChannel::new()],
            frag: None,
        }
    }
}

/// The checks one frame sent by the device must pass. `ar_alive`: an AR
/// existed before or after the operation; `activity`: our calls'
/// activity; `args_max`: ArgsMaximum of the call in flight; `alarm_max`:
/// the AR's negotiated alarm data length.
pub fn frame(
    seen: &mut Seen,
    f: &[u8],
    ar_alive: bool,
    activity: Uuid,
    args_max: u32,
    alarm_max: Option<u16>,
) {
    let e = EthFrame::parse(f).expect("every frame has an Ethernet header");
    match e.ethertype {
        0x0800 => udp(seen, e.payload, activity, args_max),
        0x8892 => {
            let (kind, rest) = split_frame_id(e.payload).expect("a PROFINET frame has a FrameID");
            match kind {
                FrameKind::Cyclic(id) => {
                    assert!(
                        ar_alive,
                        "cyclic frame {id:#06x} without an AR (after Release or abort)"
                    );
                }
                FrameKind::AlarmHigh | FrameKind::AlarmLow => {
                    let p = usize::from(kind == FrameKind::AlarmLow);
                    alarm(&mut seen.alarms[p], rest, alarm_max)
                }
                FrameKind::DcpGetSet | FrameKind::DcpIdentifyResponse | FrameKind::DcpHello => {
                    let pkt = pdu::Packet::new_checked(rest).expect("a DCP answer has a whole header");
                    for b in pdu::Blocks::new(pkt.data()) {
                        let _ = b.expect("a DCP answer's blocks decode");
                    }
                }
                _ => {}
            }
        }
        _ => {}
    }
}

fn udp(seen: &mut Seen, ip: &[u8], activity: Uuid, args_max: u32) {
    assert!(ip.len() >= 28 && ip[9] == 17 || ip[9] != 17, "IPv4/UDP header");
    if ip[9] != 17 {
        return;
    }
    let ihl = usize::from(ip[0] & 0x0F) * 4;
    let udp = &ip[ihl..];
    let len = usize::from(u16::from_be_bytes([udp[4], udp[5]]));
    assert!(len >= 8 && len <= udp.len(), "UDP length {len} of {}", udp.len());
    let payload = &udp[8..len];
    let (h, body) = Header::parse(payload).expect("every RPC datagram of the device decodes");
    assert!(
        payload.len() <= 1464 || h.is_frag() || h.ptype != PacketType::Response,
        "an unfragmented response of {} bytes",
        payload.len()
    );
    match h.ptype {
        PacketType::Request => seen.app_ready = Some(h),
        PacketType::Response if h.activity == activity => {
            let whole = if h.is_frag() {
                let (seq, next, mut acc) = match seen.frag.take() {
                    Some(f) if f.0 == h.seq => f,
                    _ => (h.seq, 0, Vec::new()),
                };
                if h.frag_num != next {
                    return;
                }
                acc.extend_from_slice(body);
                if !h.is_last_frag() {
                    seen.frag = Some((seq, next + 1, acc));
                    return;
                }
                acc
            } else {
                body.to_vec()
            };
            let a = ndr_response(&h, &whole, args_max);
            seen.answers.push(a);
        }
        PacketType::Fault | PacketType::Reject if h.activity == activity => seen.answers.push(Answer {
            seq: h.seq,
            ptype: h.ptype,
            status: None,
            args: Vec::new(),
        }),
        _ => {}
    }
}

fn u32_at(b: &[u8], at: usize, little: bool) -> u32 {
    let a: [u8; 4] = b[at..at + 4].try_into().unwrap();
    if little {
        u32::from_le_bytes(a)
    } else {
        u32::from_be_bytes(a)
    }
}

/// The NDR response: status, ArgsLength = ActualCount, Offset 0, the body
/// exactly that long, no longer than ArgsMaximum, its blocks whole.
fn ndr_response(h: &Header, body: &[u8], args_max: u32) -> Answer {
    let little = h.drep.0[0] & 0x10 != 0;
    assert!(body.len() >= 20, "an NDR response of {} bytes", body.len());
    let status = PnioStatus::from_u32(u32_at(body, 0, little));
    let n = u32_at(body, 4, little);
    assert_eq!(u32_at(body, 12, little), 0, "NDR offset");
    assert_eq!(u32_at(body, 16, little), n, "NDR actual count");
    assert!(u32_at(body, 8, little) >= n, "NDR maximum count below the length");
    assert_eq!(body.len(), 20 + n as usize, "NDR args length");
    assert!(
        n <= args_max,
        "a response of {n} bytes for ArgsMaximum {args_max}"
    );
    let args = body[20..].to_vec();
    if h.opnum == 2 || h.opnum == 5 {
        // IODReadResHeader, then RecordDataLength bytes of the record
        if !args.is_empty() {
            let mut b = Blocks::new(&args);
            let blk = b
                .next_block()
                .expect("a read response block")
                .expect("a whole read response header");
            assert_eq!(blk.block_type, 0x8009);
            assert_eq!(blk.body.len(), 58, "IODReadResHeader length");
            let rec = u32::from_be_bytes(blk.body[30..34].try_into().unwrap()) as usize;
            assert_eq!(b.remaining(), rec, "RecordDataLength and the record's bytes");
        }
    } else {
        let mut b = Blocks::new(&args);
        while let Some(blk) = b.next_block() {
            let Ok(blk) = blk else {
                panic!(
                    "a response (opnum {}) with a broken block: {:02x?}",
                    h.opnum,
                    &args[..args.len().min(96)]
                );
            };
            if blk.block_type == 0x8008 {
                assert_eq!(blk.body.len(), 58, "IODWriteResHeader length");
            }
        }
    }
    Answer {
        seq: h.seq,
        ptype: h.ptype,
        status: Some(status),
        args,
    }
}

/// A DATA-RTA's SendSeqNum is 0xFFFF first, then a repeat or the next
/// number after the controller acknowledged the last; its notification
/// fits the negotiated maximum.
fn alarm(ch: &mut AlarmChannel, rest: &[u8], alarm_max: Option<u16>) {
    let (h, var) = RtaHeader::parse(rest).expect("every RTA PDU of the device decodes");
    if h.pdu_type != profinet::alarm::PduType::Data {
        return;
    }
    let s = h.send_seq;
    assert!(s == 0xFFFF || s <= 0x7FFF, "SendSeqNum {s:#06x}");
    match ch.last {
        None => assert!(s == 0xFFFF || s == 0, "first DATA-RTA with SendSeqNum {s:#06x}"),
        Some(l) if l == s => {}
        Some(l) => {
            assert_eq!(s, profinet::alarm::rta::next_seq(l), "DATA-RTA after {l:#06x}");
            assert!(
                ch.acked,
                "a new DATA-RTA {s:#06x} before {l:#06x} was acknowledged"
            );
        }
    }
    if ch.last != Some(s) {
        ch.acked = false;
    }
    ch.last = Some(s);
    if let Some(max) = alarm_max {
        // the AlarmNotification block's length beyond its fixed fields
        assert!(
            var.len() <= usize::from(max) + 6,
            "alarm notification {} bytes, max {max}",
            var.len()
        );
    }
    if var.len() >= 26 {
        let u16_at = |i: usize| u32::from(u16::from_be_bytes([var[i], var[i + 1]]));
        let u32_at = |i: usize| u32::from_be_bytes(var[i..i + 4].try_into().unwrap());
        ch.pending = Some([
            u16_at(12),
            u16_at(14),
            u16_at(6),
            u16_at(24),
            u32_at(16),
            u32_at(20),
        ]);
    }
}
