//! The physical device (PDev) records of the DAP's interface and port
//! submodules (P-040, IEC 61158-6-10), as a controller or an engineering tool
//! reads them, from the device's real state:
//!
//! | index | subslot | record | content |
//! |---|---|---|---|
//! | 0x802A | 0x8001, 0x8002 | PDPortDataReal (block 0x020F) | own port name `port-00n`, the LLDP neighbour (peer port and station name, its MAC; line delay 0: not measured) or no peer, MAU type 100BASE-TX FD (0 while the link is down), the adjusted domain and multicast boundaries, link state up/down, media type copper |
//! | 0x802F | 0x8001, 0x8002 | PDPortDataAdjust (block 0x0202) | read: empty while nothing is adjusted, else the adjusted sub-blocks; write: see below |
//! | 0x802B | 0x8001, 0x8002 | PDPortDataCheck (block 0x0200) | read: empty while nothing is checked, else the check as written; write: CheckPeers, CheckMAUType, CheckLinkState ([`check`]); a difference is a diagnosis on the port's subslot |
//! | 0x8071 | 0x8000 | PDInterfaceAdjust (block 0x0250) | MultipleInterfaceMode as written (empty while not adjusted); NameOfDevice sets LLDP's Port ID form ([`interface`]) |
//! | 0xF841 | any submodule | PDRealData: MultipleBlockHeader (0x0400) for 0x8000 around PDInterfaceDataReal, then one per port around its PDPortDataReal |
//! | 0x8072 | 0x8000, 0x8001, 0x8002 | PDPortStatistic (block 0x0251): octet, discard and error counters ([`statistic`]) |
//! | 0x8080 | 0x8000 | PDInterfaceDataReal (block 0x0240) | the name of station (the chassis ID LLDP sends; empty while unnamed), the interface MAC, IP, subnet mask, gateway |
//!
//! A write of PDPortDataAdjust may carry the sub-blocks a controller sets
//! for the boundaries of a port: AdjustDomainBoundary (0x0209),
//! AdjustMulticastBoundary (0x0210), AdjustPeerToPeerBoundary (0x0224; bit 0
//! stops LLDP on the port) and AdjustDCPBoundary (0x0225), and AdjustMAUType
//! (0x020E) with the one MAU type the port runs (100BASE-TX FD). The whole
//! record is checked before anything is applied: a sub-block the device does
//! not support (another MAU type, AdjustLinkState, preamble length, fibre
//! optics, any other block type) is refused with "invalid parameter"
//! (PNIORW 0xB8), a record whose block lengths do not add up with "write
//! length error" (0xB1), and nothing changes. An accepted write replaces the
//! port's adjusted values; they hold until the next start.
//!
//! Any other index on these subslots keeps "invalid index" (0xB0); the
//! records on another subslot of the DAP are "invalid index" too, on a
//! subslot that does not exist "invalid slot/subslot" (0xB2).

use core::fmt::Write as _;

use heapless::{String, Vec};
use nanos::Nanos;

use crate::cm::ndr::{emit_block, Blocks};
use crate::cm::{RecordAddr, RecordError};
use crate::dcp::{IpSuite, NameOfStation};
use crate::lldp::{self, MAU_100BASE_TX_FD};
use crate::model;
use crate::rpc::cursor::{Endian, Reader, Writer};
use crate::wire::MacAddr;

pub mod check;
pub mod interface;
pub mod statistic;
#[cfg(test)]
pub(crate) mod tests;
#[cfg(test)]
pub(crate) mod tests_check;

pub use check::{Mismatch, PortCheck};

/// Record indices of the PDev.
pub mod index {
    /// PDPortDataReal (port subslots).
    pub const PD_PORT_DATA_REAL: u16 = 0x802A;
    /// PDPortDataAdjust (port subslots).
    pub const PD_PORT_DATA_ADJUST: u16 = 0x802F;
    /// PDPortDataCheck (port subslots): the topology check ([`super::check`]).
    pub const PD_PORT_DATA_CHECK: u16 = 0x802B;
    /// PDInterfaceDataReal (interface subslot).
    pub const PD_INTERFACE_DATA_REAL: u16 = 0x8080;
    /// PDRealData (device scope: at any submodule): the real data of the
    /// interface and its ports, one MultipleBlockHeader each.
    pub const PD_REAL_DATA: u16 = 0xF841;
    /// PDPortStatistic (interface and port subslots, [`super::statistic`]).
    pub const PD_PORT_STATISTIC: u16 = 0x8072;
    /// PDInterfaceAdjust (interface subslot, [`super::interface`]).
    pub const PD_INTERFACE_ADJUST: u16 = 0x8071;
}

/// Block types of the PDev records.
pub mod block_type {
    /// PDPortDataReal.
    pub const PD_PORT_DATA_REAL: u16 = 0x020F;
    /// PDPortDataAdjust.
    pub const PD_PORT_DATA_ADJUST: u16 = 0x0202;
    /// PDInterfaceDataReal.
    pub const PD_INTERFACE_DATA_REAL: u16 = 0x0240;
    /// MultipleBlockHeader (PDRealData: one per submodule).
    pub const MULTIPLE_BLOCK_HEADER: u16 = 0x0400;
    /// AdjustDomainBoundary.
    pub const ADJUST_DOMAIN_BOUNDARY: u16 = 0x0209;
    /// AdjustMulticastBoundary.
    pub const ADJUST_MULTICAST_BOUNDARY: u16 = 0x0210;
    /// AdjustMAUType.
    pub const ADJUST_MAU_TYPE: u16 = 0x020E;
    /// AdjustPeerToPeerBoundary.
    pub const ADJUST_PEER_TO_PEER_BOUNDARY: u16 = 0x0224;
    /// AdjustDCPBoundary.
    pub const ADJUST_DCP_BOUNDARY: u16 = 0x0225;
}

/// Longest peer chassis or port ID kept (an LLDP ID is at most 255 bytes).
pub const MAX_PEER_ID: usize = 255;
/// MediaType copper cable.
pub const MEDIA_COPPER: u32 = 1;
/// LinkState.Link up / down (the port state, high octet, is "unknown").
const LINK_UP: u16 = 0x0001;
const LINK_DOWN: u16 = 0x0002;

/// The neighbour a port has heard of through LLDP.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Peer {
    /// Its port name (the LLDP Port ID, without a V2.2 `.name` suffix).
    pub port: Vec<u8, MAX_PEER_ID>,
    /// Its station name (the Chassis ID; a MAC chassis ID as `xx-xx-…`).
    pub station: Vec<u8, MAX_PEER_ID>,
    /// The MAC its LLDP frames came from.
    pub mac: MacAddr,
    /// When its TTL runs out.
    pub expires: Nanos,
    /// Its PROFINET delays, if it sent them.
    pub delay: Option<lldp::PnioDelay>,
    /// Its RTClass2/RTClass3 port status, if sent.
    pub port_status: Option<(u16, u16)>,
    /// Its 802.3 MAC/PHY TLV, if sent.
    pub mac_phy: Option<lldp::MacPhy>,
    /// Its IPv4 management address, if sent.
    pub man_addr: Option<lldp::ManAddr>,
}

impl Peer {
    /// The neighbour an LLDPDU from `src` at `now` describes; `None` if its
    /// IDs do not fit.
    pub fn from_lldp(n: &lldp::Neighbor<'_>, src: MacAddr, now: Nanos) -> Option<Peer> {
        // V2.2 form "port-001.<name>": the name sits in the port ID
        let (port, station_in_port) = match n.port_id.iter().position(|&b| b == b'.') {
            Some(i) => (n.port_id.get(..i)?, n.port_id.get(i + 1..)),
            None => (n.port_id, None),
        };
        let mut station = Vec::new();
        match station_in_port {
            Some(s) => station.extend_from_slice(s).ok()?,
            None if n.chassis_subtype == 4 && n.chassis_id.len() == 6 => {
                let mut s: String<17> = String::new();
                for (i, b) in n.chassis_id.iter().enumerate() {
                    let sep = if i == 0 { "" } else { "-" };
                    write!(s, "{sep}{b:02x}").ok()?;
                }
                station.extend_from_slice(s.as_bytes()).ok()?;
            }
            None => station.extend_from_slice(n.chassis_id).ok()?,
        }
        Some(Peer {
            port: Vec::from_slice(port).ok()?,
            station,
            mac: src,
            expires: now.saturating_add(Nanos::from_secs(u64::from(n.ttl))),
            delay: n.delay,
            port_status: n.port_status,
            mac_phy: n.mac_phy,
            man_addr: n.man_addr,
        })
    }
}

/// What a controller adjusted on a port (PDPortDataAdjust); `None`: not adjusted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PortAdjust {
    /// AdjustDomainBoundary: (ingress, egress) with version 1.1, (value,
    /// value) with 1.0, and AdjustProperties.
    pub domain_boundary: Option<((u32, u32), u16, u8)>,
    /// AdjustMulticastBoundary and AdjustProperties.
    pub multicast_boundary: Option<(u32, u16)>,
    /// AdjustMAUType (always 100BASE-TX FD) and AdjustProperties.
    pub mau_type: Option<(u16, u16)>,
    /// AdjustPeerToPeerBoundary (bit 0: no LLDP) and AdjustProperties.
    pub peer_to_peer_boundary: Option<(u32, u16)>,
    /// AdjustDCPBoundary and AdjustProperties.
    pub dcp_boundary: Option<(u32, u16)>,
}

impl PortState {
    /// The operational MAU type PDPortDataReal and the SNMP agent report:
    /// 100BASE-TX FD while the link is up, 0 (unknown) while it is down.
    pub fn oper_mau_type(&self) -> u16 {
        if self.link_up {
            MAU_100BASE_TX_FD
        } else {
            0
        }
    }
}

impl PortAdjust {
    fn is_empty(&self) -> bool {
        *self == PortAdjust::default()
    }
}

/// One port's state.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PortState {
    /// The port's own MAC.
    pub mac: MacAddr,
    /// Link up.
    pub link_up: bool,
    /// The LLDP neighbour, while its TTL runs.
    pub peer: Option<Peer>,
    /// The adjusted values.
    pub adjust: PortAdjust,
    /// The checked topology (PDPortDataCheck).
    pub check: PortCheck,
}

/// The PDev of the interface X1 and its ports: what the records report.
/// The device keeps it current (name, IP, LLDP neighbours, link).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Pdev {
    /// The interface MAC.
    pub mac: MacAddr,
    /// The name of station in force.
    pub name: NameOfStation,
    /// The IP suite in force.
    pub ip: IpSuite,
    /// Port 1 and 2.
    pub ports: [PortState; model::PORTS as usize],
    /// PDInterfaceAdjust's MultipleInterfaceMode; `None`: not adjusted.
    pub interface_mode: Option<u32>,
    /// The counters of PDPortStatistic.
    pub stats: statistic::Statistics,
}

fn port_of(subslot: u16) -> Option<usize> {
    let port = subslot.checked_sub(0x8000)?;
    (1..=model::PORTS).contains(&port).then(|| usize::from(port) - 1)
}

/// The refusal of a PDev index at a subslot that is not its own.
fn misplaced(addr: RecordAddr) -> RecordError {
    if crate::cm::connect::exists(addr.slot, addr.subslot) {
        RecordError::InvalidIndex
    } else {
        RecordError::InvalidSlotSubslot
    }
}

fn pad_to4(w: &mut Writer<'_>, start: usize) -> Option<()> {
    let n = (4 - (w.pos().checked_sub(start)? % 4)) % 4;
    w.zeros(n)
}

fn counted(w: &mut Writer<'_>, s: &[u8]) -> Option<()> {
    w.u8(u8::try_from(s.len()).ok()?)?;
    w.bytes(s)
}

impl Pdev {
    /// The PDev of a device with interface MAC `mac` and port MACs
    /// `port_macs`, named `name` at `ip`; port 1's link up, port 2's down.
    pub fn new(
        mac: MacAddr,
        port_macs: [MacAddr; model::PORTS as usize],
        name: NameOfStation,
        ip: IpSuite,
    ) -> Pdev {
        let [p1, p2] = port_macs;
        let port = |mac, link_up| PortState {
            mac,
            link_up,
            peer: None,
            adjust: PortAdjust::default(),
            check: PortCheck::default(),
        };
        Pdev {
            mac,
            name,
            ip,
            ports: [port(p1, true), port(p2, false)],
            interface_mode: None,
            stats: statistic::Statistics::default(),
        }
    }

    /// Port `port` (1-based).
    pub fn port(&self, port: u16) -> Option<&PortState> {
        self.ports.get(usize::from(port).checked_sub(1)?)
    }

    /// Port `port` (1-based), mutable.
    pub fn port_mut(&mut self, port: u16) -> Option<&mut PortState> {
        self.ports.get_mut(usize::from(port).checked_sub(1)?)
    }

    /// Whether any port has a link.
    pub fn any_link_up(&self) -> bool {
        self.ports.iter().any(|p| p.link_up)
    }

    /// Whether LLDP may be sent on `port` (not stopped by an adjusted
    /// peer-to-peer boundary).
    pub fn lldp_allowed(&self, port: u16) -> bool {
        self.port(port)
            .and_then(|p| p.adjust.peer_to_peer_boundary)
            .is_none_or(|(b, _)| b & 1 == 0)
    }

    /// Whether port `port` (1-based) differs in `kind` from its
    /// PDPortDataCheck (false without a check).
    pub fn mismatch(&self, port: u16, kind: Mismatch) -> bool {
        self.port(port).is_some_and(|p| p.check.mismatch(p, kind))
    }

    /// Forgets the neighbours whose TTL ran out at `now`; the ports that lost one (bit 0 port 1).
    pub fn expire(&mut self, now: Nanos) -> u8 {
        let mut aged = 0;
        for (i, p) in self.ports.iter_mut().enumerate() {
            if p.peer.as_ref().is_some_and(|n| n.expires <= now) {
                p.peer = None;
                aged |= 1u8.checked_shl(i as u32).unwrap_or(0);
            }
        }
        aged
    }

    /// Whether `index` is one of the PDev records.
    pub fn serves(index: u16) -> bool {
        matches!(
            index,
            index::PD_PORT_DATA_REAL
                | index::PD_PORT_DATA_ADJUST
                | index::PD_PORT_DATA_CHECK
                | index::PD_INTERFACE_DATA_REAL
                | index::PD_INTERFACE_ADJUST
                | index::PD_REAL_DATA
                | index::PD_PORT_STATISTIC
        )
    }

    /// Reads record `addr` (one of [`Pdev::serves`]) into `out`; its length.
    pub fn read(&self, addr: RecordAddr, out: &mut [u8]) -> Result<usize, RecordError> {
        let mut w = Writer::new(out, Endian::Big);
        if addr.index == index::PD_REAL_DATA {
            if !crate::cm::connect::exists(addr.slot, addr.subslot) {
                return Err(RecordError::InvalidSlotSubslot);
            }
            self.emit_real_data(&mut w).ok_or(RecordError::ReadError)?;
            return Ok(w.pos());
        }
        let ok = match (addr.slot, addr.index) {
            (0, index::PD_INTERFACE_DATA_REAL) if addr.subslot == 0x8000 => self.emit_interface_real(&mut w),
            (0, index::PD_INTERFACE_ADJUST) if addr.subslot == 0x8000 => {
                interface::emit(&mut w, self.interface_mode)
            }
            (0, index::PD_PORT_STATISTIC) => {
                let c = self.counters(addr.subslot).ok_or(misplaced(addr))?;
                statistic::emit(&mut w, &c)
            }
            (0, index::PD_PORT_DATA_REAL | index::PD_PORT_DATA_ADJUST | index::PD_PORT_DATA_CHECK) => {
                let i = port_of(addr.subslot).ok_or(misplaced(addr))?;
                let p = self.ports.get(i).ok_or(RecordError::InvalidSlotSubslot)?;
                if addr.index == index::PD_PORT_DATA_CHECK {
                    check::emit(&mut w, addr.subslot, &p.check)
                } else if addr.index == index::PD_PORT_DATA_REAL {
                    emit_port_real(&mut w, addr.subslot, i, p)
                } else if p.adjust.is_empty() {
                    Some(())
                } else {
                    emit_port_adjust(&mut w, addr.subslot, &p.adjust)
                }
            }
            _ => return Err(misplaced(addr)),
        };
        ok.ok_or(RecordError::ReadError)?;
        Ok(w.pos())
    }

    /// Writes record `addr` (PDPortDataAdjust and PDPortDataCheck are writable).
    pub fn write(&mut self, addr: RecordAddr, data: &[u8]) -> Result<(), RecordError> {
        match (addr.slot, addr.index) {
            (0, index::PD_PORT_DATA_ADJUST) => {
                let i = port_of(addr.subslot).ok_or(misplaced(addr))?;
                let adjust = parse_port_adjust(addr.subslot, data)?;
                let p = self.ports.get_mut(i).ok_or(RecordError::InvalidSlotSubslot)?;
                p.adjust = adjust;
                Ok(())
            }
            (0, index::PD_PORT_DATA_REAL) if port_of(addr.subslot).is_some() => {
                Err(RecordError::AccessDenied)
            }
            (0, index::PD_PORT_DATA_CHECK) => {
                let i = port_of(addr.subslot).ok_or(misplaced(addr))?;
                let c = check::parse(addr.subslot, data)?;
                let p = self.ports.get_mut(i).ok_or(RecordError::InvalidSlotSubslot)?;
                p.check = c;
                Ok(())
            }
            (0, index::PD_INTERFACE_DATA_REAL) if addr.subslot == 0x8000 => Err(RecordError::AccessDenied),
            (0, index::PD_PORT_STATISTIC) if self.counters(addr.subslot).is_some() => {
                Err(RecordError::AccessDenied)
            }
            _ if addr.index == index::PD_REAL_DATA => {
                if crate::cm::connect::exists(addr.slot, addr.subslot) {
                    Err(RecordError::AccessDenied)
                } else {
                    Err(RecordError::InvalidSlotSubslot)
                }
            }
            (0, index::PD_INTERFACE_ADJUST) if addr.subslot == 0x8000 => {
                self.interface_mode = Some(interface::parse(data)?);
                Ok(())
            }
            _ => Err(misplaced(addr)),
        }
    }

    /// PDRealData: MultipleBlockHeader (API 0, slot 0, subslot) around
    /// PDInterfaceDataReal of 0x8000, then around PDPortDataReal of each port.
    fn emit_real_data(&self, w: &mut Writer<'_>) -> Option<()> {
        let multiple = |w: &mut Writer<'_>, subslot: u16, body: &dyn Fn(&mut Writer<'_>) -> Option<()>| {
            emit_block(w, block_type::MULTIPLE_BLOCK_HEADER, |w| {
                w.zeros(2)?;
                w.u32(0)?;
                w.u16(0)?;
                w.u16(subslot)?;
                body(w)
            })
        };
        multiple(w, 0x8000, &|w| self.emit_interface_real(w))?;
        for (i, p) in self.ports.iter().enumerate() {
            let subslot = 0x8001u16.checked_add(u16::try_from(i).ok()?)?;
            multiple(w, subslot, &|w| emit_port_real(w, subslot, i, p))?;
        }
        Some(())
    }

    fn emit_interface_real(&self, w: &mut Writer<'_>) -> Option<()> {
        let start = w.pos();
        emit_block(w, block_type::PD_INTERFACE_DATA_REAL, |w| {
            counted(w, self.name.as_bytes())?;
            pad_to4(w, start)?;
            w.bytes(&self.mac.0)?;
            w.zeros(2)?;
            w.bytes(&self.ip.ip.octets())?;
            w.bytes(&self.ip.mask.octets())?;
            w.bytes(&self.ip.gateway.octets())
        })
    }
}

fn emit_port_real(w: &mut Writer<'_>, subslot: u16, i: usize, p: &PortState) -> Option<()> {
    let start = w.pos();
    let mut own: String<8> = String::new();
    write!(own, "port-{:03}", i + 1).ok()?;
    emit_block(w, block_type::PD_PORT_DATA_REAL, |w| {
        w.zeros(2)?;
        w.u16(0)?;
        w.u16(subslot)?;
        counted(w, own.as_bytes())?;
        w.u8(u8::from(p.peer.is_some()))?;
        pad_to4(w, start)?;
        if let Some(peer) = &p.peer {
            counted(w, &peer.port)?;
            counted(w, &peer.station)?;
            pad_to4(w, start)?;
            w.u32(0)?; // LineDelay: not measured
            w.bytes(&peer.mac.0)?;
            w.zeros(2)?;
        }
        w.u16(p.oper_mau_type())?;
        w.zeros(2)?;
        let domain = p.adjust.domain_boundary.map_or(0, |((ingress, _), _, _)| ingress);
        w.u32(domain)?;
        w.u32(p.adjust.multicast_boundary.map_or(0, |(b, _)| b))?;
        w.u16(if p.link_up { LINK_UP } else { LINK_DOWN })?;
        w.zeros(2)?;
        w.u32(MEDIA_COPPER)
    })
}

fn emit_sub(
    w: &mut Writer<'_>,
    ty: u16,
    version_low: u8,
    body: impl FnOnce(&mut Writer<'_>) -> Option<()>,
) -> Option<()> {
    let start = w.pos();
    emit_block(w, ty, |w| {
        w.zeros(2)?;
        body(w)
    })?;
    w.patch_u16(start.checked_add(4)?, u16::from_be_bytes([1, version_low]))
}

fn emit_value(w: &mut Writer<'_>, ty: u16, v: (u32, u16)) -> Option<()> {
    emit_sub(w, ty, 0, |w| {
        w.u32(v.0)?;
        w.u16(v.1)?;
        w.zeros(2)
    })
}

fn emit_port_adjust(w: &mut Writer<'_>, subslot: u16, a: &PortAdjust) -> Option<()> {
    emit_block(w, block_type::PD_PORT_DATA_ADJUST, |w| {
        w.zeros(2)?;
        w.u16(0)?;
        w.u16(subslot)?;
        if let Some(((ingress, egress), props, version_low)) = a.domain_boundary {
            emit_sub(w, block_type::ADJUST_DOMAIN_BOUNDARY, version_low, |w| {
                w.u32(ingress)?;
                if version_low == 1 {
                    w.u32(egress)?;
                }
                w.u16(props)?;
                w.zeros(2)
            })?;
        }
        if let Some(v) = a.multicast_boundary {
            emit_value(w, block_type::ADJUST_MULTICAST_BOUNDARY, v)?;
        }
        if let Some((mau, props)) = a.mau_type {
            emit_sub(w, block_type::ADJUST_MAU_TYPE, 0, |w| {
                w.u16(mau)?;
                w.u16(props)
            })?;
        }
        if let Some(v) = a.peer_to_peer_boundary {
            emit_value(w, block_type::ADJUST_PEER_TO_PEER_BOUNDARY, v)?;
        }
        if let Some(v) = a.dcp_boundary {
            emit_value(w, block_type::ADJUST_DCP_BOUNDARY, v)?;
        }
        Some(())
    })
}

/// A sub-block's value and AdjustProperties after its two padding octets
/// (`u32` value, `u16` properties, two padding octets).
fn value_props(body: &[u8]) -> Result<(u32, u16), RecordError> {
    let mut r = Reader::new(body, Endian::Big);
    let v = (|| {
        r.skip(2)?;
        let v = r.u32()?;
        let p = r.u16()?;
        r.skip(2)?;
        Some((v, p))
    })()
    .ok_or(RecordError::WriteLength)?;
    if r.remaining() != 0 {
        return Err(RecordError::WriteLength);
    }
    Ok(v)
}

/// The body of a record that must be exactly one block of `block_type`,
/// version 1.0: the bytes not adding up are "write length error", another
/// block or version "invalid parameter".
pub(crate) fn single_block(data: &[u8], block_type: u16) -> Result<&[u8], RecordError> {
    let mut outer = Blocks::new(data);
    let blk = match outer.next_block() {
        Some(Ok(b)) => b,
        Some(Err(_)) | None => return Err(RecordError::WriteLength),
    };
    if outer.remaining() != 0 {
        return Err(RecordError::WriteLength);
    }
    if blk.block_type != block_type || (blk.version_high, blk.version_low) != (1, 0) {
        return Err(RecordError::InvalidParameter);
    }
    Ok(blk.body)
}

/// The sub-blocks of a port record's body (padding, SlotNumber 0,
/// SubslotNumber `subslot`, then the sub-blocks).
pub(crate) fn port_body(body: &[u8], subslot: u16) -> Result<&[u8], RecordError> {
    let mut r = Reader::new(body, Endian::Big);
    let (slot, sub) = (|| {
        r.skip(2)?;
        Some((r.u16()?, r.u16()?))
    })()
    .ok_or(RecordError::WriteLength)?;
    if (slot, sub) != (0, subslot) {
        return Err(RecordError::InvalidParameter);
    }
    Ok(r.rest())
}

/// Checks a PDPortDataAdjust record for `subslot` whole; the adjusted values
/// it sets. Nothing is applied here.
pub fn parse_port_adjust(subslot: u16, data: &[u8]) -> Result<PortAdjust, RecordError> {
    let body = single_block(data, block_type::PD_PORT_DATA_ADJUST)?;
    let mut a = PortAdjust::default();
    let mut subs = Blocks::new(port_body(body, subslot)?);
    while let Some(b) = subs.next_block() {
        let b = b.map_err(|_| RecordError::WriteLength)?;
        if b.version_high != 1 {
            return Err(RecordError::InvalidParameter);
        }
        let v0 = b.version_low == 0;
        match b.block_type {
            block_type::ADJUST_DOMAIN_BOUNDARY if b.version_low <= 1 => {
                let mut r = Reader::new(b.body, Endian::Big);
                let v = (|| {
                    r.skip(2)?;
                    let ingress = r.u32()?;
                    let egress = if v0 { ingress } else { r.u32()? };
                    let p = r.u16()?;
                    r.skip(2)?;
                    Some(((ingress, egress), p))
                })()
                .ok_or(RecordError::WriteLength)?;
                if r.remaining() != 0 {
                    return Err(RecordError::WriteLength);
                }
                a.domain_boundary = Some((v.0, v.1, b.version_low));
            }
            block_type::ADJUST_MULTICAST_BOUNDARY if v0 => a.multicast_boundary = Some(value_props(b.body)?),
            block_type::ADJUST_PEER_TO_PEER_BOUNDARY if v0 => {
                a.peer_to_peer_boundary = Some(value_props(b.body)?);
            }
            block_type::ADJUST_DCP_BOUNDARY if v0 => a.dcp_boundary = Some(value_props(b.body)?),
            block_type::ADJUST_MAU_TYPE if v0 => {
                let mut r = Reader::new(b.body, Endian::Big);
                let v = (|| {
                    r.skip(2)?;
                    Some((r.u16()?, r.u16()?))
                })()
                .ok_or(RecordError::WriteLength)?;
                if r.remaining() != 0 {
                    return Err(RecordError::WriteLength);
                }
                if v.0 != MAU_100BASE_TX_FD {
                    return Err(RecordError::InvalidParameter);
                }
                a.mau_type = Some(v);
            }
            _ => return Err(RecordError::InvalidParameter),
        }
    }
    Ok(a)
}
