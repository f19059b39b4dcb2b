//! Ethernet II / IEEE 802.1Q framing and PROFINET FrameID dispatch.
//!
//! [`EthFrame::parse`] checks a received frame once and hands out its fields and
//! payload; [`emit_header`] writes a header in front of a payload a caller then
//! fills. Frames shorter than their header are refused, never indexed.

/// A MAC address.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct MacAddr(pub [u8; 6]);

impl MacAddr {
    /// ff:ff:ff:ff:ff:ff.
    pub const BROADCAST: MacAddr = MacAddr([0xFF; 6]);
    /// 01:0e:cf:00:00:00, the PROFINET DCP Identify multicast.
    pub const DCP_IDENTIFY: MacAddr = MacAddr([0x01, 0x0E, 0xCF, 0x00, 0x00, 0x00]);
    /// 01:0e:cf:00:00:01, the DCP Hello multicast.
    pub const DCP_HELLO: MacAddr = MacAddr([0x01, 0x0E, 0xCF, 0x00, 0x00, 0x01]);
    /// 01:80:c2:00:00:0e, the LLDP nearest-bridge multicast.
    pub const LLDP: MacAddr = MacAddr([0x01, 0x80, 0xC2, 0x00, 0x00, 0x0E]);

    /// Group (multicast or broadcast) bit set.
    pub const fn is_multicast(self) -> bool {
        self.0[0] & 1 != 0
    }
}

/// EtherTypes the device handles.
pub mod ethertype {
    /// IPv4.
    pub const IPV4: u16 = 0x0800;
    /// ARP.
    pub const ARP: u16 = 0x0806;
    /// IEEE 802.1Q VLAN tag.
    pub const VLAN: u16 = 0x8100;
    /// PROFINET real time (RT cyclic, RTA alarms, DCP).
    pub const PROFINET: u16 = 0x8892;
    /// LLDP.
    pub const LLDP: u16 = 0x88CC;
}

/// Length of an untagged Ethernet II header.
pub const HEADER_LEN: usize = 14;
/// Length of the 802.1Q tag.
pub const VLAN_TAG_LEN: usize = 4;
/// Smallest Ethernet payload (frames are padded to 60 bytes before the FCS).
pub const MIN_FRAME_LEN: usize = 60;

/// A received Ethernet frame, checked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EthFrame<'a> {
    /// Destination.
    pub dst: MacAddr,
    /// Source.
    pub src: MacAddr,
    /// 802.1Q TCI (priority, DEI, VLAN ID) if the frame was tagged.
    pub vlan_tci: Option<u16>,
    /// The EtherType after any VLAN tag.
    pub ethertype: u16,
    /// Everything after the header (may include padding).
    pub payload: &'a [u8],
}

fn mac_at(b: &[u8], at: usize) -> Option<MacAddr> {
    let s = b.get(at..at + 6)?;
    let mut m = [0u8; 6];
    m.copy_from_slice(s);
    Some(MacAddr(m))
}

fn be16(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_be_bytes([*b.get(at)?, *b.get(at + 1)?]))
}

impl<'a> EthFrame<'a> {
    /// Parses a frame (without FCS); `None` if it is shorter than its header.
    pub fn parse(frame: &'a [u8]) -> Option<EthFrame<'a>> {
        let dst = mac_at(frame, 0)?;
        let src = mac_at(frame, 6)?;
        let outer = be16(frame, 12)?;
        let (vlan_tci, ethertype, at) = if outer == ethertype::VLAN {
            (
                Some(be16(frame, 14)?),
                be16(frame, 16)?,
                HEADER_LEN + VLAN_TAG_LEN,
            )
        } else {
            (None, outer, HEADER_LEN)
        };
        Some(EthFrame {
            dst,
            src,
            vlan_tci,
            ethertype,
            payload: frame.get(at..)?,
        })
    }
}

/// Writes an Ethernet header (with an 802.1Q tag if `vlan_tci` is given) at the
/// start of `buf` and returns its length, or `None` if `buf` is too short.
pub fn emit_header(
    buf: &mut [u8],
    dst: MacAddr,
    src: MacAddr,
    vlan_tci: Option<u16>,
    ethertype: u16,
) -> Option<usize> {
    let len = HEADER_LEN + if vlan_tci.is_some() { VLAN_TAG_LEN } else { 0 };
    let h = buf.get_mut(..len)?;
    let (d, rest) = h.split_at_mut(6);
    d.copy_from_slice(&dst.0);
    let (s, rest) = rest.split_at_mut(6);
    s.copy_from_slice(&src.0);
    match (vlan_tci, rest) {
        (Some(tci), [a, b, c, d, e, f]) => {
            [*a, *b] = ethertype::VLAN.to_be_bytes();
            [*c, *d] = tci.to_be_bytes();
            [*e, *f] = ethertype.to_be_bytes();
        }
        (None, [a, b]) => [*a, *b] = ethertype.to_be_bytes(),
        _ => return None,
    }
    Some(len)
}

/// What a PROFINET frame (EtherType 0x8892) is, by its FrameID.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameKind {
    /// RT_CLASS_1 cyclic data: 0x8000…0xBFFF and 0xC000…0xFBFF (controllers
    /// number their CRs in either range; both are accepted).
    Cyclic(u16),
    /// Alarm high priority (0xFC01).
    AlarmHigh,
    /// Alarm low priority (0xFE01).
    AlarmLow,
    /// DCP Hello (0xFEFC).
    DcpHello,
    /// DCP Get/Set (0xFEFD).
    DcpGetSet,
    /// DCP Identify request (0xFEFE).
    DcpIdentifyRequest,
    /// DCP Identify response (0xFEFF).
    DcpIdentifyResponse,
    /// Anything else (RT_CLASS_3, PTCP, reserved): dropped and counted.
    Other(u16),
}

impl FrameKind {
    /// Classifies a FrameID.
    pub const fn of(frame_id: u16) -> FrameKind {
        match frame_id {
            0x8000..=0xFBFF => FrameKind::Cyclic(frame_id),
            0xFC01 => FrameKind::AlarmHigh,
            0xFE01 => FrameKind::AlarmLow,
            0xFEFC => FrameKind::DcpHello,
            0xFEFD => FrameKind::DcpGetSet,
            0xFEFE => FrameKind::DcpIdentifyRequest,
            0xFEFF => FrameKind::DcpIdentifyResponse,
            other => FrameKind::Other(other),
        }
    }

    /// The FrameID of a kind.
    pub const fn frame_id(self) -> u16 {
        match self {
            FrameKind::Cyclic(id) | FrameKind::Other(id) => id,
            FrameKind::AlarmHigh => 0xFC01,
            FrameKind::AlarmLow => 0xFE01,
            FrameKind::DcpHello => 0xFEFC,
            FrameKind::DcpGetSet => 0xFEFD,
            FrameKind::DcpIdentifyRequest => 0xFEFE,
            FrameKind::DcpIdentifyResponse => 0xFEFF,
        }
    }
}

/// Splits a PROFINET payload (after the EtherType) into its FrameID kind and the
/// bytes after the FrameID; `None` if it is shorter than the FrameID.
pub fn split_frame_id(payload: &[u8]) -> Option<(FrameKind, &[u8])> {
    let id = be16(payload, 0)?;
    Some((FrameKind::of(id), payload.get(2..)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tagged_and_untagged_frames_parse_and_round_trip() {
        let mut buf = [0u8; 64];
        let src = MacAddr([2, 0, 0, 0, 0, 1]);
        let n = emit_header(
            &mut buf,
            MacAddr::DCP_IDENTIFY,
            src,
            Some(0xC000),
            ethertype::PROFINET,
        )
        .unwrap();
        assert_eq!(n, 18);
        buf[18..20].copy_from_slice(&0xFEFEu16.to_be_bytes());
        let f = EthFrame::parse(&buf).unwrap();
        assert_eq!(
            (f.dst, f.src, f.vlan_tci, f.ethertype),
            (MacAddr::DCP_IDENTIFY, src, Some(0xC000), 0x8892)
        );
        assert_eq!(
            split_frame_id(f.payload).unwrap().0,
            FrameKind::DcpIdentifyRequest
        );
        let n = emit_header(&mut buf, MacAddr::BROADCAST, src, None, ethertype::ARP).unwrap();
        assert_eq!(n, 14);
        let f = EthFrame::parse(&buf).unwrap();
        assert_eq!((f.vlan_tci, f.ethertype, f.payload.len()), (None, 0x0806, 50));
    }

    #[test]
    fn p042_cyclic_frame_ids_cover_both_rt_class_1_numberings() {
        assert_eq!(FrameKind::of(0x8001), FrameKind::Cyclic(0x8001));
        assert_eq!(FrameKind::of(0xC000), FrameKind::Cyclic(0xC000));
        assert_eq!(FrameKind::of(0xFBFF), FrameKind::Cyclic(0xFBFF));
        assert_eq!(FrameKind::of(0x0100), FrameKind::Other(0x0100));
        assert_eq!(FrameKind::of(0xFC01).frame_id(), 0xFC01);
    }

    #[test]
    fn short_frames_are_refused() {
        for len in 0..14 {
            assert!(EthFrame::parse(&[0u8; 20][..len]).is_none());
        }
        let mut tagged = [0u8; 17];
        tagged[12..14].copy_from_slice(&0x8100u16.to_be_bytes());
        assert!(EthFrame::parse(&tagged).is_none());
        assert!(split_frame_id(&[0x80]).is_none());
        assert!(emit_header(&mut [0u8; 13], MacAddr::BROADCAST, MacAddr::BROADCAST, None, 1).is_none());
    }
}
