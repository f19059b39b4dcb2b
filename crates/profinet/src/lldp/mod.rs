//! LLDP transmit with the TLVs a PROFINET device sends on each port (P-037),
//! and what a received LLDPDU says: the neighbour's chassis and port ID (DCP's
//! alias name, PDPortDataReal's peer) and, when sent, its PROFINET delay and
//! port status TLVs, its 802.3 MAC/PHY TLV and its IPv4 management address
//! (the SNMP agent's remote tables, P-038).
//!
//! Every [`TX_INTERVAL`] (5 s) each port sends, from its own MAC to
//! 01:80:c2:00:00:0e ([`build_frame`]):
//!
//! | TLV | content |
//! |---|---|
//! | Chassis ID | subtype 7 "locally assigned": the name of station; subtype 4 "MAC address" (the interface MAC) while the station has no name |
//! | Port ID | subtype 7: `port-001`, `port-002` (PROFINET V2.3 form; [`PortIdForm::WithName`] gives the older `port-001.<name>`) |
//! | TTL | 20 s (4 × the interval) |
//! | PROFINET (OUI 00-0E-CF) 1 | LLDP_PNIO_DELAY: port Rx/Tx delays local and remote, cable delay (ns) |
//! | PROFINET 2 | LLDP_PNIO_PORTSTATUS: RTClass2 and RTClass3 port status (0: off, no IRT) |
//! | PROFINET 5 | LLDP_PNIO_CHASSIS_MAC: the interface MAC |
//! | IEEE 802.3 (OUI 00-12-0F) 1 | MAC/PHY configuration/status: auto-negotiation, advertised capabilities, operational MAU type |
//! | Management address | the IPv4 address (ifIndex numbering, interface 1), when one is set |
//! | End | |
//!
//! [`Schedule`] says when a port is due, time as an argument. The device
//! sends one port's LLDPDU per poll: when both are due, the second goes out
//! with the next poll, which the first asks for at once (its deadline is
//! `now`), so no poll builds two (issue 36: a poll's longest run within twice
//! its usual one).

use core::net::Ipv4Addr;

use nanos::Nanos;

use crate::dcp::NameOfStation;
use crate::model;
use crate::wire::{emit_header, ethertype, EthFrame, MacAddr};

mod stats;
#[cfg(test)]
mod tests;

pub use stats::{Rx as RxStats, Stats};

/// The transmit interval (msgTxInterval).
pub const TX_INTERVAL: Nanos = Nanos::from_secs(5);
/// TTL sent: msgTxHold (4) × the interval, in seconds.
pub const TTL_SECS: u16 = 20;
/// lldpReinitDelay (s): the 802.1AB default; a port sends again when its link comes back.
pub const REINIT_DELAY_SECS: u32 = 2;
/// lldpTxDelay (s): the smallest the MIB allows; a change (name, IP, link) is sent at once.
pub const TX_DELAY_SECS: u32 = 1;
/// lldpNotificationInterval (s): the 802.1AB default (this device sends no notifications).
pub const NOTIFICATION_INTERVAL_SECS: u32 = 5;
/// The PROFINET OUI.
pub const OUI_PROFINET: [u8; 3] = [0x00, 0x0E, 0xCF];
/// The IEEE 802.3 OUI.
pub const OUI_IEEE_802_3: [u8; 3] = [0x00, 0x12, 0x0F];
/// MAU type 100BASE-TX full duplex (RFC 4836 dot3MauType100BaseTXFD).
pub const MAU_100BASE_TX_FD: u16 = 16;
/// Advertised capabilities 10BASE-T and 100BASE-TX, half and full duplex
/// (ifMauAutoNegCapAdvertisedBits, bit 0 = most significant).
pub const ADVERTISE_10_100: u16 = 0x6C00;
/// The interface numbering of the Management Address TLV sent: ifIndex (2)…
pub const MAN_ADDR_IF_SUBTYPE: u8 = 2;
/// …and the interface, the PROFINET interface (ifIndex 1 of the SNMP agent).
pub const MAN_ADDR_IF_ID: u32 = 1;
/// Longest Port ID this device sends ("port-001." and a name of station).
pub const MAX_PORT_ID_LEN: usize = 9 + crate::dcp::name::MAX_LEN;

mod tlv_type {
    pub const END: u8 = 0;
    pub const CHASSIS_ID: u8 = 1;
    pub const PORT_ID: u8 = 2;
    pub const TTL: u8 = 3;
    pub const MANAGEMENT_ADDRESS: u8 = 8;
    pub const ORG: u8 = 127;
}

/// How the Port ID is written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PortIdForm {
    /// `port-001` (PROFINET V2.3 and later; the name is in the Chassis ID).
    #[default]
    Short,
    /// `port-001.<name of station>` (PROFINET V2.2).
    WithName,
}

/// The PROFINET delay values of a port, in nanoseconds (0: unknown).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PnioDelay {
    /// PortRxDelayLocal.
    pub rx_local: u32,
    /// PortRxDelayRemote.
    pub rx_remote: u32,
    /// PortTxDelayLocal.
    pub tx_local: u32,
    /// PortTxDelayRemote.
    pub tx_remote: u32,
    /// CableDelayLocal.
    pub cable_local: u32,
}

/// The IEEE 802.3 MAC/PHY configuration/status TLV.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MacPhy {
    /// Auto-negotiation support/status bits (bit 0 supported, bit 1 enabled).
    pub autoneg: u8,
    /// Advertised capabilities (ifMauAutoNegCapAdvertisedBits).
    pub advertised: u16,
    /// Operational MAU type.
    pub mau_type: u16,
}

/// An IPv4 Management Address TLV.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ManAddr {
    /// The address.
    pub ip: Ipv4Addr,
    /// Interface numbering subtype (1 unknown, 2 ifIndex, 3 system port number).
    pub if_subtype: u8,
    /// Interface number.
    pub if_id: u32,
}

/// What one port reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PortInfo {
    /// The port's own MAC (the frame's source, P-006).
    pub mac: MacAddr,
    /// Auto-negotiation support/status bits (bit 0 supported, bit 1 enabled).
    pub autoneg: u8,
    /// Advertised capabilities ([`ADVERTISE_10_100`]).
    pub advertised: u16,
    /// Operational MAU type ([`MAU_100BASE_TX_FD`]).
    pub mau_type: u16,
    /// PROFINET delays.
    pub delay: PnioDelay,
    /// RTClass2 and RTClass3 port status (LLDP_PNIO_PORTSTATUS).
    pub rt_status: (u16, u16),
}

impl PortInfo {
    /// A 100 Mbit/s full-duplex port with auto-negotiation on.
    pub const fn fast_ethernet(mac: MacAddr) -> PortInfo {
        PortInfo {
            mac,
            autoneg: 0x03,
            advertised: ADVERTISE_10_100,
            mau_type: MAU_100BASE_TX_FD,
            delay: PnioDelay {
                rx_local: 0,
                rx_remote: 0,
                tx_local: 0,
                tx_remote: 0,
                cable_local: 0,
            },
            // RT_CLASS_1 only: no RTClass2/3 (off)
            rt_status: (0, 0),
        }
    }
}

/// The station as LLDP shows it.
#[derive(Clone, Copy, Debug)]
pub struct Station<'a> {
    /// Name of station (empty: the Chassis ID is the interface MAC).
    pub name: &'a NameOfStation,
    /// The interface MAC (LLDP_PNIO_CHASSIS_MAC).
    pub interface_mac: MacAddr,
    /// The IP address, if set (management address TLV).
    pub ip: Option<Ipv4Addr>,
    /// Port ID form.
    pub port_id_form: PortIdForm,
}

/// Writes TLVs into a buffer; any overflow makes the whole frame fail.
struct TlvWriter<'a> {
    buf: &'a mut [u8],
    pos: usize,
}

impl TlvWriter<'_> {
    fn tlv(&mut self, ty: u8, parts: &[&[u8]]) -> Option<()> {
        let len: usize = parts.iter().map(|p| p.len()).sum();
        let len16 = u16::try_from(len).ok().filter(|&l| l < 512)?;
        let head = (u16::from(ty) << 9) | len16;
        let out = self.buf.get_mut(self.pos..self.pos + 2 + len)?;
        let (h, mut rest) = out.split_at_mut_checked(2)?;
        h.copy_from_slice(&head.to_be_bytes());
        for p in parts {
            let (dst, tail) = rest.split_at_mut_checked(p.len())?;
            dst.copy_from_slice(p);
            rest = tail;
        }
        self.pos += 2 + len;
        Some(())
    }
}

/// Writes the Port ID of `port` (1-based) into `out`.
pub fn port_id(
    port: u16,
    form: PortIdForm,
    name: &NameOfStation,
    out: &mut heapless::Vec<u8, MAX_PORT_ID_LEN>,
) -> Option<()> {
    use core::fmt::Write;
    let mut s: heapless::String<8> = heapless::String::new();
    write!(s, "port-{port:03}").ok()?;
    out.clear();
    out.extend_from_slice(s.as_bytes()).ok()?;
    if form == PortIdForm::WithName && !name.is_empty() {
        out.push(b'.').ok()?;
        out.extend_from_slice(name.as_bytes()).ok()?;
    }
    Some(())
}

/// Builds the LLDP frame of `port` (1…[`model::PORTS`]) into `out`; its length,
/// or `None` if the port does not exist or `out` is too small (give it 1514).
pub fn build_frame(station: &Station<'_>, port: u16, info: &PortInfo, out: &mut [u8]) -> Option<usize> {
    if port == 0 || port > model::PORTS {
        return None;
    }
    let eth = emit_header(out, MacAddr::LLDP, info.mac, None, ethertype::LLDP)?;
    let mut w = TlvWriter {
        buf: out.get_mut(eth..)?,
        pos: 0,
    };
    if station.name.is_empty() {
        w.tlv(tlv_type::CHASSIS_ID, &[&[4], &station.interface_mac.0])?;
    } else {
        w.tlv(tlv_type::CHASSIS_ID, &[&[7], station.name.as_bytes()])?;
    }
    let mut pid = heapless::Vec::new();
    port_id(port, station.port_id_form, station.name, &mut pid)?;
    w.tlv(tlv_type::PORT_ID, &[&[7], &pid])?;
    w.tlv(tlv_type::TTL, &[&TTL_SECS.to_be_bytes()])?;
    let d = &info.delay;
    let mut delay = [0u8; 20];
    for (chunk, v) in
        delay
            .chunks_exact_mut(4)
            .zip([d.rx_local, d.rx_remote, d.tx_local, d.tx_remote, d.cable_local])
    {
        chunk.copy_from_slice(&v.to_be_bytes());
    }
    w.tlv(tlv_type::ORG, &[&OUI_PROFINET, &[1], &delay])?;
    let (rt2, rt3) = info.rt_status;
    w.tlv(
        tlv_type::ORG,
        &[&OUI_PROFINET, &[2], &rt2.to_be_bytes(), &rt3.to_be_bytes()],
    )?;
    w.tlv(tlv_type::ORG, &[&OUI_PROFINET, &[5], &station.interface_mac.0])?;
    w.tlv(
        tlv_type::ORG,
        &[
            &OUI_IEEE_802_3,
            &[1, info.autoneg],
            &info.advertised.to_be_bytes(),
            &info.mau_type.to_be_bytes(),
        ],
    )?;
    if let Some(ip) = station.ip.filter(|ip| !ip.is_unspecified()) {
        // Address string length 5 (subtype + 4), subtype 1 IPv4, ifIndex
        // numbering (2), interface 1, no OID.
        w.tlv(
            tlv_type::MANAGEMENT_ADDRESS,
            &[
                &[5, 1],
                &ip.octets(),
                &[MAN_ADDR_IF_SUBTYPE],
                &MAN_ADDR_IF_ID.to_be_bytes(),
                &[0],
            ],
        )?;
    }
    w.tlv(tlv_type::END, &[])?;
    let len = eth + w.pos;
    let padded = len.max(crate::wire::MIN_FRAME_LEN);
    out.get_mut(len..padded)?.fill(0);
    Some(padded)
}

/// When each port sends: every [`TX_INTERVAL`], and at once after
/// [`Schedule::kick`] (start-up, link up, a new name or IP).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Schedule {
    next: [Option<Nanos>; model::PORTS as usize],
}

impl Schedule {
    /// Makes every port due at `now`.
    pub fn kick(&mut self, now: Nanos) {
        self.next = [Some(now); model::PORTS as usize];
    }

    /// Makes one port (1-based) due at `now` (its link came up).
    pub fn kick_port(&mut self, port: u16, now: Nanos) {
        if let Some(n) = self.next.get_mut(usize::from(port).wrapping_sub(1)) {
            *n = Some(now);
        }
    }

    /// Stops sending on a port (link down).
    pub fn stop_port(&mut self, port: u16) {
        if let Some(n) = self.next.get_mut(usize::from(port).wrapping_sub(1)) {
            *n = None;
        }
    }

    /// The first port (1-based) due at `now`; after sending, call
    /// [`Schedule::sent`].
    pub fn due(&self, now: Nanos) -> Option<u16> {
        let i = self.next.iter().position(|n| n.is_some_and(|t| t <= now))?;
        u16::try_from(i + 1).ok()
    }

    /// Records that `port` sent at `now`: next time is `now + 5 s`.
    pub fn sent(&mut self, port: u16, now: Nanos) {
        if let Some(n) = self.next.get_mut(usize::from(port).wrapping_sub(1)) {
            *n = Some(now + TX_INTERVAL);
        }
    }

    /// The earliest time any port is due (for the caller's timer).
    pub fn next_deadline(&self) -> Option<Nanos> {
        self.next.iter().flatten().min().copied()
    }
}

/// What a received LLDPDU says about the neighbour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Neighbor<'a> {
    /// Chassis ID subtype.
    pub chassis_subtype: u8,
    /// Chassis ID value.
    pub chassis_id: &'a [u8],
    /// Port ID subtype.
    pub port_subtype: u8,
    /// Port ID value.
    pub port_id: &'a [u8],
    /// TTL in seconds.
    pub ttl: u16,
    /// LLDP_PNIO_DELAY, if sent.
    pub delay: Option<PnioDelay>,
    /// LLDP_PNIO_PORTSTATUS (RTClass2, RTClass3), if sent.
    pub port_status: Option<(u16, u16)>,
    /// The 802.3 MAC/PHY TLV, if sent.
    pub mac_phy: Option<MacPhy>,
    /// The first IPv4 management address, if one was sent.
    pub man_addr: Option<ManAddr>,
}

fn be16(v: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_be_bytes(v.get(at..at + 2)?.try_into().ok()?))
}

fn be32(v: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_be_bytes(v.get(at..at + 4)?.try_into().ok()?))
}

/// An IPv4 Management Address TLV's value (string length 5, subtype 1, the
/// address, interface subtype and number, OID); `None` for any other address.
fn parse_man_addr(v: &[u8]) -> Option<ManAddr> {
    let (&[5, 1], rest) = v.split_first_chunk::<2>()? else {
        return None;
    };
    let (ip, rest) = rest.split_first_chunk::<4>()?;
    let (&if_subtype, rest) = rest.split_first()?;
    let if_id = be32(rest, 0)?;
    // the OID string must fit what is left
    let oid_len = usize::from(*rest.get(4)?);
    rest.get(5..5 + oid_len)?;
    Some(ManAddr {
        ip: Ipv4Addr::from(*ip),
        if_subtype,
        if_id,
    })
}

impl<'a> Neighbor<'a> {
    /// Parses an LLDP frame: the three mandatory TLVs must come first, in
    /// order; `None` otherwise.
    pub fn parse(frame: &EthFrame<'a>) -> Option<Neighbor<'a>> {
        if frame.ethertype != ethertype::LLDP {
            return None;
        }
        let mut rest = frame.payload;
        let mut next = || -> Option<(u8, &'a [u8])> {
            let head = u16::from_be_bytes([*rest.first()?, *rest.get(1)?]);
            let len = usize::from(head & 0x01FF);
            let value = rest.get(2..2 + len)?;
            rest = rest.get(2 + len..)?;
            Some(((head >> 9) as u8, value))
        };
        let (t1, chassis) = next()?;
        let (t2, port) = next()?;
        let (t3, ttl) = next()?;
        if (t1, t2, t3) != (tlv_type::CHASSIS_ID, tlv_type::PORT_ID, tlv_type::TTL) {
            return None;
        }
        let (&chassis_subtype, chassis_id) = chassis.split_first()?;
        let (&port_subtype, port_id) = port.split_first()?;
        if chassis_id.is_empty() || port_id.is_empty() || ttl.len() != 2 {
            return None;
        }
        let mut n = Neighbor {
            chassis_subtype,
            chassis_id,
            port_subtype,
            port_id,
            ttl: u16::from_be_bytes([*ttl.first()?, *ttl.get(1)?]),
            delay: None,
            port_status: None,
            mac_phy: None,
            man_addr: None,
        };
        // the optional TLVs up to End or the first that does not fit the frame;
        // one with a wrong length is skipped
        while let Some((t, v)) = next() {
            match t {
                tlv_type::END => break,
                tlv_type::MANAGEMENT_ADDRESS if n.man_addr.is_none() => n.man_addr = parse_man_addr(v),
                tlv_type::ORG => match (v.get(..3), v.get(3), v.get(4..).unwrap_or(&[])) {
                    (Some(oui), Some(1), d) if oui == OUI_PROFINET && d.len() == 20 => {
                        n.delay = Some(PnioDelay {
                            rx_local: be32(d, 0)?,
                            rx_remote: be32(d, 4)?,
                            tx_local: be32(d, 8)?,
                            tx_remote: be32(d, 12)?,
                            cable_local: be32(d, 16)?,
                        });
                    }
                    (Some(oui), Some(2), d) if oui == OUI_PROFINET && d.len() >= 4 => {
                        n.port_status = Some((be16(d, 0)?, be16(d, 2)?));
                    }
                    (Some(oui), Some(1), d) if oui == OUI_IEEE_802_3 && d.len() == 5 => {
                        n.mac_phy = Some(MacPhy {
                            autoneg: *d.first()?,
                            advertised: be16(d, 1)?,
                            mau_type: be16(d, 3)?,
                        });
                    }
                    _ => {}
                },
                _ => {}
            }
        }
        Some(n)
    }

    /// The alias name DCP answers to for this neighbour: `<port ID>.<chassis
    /// ID>` (V2.3), or the port ID alone if it already carries the name
    /// (`port-001.<name>`, V2.2). `None` for a MAC chassis ID (no name).
    pub fn alias(&self, out: &mut heapless::Vec<u8, { crate::dcp::server::MAX_ALIAS_LEN }>) -> Option<()> {
        out.clear();
        if self.port_id.contains(&b'.') {
            return out.extend_from_slice(self.port_id).ok();
        }
        if self.chassis_subtype == 4 {
            return None;
        }
        out.extend_from_slice(self.port_id).ok()?;
        out.push(b'.').ok()?;
        out.extend_from_slice(self.chassis_id).ok()
    }
}
