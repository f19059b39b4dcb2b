//! SNMPv1/v2c agent of the PROFINET interface (spec P-038).
//!
//! `#![no_std]`, heap-free, panic-free: a request is read through the checked BER views of
//! [`ber`], answered into a caller's buffer, and any malformed, oversized or wrong-community
//! request is dropped (`None`) and changes nothing. The view ([`mib`]) is MIB-II `system` and
//! `interfaces` (the interface and its two ports), LLDP-MIB local and remote data with the
//! management address tables, and the PROFINET (LLDP-EXT-PNO-MIB) and IEEE 802.3
//! (LLDP-EXT-DOT3-MIB) extensions, local and as the neighbour's LLDPDU told them.
//! Communities: read `public`, write `private` by default.
//! sysContact, sysName and sysLocation are writable (OCTET STRING, at most 255 bytes); the
//! caller persists them when [`Answer::changed`] is set. Time (sysUpTime) is an argument.
#![no_std]
#![deny(missing_docs)]

pub mod ber;
pub mod mib;

use ber::{Reader, Writer};
use mib::{Lookup, Val};

/// Longest writable string.
pub const TEXT_MAX: usize = 255;

/// A fixed-capacity byte string.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub struct Text<const N: usize> {
    b: [u8; N],
    len: usize,
}

impl<const N: usize> Text<N> {
    /// From bytes; `None` if longer than `N`.
    pub fn new(s: &[u8]) -> Option<Self> {
        let mut t = Self { b: [0; N], len: 0 };
        t.b.get_mut(..s.len())?.copy_from_slice(s);
        t.len = s.len();
        Some(t)
    }
    /// The bytes.
    pub fn get(&self) -> &[u8] {
        self.b.get(..self.len).unwrap_or(&[])
    }
}

/// PROFINET delays of a port in nanoseconds (LLDP_PNIO_DELAY; 0: not measured).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Delays {
    /// Line propagation delay (CableDelayLocal): lldpXPno…LPDValue.
    pub line: u32,
    /// PortTxDelayLocal: lldpXPno…PortTxDValue.
    pub tx: u32,
    /// PortRxDelayLocal: lldpXPno…PortRxDValue.
    pub rx: u32,
}

/// The PROFINET part of a port's LLDPDU (LLDP_PNIO_DELAY and LLDP_PNIO_PORTSTATUS).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Pno {
    /// Delays.
    pub delay: Delays,
    /// RTClass2_PortStatus as sent (low two bits: off 0, configured 1, up/running 2).
    pub rt2: u16,
    /// RTClass3_PortStatus as sent (low three bits: off 0, up 2, down 3, run 4).
    pub rt3: u16,
}

/// The IEEE 802.3 MAC/PHY configuration/status of a port.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MacPhy {
    /// Auto-negotiation support/status (bit 0 supported, bit 1 enabled).
    pub autoneg: u8,
    /// PMD auto-negotiation advertised capability, as sent (big-endian).
    pub advertised: [u8; 2],
    /// Operational MAU type (RFC 4836 dot3MauType; 0: unknown, link down).
    pub mau_type: u16,
}

/// An IPv4 management address (LLDP Management Address TLV).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ManAddr {
    /// The address.
    pub ipv4: [u8; 4],
    /// Interface numbering subtype (1 unknown, 2 ifIndex, 3 system port number).
    pub if_subtype: u8,
    /// Interface number.
    pub if_id: u32,
}

/// A neighbour seen by LLDP on one port.
#[derive(Clone, Copy, Debug)]
pub struct Neighbor<'a> {
    /// LLDP chassis ID subtype.
    pub chassis_subtype: u8,
    /// Chassis ID.
    pub chassis_id: &'a [u8],
    /// LLDP port ID subtype.
    pub port_subtype: u8,
    /// Port ID.
    pub port_id: &'a [u8],
    /// System name (empty when not sent); also the neighbour's NameOfStation
    /// (lldpXPnoRemPortNoS).
    pub sys_name: &'a [u8],
    /// The PROFINET TLVs, if it sent any (a row of lldpXPnoRemTable).
    pub pno: Option<Pno>,
    /// The MAC/PHY TLV, if sent (a row of lldpXdot3RemPortTable).
    pub mac_phy: Option<MacPhy>,
    /// Its IPv4 management address, if sent (a row of lldpRemManAddrTable).
    pub man_addr: Option<ManAddr>,
}

/// One local port as this device's LLDP transmitter describes it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LocalPort {
    /// The PROFINET TLVs sent.
    pub pno: Pno,
    /// The MAC/PHY TLV (operational MAU type as PDPortDataReal reports it).
    pub mac_phy: MacPhy,
}

/// What the device contributes per request: identity, time and what LLDP has seen.
pub struct Device<'a> {
    /// sysDescr / lldpLocSysDesc.
    pub descr: &'a [u8],
    /// sysUpTime in centiseconds (the caller's time argument).
    pub uptime_cs: u32,
    /// MAC of the interface, port 1, port 2.
    pub macs: [[u8; 6]; 3],
    /// Link up on port 1, port 2.
    pub links: [bool; 2],
    /// LLDP neighbours on port 1, port 2.
    pub neighbors: [Option<Neighbor<'a>>; 2],
    /// NameOfStation (lldpXPnoLocPortNoS; empty while unnamed).
    pub name_of_station: &'a [u8],
    /// The interface's management address while it has an IP (lldpLocManAddrTable).
    pub man_addr: Option<ManAddr>,
    /// The ports whose LLDPDUs carry it (lldpConfigManAddrPortsTxEnable, an LldpPortList:
    /// bit 7 of the octet is port 1, bit 6 port 2).
    pub man_addr_ports: [u8; 1],
    /// What LLDP sends on port 1, port 2.
    pub ports: [LocalPort; 2],
    /// The LLDP agent's timing and counters (lldpConfiguration, lldpStatistics).
    pub lldp: LldpAgent,
}

/// The LLDP agent's configuration (as the transmitter uses it) and counters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LldpAgent {
    /// lldpMessageTxInterval, seconds.
    pub tx_interval: u32,
    /// lldpMessageTxHoldMultiplier (TTL = interval × this).
    pub hold: u32,
    /// lldpReinitDelay, seconds.
    pub reinit_delay: u32,
    /// lldpTxDelay, seconds.
    pub tx_delay: u32,
    /// lldpNotificationInterval, seconds.
    pub notification_interval: u32,
    /// lldpPortConfigTLVsTxEnable (BITS: portDesc 0x80, sysName 0x40, sysDesc 0x20, sysCap 0x10).
    pub tlvs_tx: u8,
    /// lldpStatistics.
    pub stats: LldpStats,
}

/// LLDP counters (IEEE 802.1AB-2005 10.5.2), saturating.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LldpStats {
    /// sysUpTime (centiseconds) of the last change of the remote tables.
    pub last_change_cs: u32,
    /// lldpStatsRemTablesInserts.
    pub inserts: u32,
    /// lldpStatsRemTablesDeletes.
    pub deletes: u32,
    /// lldpStatsRemTablesDrops.
    pub drops: u32,
    /// lldpStatsRemTablesAgeouts.
    pub ageouts: u32,
    /// lldpStatsTxPortFramesTotal of port 1, port 2.
    pub tx: [u32; 2],
    /// lldpStatsRxPortTable rows of port 1, port 2.
    pub rx: [RxStats; 2],
}

/// lldpStatsRxPortEntry.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RxStats {
    /// lldpStatsRxPortFramesDiscardedTotal.
    pub discarded: u32,
    /// lldpStatsRxPortFramesInErrors.
    pub errors: u32,
    /// lldpStatsRxPortFramesTotal.
    pub frames: u32,
    /// lldpStatsRxPortTLVsDiscardedTotal.
    pub tlvs_discarded: u32,
    /// lldpStatsRxPortTLVsUnrecognizedTotal.
    pub tlvs_unrecognized: u32,
    /// lldpStatsRxPortAgeoutsTotal.
    pub ageouts: u32,
}

const RX_ZERO: RxStats = RxStats {
    discarded: 0,
    errors: 0,
    frames: 0,
    tlvs_discarded: 0,
    tlvs_unrecognized: 0,
    ageouts: 0,
};

impl<'a> Device<'a> {
    /// A device with nothing to tell (the view's shape for set checks).
    pub const fn empty() -> Device<'static> {
        Device {
            descr: &[],
            uptime_cs: 0,
            macs: [[0; 6]; 3],
            links: [false; 2],
            neighbors: [None, None],
            name_of_station: &[],
            man_addr: None,
            man_addr_ports: [0],
            ports: [LocalPort {
                pno: Pno {
                    delay: Delays {
                        line: 0,
                        tx: 0,
                        rx: 0,
                    },
                    rt2: 0,
                    rt3: 0,
                },
                mac_phy: MacPhy {
                    autoneg: 0,
                    advertised: [0; 2],
                    mau_type: 0,
                },
            }; 2],
            lldp: LldpAgent {
                tx_interval: 0,
                hold: 0,
                reinit_delay: 0,
                tx_delay: 0,
                notification_interval: 0,
                tlvs_tx: 0,
                stats: LldpStats {
                    last_change_cs: 0,
                    inserts: 0,
                    deletes: 0,
                    drops: 0,
                    ageouts: 0,
                    tx: [0; 2],
                    rx: [RX_ZERO; 2],
                },
            },
        }
    }
    fn port(&self, port: u32) -> Option<&LocalPort> {
        port.checked_sub(1).and_then(|p| self.ports.get(p as usize))
    }
    fn mac(&self, i: u32) -> &[u8] {
        self.macs.get(i as usize).map(|m| &m[..]).unwrap_or(&[])
    }
    fn link(&self, port: u32) -> bool {
        port.checked_sub(1)
            .and_then(|p| self.links.get(p as usize))
            .copied()
            .unwrap_or(false)
    }
    fn neighbor(&self, port: u32) -> Option<&Neighbor<'a>> {
        port.checked_sub(1)
            .and_then(|p| self.neighbors.get(p as usize))
            .and_then(|n| n.as_ref())
    }
}

/// The agent's kept state: communities and the writable system strings.
#[derive(Clone, Debug)]
pub struct Agent {
    /// Read community.
    pub read_community: Text<32>,
    /// Write community (also allows reads).
    pub write_community: Text<32>,
    /// sysContact.
    pub sys_contact: Text<TEXT_MAX>,
    /// sysName.
    pub sys_name: Text<TEXT_MAX>,
    /// sysLocation.
    pub sys_location: Text<TEXT_MAX>,
}

impl Default for Agent {
    fn default() -> Self {
        let e = Text {
            b: [0; TEXT_MAX],
            len: 0,
        };
        let mut r = Text { b: [0; 32], len: 0 };
        let mut w = r;
        r.b[..6].copy_from_slice(b"public");
        r.len = 6;
        w.b[..7].copy_from_slice(b"private");
        w.len = 7;
        Self {
            read_community: r,
            write_community: w,
            sys_contact: e,
            sys_name: e,
            sys_location: e,
        }
    }
}

/// A response ready to send.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Answer {
    /// Bytes of the response in the output buffer.
    pub len: usize,
    /// A set changed a writable object (persist the agent's strings).
    pub changed: bool,
}

/// Largest request accepted and largest response sent (an SNMP message over UDP on Ethernet).
pub const MAX_MSG: usize = 1472;
/// Most variable bindings in one request.
pub const MAX_VARBINDS: usize = 32;

const GET: u8 = 0xa0;
const GET_NEXT: u8 = 0xa1;
const RESPONSE: u8 = 0xa2;
const SET: u8 = 0xa3;
const GET_BULK: u8 = 0xa5;

/// Error statuses (RFC 1157, RFC 3416).
pub mod err {
    /// tooBig
    pub const TOO_BIG: i32 = 1;
    /// noSuchName (v1)
    pub const NO_SUCH_NAME: i32 = 2;
    /// badValue (v1)
    pub const BAD_VALUE: i32 = 3;
    /// readOnly (v1)
    pub const READ_ONLY: i32 = 4;
    /// wrongType
    pub const WRONG_TYPE: i32 = 7;
    /// wrongLength
    pub const WRONG_LENGTH: i32 = 8;
    /// noCreation
    pub const NO_CREATION: i32 = 11;
    /// notWritable
    pub const NOT_WRITABLE: i32 = 17;
}

struct Req<'a> {
    version: i32,
    pdu: u8,
    id: i32,
    a: i32,
    b: i32,
    vbl: &'a [u8],
}

fn parse(msg: &[u8]) -> Option<(Req<'_>, &[u8])> {
    if msg.len() > MAX_MSG {
        return None;
    }
    let mut top = Reader::new(msg);
    let body = top.expect(0x30)?;
    if !top.is_empty() {
        return None;
    }
    let mut r = Reader::new(body);
    let version = r.int()?;
    if version != 0 && version != 1 {
        return None;
    }
    let community = r.expect(0x04)?;
    let (pdu, p) = r.tlv()?;
    if !r.is_empty() || !matches!(pdu, GET | GET_NEXT | SET | GET_BULK) || (pdu == GET_BULK && version == 0) {
        return None;
    }
    let mut p = Reader::new(p);
    let id = p.int()?;
    let a = p.int()?;
    let b = p.int()?;
    let vbl = p.expect(0x30)?;
    if !p.is_empty() {
        return None;
    }
    // every binding well-formed: SEQUENCE { OID, value }
    let mut v = Reader::new(vbl);
    let mut n = 0;
    while !v.is_empty() {
        let mut vb = Reader::new(v.expect(0x30)?);
        vb.oid()?;
        vb.tlv()?;
        if !vb.is_empty() {
            return None;
        }
        n += 1;
        if n > MAX_VARBINDS {
            return None;
        }
    }
    Some((
        Req {
            version,
            pdu,
            id,
            a,
            b,
            vbl,
        },
        community,
    ))
}

fn put_val(w: &mut Writer, v: Val) {
    match v {
        Val::Int(x) => w.int(0x02, x),
        Val::Str(s) => w.prim(0x04, s),
        Val::Oid(o) => w.oid(o),
        Val::Ticks(x) => w.uint(0x43, x),
        Val::Counter(x) => w.uint(0x41, x),
        Val::Gauge(x) => w.uint(0x42, x),
    }
}

fn varbinds(vbl: &[u8]) -> impl Iterator<Item = (ber::Oid, u8, &[u8])> {
    let mut r = Reader::new(vbl);
    core::iter::from_fn(move || {
        let mut vb = Reader::new(r.expect(0x30)?);
        let oid = vb.oid()?;
        let (t, v) = vb.tlv()?;
        Some((oid, t, v))
    })
}

impl Agent {
    /// Answer one request datagram into `out`; `None` drops it (malformed, oversized, wrong
    /// community, or a version/PDU this agent does not speak).
    pub fn handle(&mut self, msg: &[u8], dev: &Device, out: &mut [u8]) -> Option<Answer> {
        let (req, community) = parse(msg)?;
        let write = community == self.write_community.get();
        if !write && community != self.read_community.get() {
            return None;
        }
        if req.pdu == SET && !write {
            // RFC 3584: an unauthorised set is dropped (authenticationFailure), not answered
            return None;
        }
        let cap = out.len().min(MAX_MSG);
        let out = out.get_mut(..cap)?;
        let mut changed = false;
        let status = if req.pdu == SET {
            self.check_set(&req)
        } else {
            None
        };
        if req.pdu == SET && status.is_none() {
            changed = self.apply_set(&req);
        }
        let len = match status {
            Some((e, i)) => encode(out, &req, community, e, i, |w| echo(w, req.vbl)),
            None => {
                let mut fail = None;
                let len = encode(out, &req, community, 0, 0, |w| {
                    fail = self.fill(w, &req, dev);
                });
                match fail {
                    Some((e, i)) => encode(out, &req, community, e, i, |w| echo(w, req.vbl)),
                    None => len,
                }
            }
        };
        let len = match len {
            Some(l) => l,
            None => encode(out, &req, community, err::TOO_BIG, 0, |_| {})?,
        };
        Some(Answer { len, changed })
    }

    /// Fill the varbind list; `Some((status, index))` for a v1 error.
    fn fill(&self, w: &mut Writer, req: &Req, dev: &Device) -> Option<(i32, i32)> {
        let v1 = req.version == 0;
        if req.pdu == GET_BULK {
            let nonrep = req.a.max(0) as usize;
            let reps = req.b.max(0) as usize;
            let mut last: [Option<ber::Oid>; MAX_VARBINDS] = [None; MAX_VARBINDS];
            let mut nrep = 0;
            for (i, (oid, _, _)) in varbinds(req.vbl).enumerate() {
                if i >= nonrep && reps == 0 {
                    break;
                }
                let l = w.len();
                let got = self.next_vb(w, oid.arcs(), dev);
                if !w.ok() {
                    w.truncate(l);
                    return None;
                }
                if i >= nonrep {
                    if let Some(s) = last.get_mut(nrep) {
                        *s = Some(got.unwrap_or(oid));
                        nrep += 1;
                    }
                }
            }
            for _ in 1..reps {
                let mut any = false;
                for s in last.iter_mut().take(nrep) {
                    let Some(o) = s else { continue };
                    let l = w.len();
                    let got = self.next_vb(w, o.arcs(), dev);
                    if !w.ok() {
                        // RFC 3416 4.2.3: a get-bulk response is truncated, not tooBig
                        w.truncate(l);
                        return None;
                    }
                    any |= got.is_some();
                    if let Some(g) = got {
                        *o = g;
                    }
                }
                if !any {
                    break;
                }
            }
            return None;
        }
        for (i, (oid, _, _)) in varbinds(req.vbl).enumerate() {
            let idx = i as i32 + 1;
            if req.pdu == GET_NEXT {
                if self.next_vb(w, oid.arcs(), dev).is_none() && v1 {
                    return Some((err::NO_SUCH_NAME, idx));
                }
                continue;
            }
            let m = w.open(0x30);
            w.oid(oid.arcs());
            match mib::find(oid.arcs(), dev) {
                Lookup::Found(id, r) => put_val(w, mib::value(id, r, self, dev)),
                _ if v1 => return Some((err::NO_SUCH_NAME, idx)),
                Lookup::NoInstance => w.prim(0x81, &[]),
                Lookup::NoObject => w.prim(0x80, &[]),
            }
            w.close(m);
        }
        None
    }

    /// One get-next binding; returns the OID answered, or `None` at the end of the view.
    fn next_vb(&self, w: &mut Writer, oid: &[u32], dev: &Device) -> Option<ber::Oid> {
        let m = w.open(0x30);
        let r = match mib::next(oid, dev) {
            Some((id, row, full)) => {
                w.oid(full.arcs());
                put_val(w, mib::value(id, row, self, dev));
                Some(full)
            }
            None => {
                w.oid(oid);
                w.prim(0x82, &[]);
                None
            }
        };
        w.close(m);
        r
    }

    /// Validate a set (RFC 3416 4.2.5); the first failing binding's status and index.
    fn check_set(&self, req: &Req) -> Option<(i32, i32)> {
        let v1 = req.version == 0;
        let dev = Device::empty();
        for (i, (oid, t, v)) in varbinds(req.vbl).enumerate() {
            let idx = i as i32 + 1;
            let e = match mib::find(oid.arcs(), &dev) {
                Lookup::Found(id, _) if id.writable() => {
                    if t != 0x04 {
                        Some(if v1 { err::BAD_VALUE } else { err::WRONG_TYPE })
                    } else if v.len() > TEXT_MAX {
                        Some(if v1 { err::BAD_VALUE } else { err::WRONG_LENGTH })
                    } else {
                        None
                    }
                }
                Lookup::Found(..) => Some(if v1 { err::READ_ONLY } else { err::NOT_WRITABLE }),
                Lookup::NoInstance if !v1 => Some(err::NO_CREATION),
                Lookup::NoObject if !v1 => Some(err::NOT_WRITABLE),
                _ => Some(err::NO_SUCH_NAME),
            };
            if let Some(e) = e {
                return Some((e, idx));
            }
        }
        None
    }

    /// Applies a checked set; whether the kept strings differ afterwards (a set that writes an
    /// object twice, back to what it was, changed nothing).
    fn apply_set(&mut self, req: &Req) -> bool {
        let dev = Device::empty();
        let before = (self.sys_contact, self.sys_name, self.sys_location);
        for (oid, _, v) in varbinds(req.vbl) {
            let Some(t) = Text::new(v) else { continue };
            let slot = match mib::find(oid.arcs(), &dev) {
                Lookup::Found(mib::Id::SysContact, _) => &mut self.sys_contact,
                Lookup::Found(mib::Id::SysName, _) => &mut self.sys_name,
                Lookup::Found(mib::Id::SysLocation, _) => &mut self.sys_location,
                _ => continue,
            };
            *slot = t;
        }
        before != (self.sys_contact, self.sys_name, self.sys_location)
    }
}

fn echo(w: &mut Writer, vbl: &[u8]) {
    let m = w.open(0x30);
    for (oid, t, v) in varbinds(vbl) {
        let s = w.open(0x30);
        w.oid(oid.arcs());
        w.prim(t, v);
        w.close(s);
    }
    w.close(m);
}

fn encode(
    out: &mut [u8],
    req: &Req,
    community: &[u8],
    status: i32,
    index: i32,
    body: impl FnOnce(&mut Writer),
) -> Option<usize> {
    let mut w = Writer::new(out);
    message(
        &mut w,
        req.version,
        community,
        RESPONSE,
        [req.id, status, index],
        |w| {
            if status == 0 {
                let m = w.open(0x30);
                body(w);
                w.close(m);
            } else if status == err::TOO_BIG {
                let m = w.open(0x30);
                w.close(m);
            } else {
                body(w);
            }
        },
    );
    w.finish()
}

/// Writes one SNMP message (RFC 1157, RFC 3416) into `w`: the SEQUENCE of
/// `version`, `community` and the PDU tagged `pdu`, which holds the three
/// INTEGERs `ints` (request-id, then error-status and error-index, or
/// non-repeaters and max-repetitions) and what `bindings` writes after them
/// (the variable-binding list).
pub fn message(
    w: &mut Writer,
    version: i32,
    community: &[u8],
    pdu: u8,
    ints: [i32; 3],
    bindings: impl FnOnce(&mut Writer),
) {
    let top = w.open(0x30);
    w.int(0x02, version);
    w.prim(0x04, community);
    let p = w.open(pdu);
    for x in ints {
        w.int(0x02, x);
    }
    bindings(w);
    w.close(p);
    w.close(top);
}

#[cfg(any(test, feature = "testing"))]
pub mod testing;
#[cfg(test)]
mod tests;
