//! PDPortDataCheck (index 0x802B, block 0x0200) of a port subslot: the
//! topology a controller expects there (IEC 61158-6-10), as TIA Portal
//! writes it at start-up when the topology is configured, and the
//! diagnoses a difference raises.
//!
//! | sub-block | content | mismatch (ChannelErrorType / ExtChannelErrorType) |
//! |---|---|---|
//! | CheckPeers (0x020A) | NumberOfPeers (1), LengthPeerPortID, PeerPortID, LengthPeerChassisID, PeerChassisID, padding to 4 | 0x8001 "remote mismatch" / 0x8005 no peer detected (link up, no LLDP neighbour), 0x8000 peer name of station, 0x8001 peer name of port |
//! | CheckMAUType (0x020C) | MAUType | 0x8000 "data transmission impossible" / 0x8001 MAU type mismatch (link up, another MAU type) |
//! | CheckLinkState (0x021C) | LinkState (Link Up, Port unknown) | 0x8000 "data transmission impossible" / 0x8000 link state mismatch: link down |
//!
//! A write is checked whole before it is stored: another outer block type
//! or version, a block for another subslot, NumberOfPeers other than 1, a
//! MAU type 0, a LinkState other than "up", CheckLineDelay, CheckSyncDifference,
//! CheckMAUTypeDifference, an unknown or repeated sub-block: "invalid
//! parameter" (PNIORW 0xB8); lengths that do not add up: "write length
//! error" (0xB1). A refused write keeps the check in force. The check is
//! read back as written (empty while none is set; a record with no
//! sub-block clears it); it holds until the next start.

use heapless::Vec;

use super::{counted, pad_to4, PortState, MAX_PEER_ID};
use crate::cm::ndr::{emit_block, Blocks};
use crate::cm::RecordError;
use crate::lldp::MAU_100BASE_TX_FD;
use crate::rpc::cursor::{Endian, Reader, Writer};

/// Block types of PDPortDataCheck and its sub-blocks.
pub mod check_block {
    /// PDPortDataCheck.
    pub const PD_PORT_DATA_CHECK: u16 = 0x0200;
    /// CheckPeers.
    pub const CHECK_PEERS: u16 = 0x020A;
    /// CheckMAUType.
    pub const CHECK_MAU_TYPE: u16 = 0x020C;
    /// CheckLinkState.
    pub const CHECK_LINK_STATE: u16 = 0x021C;
}

/// ChannelErrorType "data transmission impossible".
pub const DATA_TRANSMISSION_IMPOSSIBLE: u16 = 0x8000;
/// ChannelErrorType "remote mismatch".
pub const REMOTE_MISMATCH: u16 = 0x8001;

/// A topology difference on a port: (ChannelErrorType, ExtChannelErrorType).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mismatch {
    /// The port has a link and no LLDP neighbour.
    NoPeer,
    /// The neighbour's name of station differs.
    PeerStation,
    /// The neighbour's port differs.
    PeerPort,
    /// The port runs another MAU type.
    MauType,
    /// The link is down.
    LinkDown,
}

impl Mismatch {
    /// Every kind, in the order they are evaluated.
    pub const ALL: [Mismatch; 5] = [
        Mismatch::NoPeer,
        Mismatch::PeerStation,
        Mismatch::PeerPort,
        Mismatch::MauType,
        Mismatch::LinkDown,
    ];

    /// (ChannelErrorType, ExtChannelErrorType) of IEC 61158-6-10.
    pub const fn error_types(self) -> (u16, u16) {
        match self {
            Mismatch::NoPeer => (REMOTE_MISMATCH, 0x8005),
            Mismatch::PeerStation => (REMOTE_MISMATCH, 0x8000),
            Mismatch::PeerPort => (REMOTE_MISMATCH, 0x8001),
            Mismatch::MauType => (DATA_TRANSMISSION_IMPOSSIBLE, 0x8001),
            Mismatch::LinkDown => (DATA_TRANSMISSION_IMPOSSIBLE, 0x8000),
        }
    }
}

/// The expected neighbour of a CheckPeers sub-block, as written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CheckPeer {
    /// PeerPortID (`port-001`, or `port-001.<name>` in the V2.2 form).
    pub port_id: Vec<u8, MAX_PEER_ID>,
    /// PeerChassisID (the neighbour's name of station).
    pub chassis_id: Vec<u8, MAX_PEER_ID>,
}

/// What a controller checks on a port; all `None`: no check.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PortCheck {
    /// CheckPeers.
    pub peer: Option<CheckPeer>,
    /// CheckMAUType.
    pub mau_type: Option<u16>,
    /// CheckLinkState.
    pub link_state: Option<u16>,
}

impl PortCheck {
    /// No check configured.
    pub fn is_empty(&self) -> bool {
        *self == PortCheck::default()
    }

    /// Whether `kind` differs on port `p` from what is checked.
    pub fn mismatch(&self, p: &PortState, kind: Mismatch) -> bool {
        match kind {
            Mismatch::NoPeer => self.peer.is_some() && p.link_up && p.peer.is_none(),
            Mismatch::PeerStation | Mismatch::PeerPort => {
                let (Some(want), Some(have)) = (&self.peer, &p.peer) else {
                    return false;
                };
                // the V2.2 form carries the station after a '.' in the port ID
                let (port, station) = match want.port_id.iter().position(|&b| b == b'.') {
                    Some(i) => (
                        want.port_id.get(..i).unwrap_or(&[]),
                        want.port_id.get(i + 1..).unwrap_or(&[]),
                    ),
                    None => (want.port_id.as_slice(), want.chassis_id.as_slice()),
                };
                if kind == Mismatch::PeerStation {
                    !station.eq_ignore_ascii_case(&have.station)
                } else {
                    !port.eq_ignore_ascii_case(&have.port)
                }
            }
            Mismatch::MauType => self.mau_type.is_some_and(|m| p.link_up && m != MAU_100BASE_TX_FD),
            Mismatch::LinkDown => self.link_state.is_some() && !p.link_up,
        }
    }
}

/// Writes the PDPortDataCheck record of `subslot` (nothing if no check).
pub fn emit(w: &mut Writer<'_>, subslot: u16, c: &PortCheck) -> Option<()> {
    if c.is_empty() {
        return Some(());
    }
    emit_block(w, check_block::PD_PORT_DATA_CHECK, |w| {
        w.zeros(2)?;
        w.u16(0)?;
        w.u16(subslot)?;
        if let Some(peer) = &c.peer {
            let start = w.pos();
            emit_block(w, check_block::CHECK_PEERS, |w| {
                w.u8(1)?;
                counted(w, &peer.port_id)?;
                counted(w, &peer.chassis_id)?;
                pad_to4(w, start)
            })?;
        }
        if let Some(m) = c.mau_type {
            emit_block(w, check_block::CHECK_MAU_TYPE, |w| w.u16(m))?;
        }
        if let Some(l) = c.link_state {
            emit_block(w, check_block::CHECK_LINK_STATE, |w| w.u16(l))?;
        }
        Some(())
    })
}

fn id(r: &mut Reader<'_>) -> Result<Vec<u8, MAX_PEER_ID>, RecordError> {
    let n = r.u8().ok_or(RecordError::WriteLength)?;
    let s = r.bytes(usize::from(n)).ok_or(RecordError::WriteLength)?;
    if s.is_empty() {
        return Err(RecordError::InvalidParameter);
    }
    Vec::from_slice(s).map_err(|_| RecordError::InvalidParameter)
}

/// Checks a PDPortDataCheck record for `subslot` whole; the check it sets.
/// Nothing is applied here.
pub fn parse(subslot: u16, data: &[u8]) -> Result<PortCheck, RecordError> {
    let body = super::single_block(data, check_block::PD_PORT_DATA_CHECK)?;
    let mut c = PortCheck::default();
    let mut subs = Blocks::new(super::port_body(body, subslot)?);
    while let Some(b) = subs.next_block() {
        let b = b.map_err(|_| RecordError::WriteLength)?;
        if (b.version_high, b.version_low) != (1, 0) {
            return Err(RecordError::InvalidParameter);
        }
        let mut r = Reader::new(b.body, Endian::Big);
        match b.block_type {
            check_block::CHECK_PEERS if c.peer.is_none() => {
                if r.u8().ok_or(RecordError::WriteLength)? != 1 {
                    return Err(RecordError::InvalidParameter);
                }
                let port_id = id(&mut r)?;
                let chassis_id = id(&mut r)?;
                // padding to 4 from the sub-block's start (6 header octets)
                let used = 6usize.saturating_add(b.body.len()).saturating_sub(r.remaining());
                let pad = (4 - used % 4) % 4;
                if r.remaining() != pad {
                    return Err(RecordError::WriteLength);
                }
                c.peer = Some(CheckPeer { port_id, chassis_id });
            }
            check_block::CHECK_MAU_TYPE if c.mau_type.is_none() => {
                let m = r.u16().ok_or(RecordError::WriteLength)?;
                if r.remaining() != 0 {
                    return Err(RecordError::WriteLength);
                }
                if m == 0 {
                    return Err(RecordError::InvalidParameter);
                }
                c.mau_type = Some(m);
            }
            check_block::CHECK_LINK_STATE if c.link_state.is_none() => {
                let l = r.u16().ok_or(RecordError::WriteLength)?;
                if r.remaining() != 0 {
                    return Err(RecordError::WriteLength);
                }
                // LinkState.Link "up" (low octet 1), Port "unknown"
                if l != super::LINK_UP {
                    return Err(RecordError::InvalidParameter);
                }
                c.link_state = Some(l);
            }
            _ => return Err(RecordError::InvalidParameter),
        }
    }
    Ok(c)
}
