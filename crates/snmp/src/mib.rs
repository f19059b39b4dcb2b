//! The MIB view: MIB-II system and interfaces, LLDP-MIB configuration (read-only: the
//! transmitter's fixed PROFINET timing) and statistics, local and remote data with the
//! management address tables (and lldpConfigManAddrTable, the ports that send the address), LLDP-EXT-PNO-MIB (lldpXPnoMIB, 1.0.8802.1.1.2.1.5.3791) and
//! LLDP-EXT-DOT3-MIB (lldpXdot3MIB, 1.0.8802.1.1.2.1.5.4623) local and remote port tables, as
//! an ordered list of objects (table columns) whose instances are enumerated in lexicographic
//! order; a remote row exists only while the neighbour's LLDPDU carried what fills it.

use crate::ber::Oid;
use crate::{Agent, Device};

/// A value of a variable binding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Val<'a> {
    /// INTEGER
    Int(i32),
    /// OCTET STRING
    Str(&'a [u8]),
    /// OBJECT IDENTIFIER
    Oid(&'a [u32]),
    /// TimeTicks (centiseconds)
    Ticks(u32),
    /// Counter32
    Counter(u32),
    /// Gauge32
    Gauge(u32),
}

/// What an object is and how its instances are numbered.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Id {
    /// sysDescr
    SysDescr,
    /// sysObjectID
    SysObjectId,
    /// sysUpTime
    SysUpTime,
    /// sysContact (writable)
    SysContact,
    /// sysName (writable)
    SysName,
    /// sysLocation (writable)
    SysLocation,
    /// sysServices
    SysServices,
    /// ifNumber
    IfNumber,
    /// ifTable column (ifIndex, ifDescr, ifType, ifMtu, ifSpeed, ifPhysAddress, ifAdminStatus, ifOperStatus)
    If(u32),
    /// lldpLocChassisIdSubtype
    LocChassisIdSubtype,
    /// lldpLocChassisId
    LocChassisId,
    /// lldpLocSysName
    LocSysName,
    /// lldpLocSysDesc
    LocSysDesc,
    /// lldpLocPortTable column (2 subtype, 3 id, 4 desc)
    LocPort(u32),
    /// lldpRemTable column (4 chassis subtype, 5 chassis id, 6 port subtype, 7 port id, 9 sys name)
    Rem(u32),
    /// lldpConfiguration scalar (1 tx interval, 2 hold multiplier, 3 reinit delay, 4 tx delay,
    /// 5 notification interval)
    Config(u32),
    /// lldpPortConfigTable column (2 admin status, 3 notification enable, 4 TLVs tx enable)
    PortConfig(u32),
    /// lldpStatistics scalar (1 last change time, 2 inserts, 3 deletes, 4 drops, 5 ageouts)
    Stats(u32),
    /// lldpStatsTxPortFramesTotal
    StatsTx,
    /// lldpStatsRxPortTable column (2 discarded, 3 errors, 4 frames, 5 TLVs discarded,
    /// 6 TLVs unrecognized, 7 ageouts)
    StatsRx(u32),
    /// lldpConfigManAddrPortsTxEnable (lldpConfigManAddrTable, indexed as lldpLocManAddrTable)
    ConfigManAddrPorts,
    /// lldpLocManAddrTable column (3 len, 4 if subtype, 5 if id, 6 OID), index subtype.address
    LocManAddr(u32),
    /// lldpRemManAddrTable column (3 if subtype, 4 if id, 5 OID)
    RemManAddr(u32),
    /// lldpXPnoLocTable column (1 LPD, 2 port Tx delay, 3 port Rx delay, 4 RT2, 5 RT3, 6 NoS)
    PnoLoc(u32),
    /// lldpXPnoRemTable column (as [`Id::PnoLoc`])
    PnoRem(u32),
    /// lldpXdot3LocPortTable column (1 auto-neg supported, 2 enabled, 3 advertised, 4 MAU type)
    Dot3Loc(u32),
    /// lldpXdot3RemPortTable column (as [`Id::Dot3Loc`])
    Dot3Rem(u32),
}

/// MIB-II system (scalars).
static SYS: [u32; 7] = [1, 3, 6, 1, 2, 1, 1];
/// MIB-II interfaces (ifNumber).
static IFACES: [u32; 7] = [1, 3, 6, 1, 2, 1, 2];
/// ifEntry.
static IF_ENTRY: [u32; 9] = [1, 3, 6, 1, 2, 1, 2, 2, 1];
/// lldpConfiguration (scalars).
static LLDP_CONFIG: [u32; 8] = [1, 0, 8802, 1, 1, 2, 1, 1];
/// lldpPortConfigEntry.
static LLDP_PORT_CONFIG: [u32; 10] = [1, 0, 8802, 1, 1, 2, 1, 1, 6, 1];
/// lldpStatistics (scalars).
static LLDP_STATS: [u32; 8] = [1, 0, 8802, 1, 1, 2, 1, 2];
/// lldpStatsTxPortEntry.
static LLDP_STATS_TX: [u32; 10] = [1, 0, 8802, 1, 1, 2, 1, 2, 6, 1];
/// lldpStatsRxPortEntry.
static LLDP_STATS_RX: [u32; 10] = [1, 0, 8802, 1, 1, 2, 1, 2, 7, 1];
/// lldpConfigManAddrEntry.
static LLDP_CONFIG_MAN: [u32; 10] = [1, 0, 8802, 1, 1, 2, 1, 1, 7, 1];
/// lldpLocalSystemData (scalars).
static LLDP_LOC: [u32; 8] = [1, 0, 8802, 1, 1, 2, 1, 3];
/// lldpLocPortEntry.
static LLDP_LOC_PORT: [u32; 10] = [1, 0, 8802, 1, 1, 2, 1, 3, 7, 1];
/// lldpLocManAddrEntry.
static LLDP_LOC_MAN: [u32; 10] = [1, 0, 8802, 1, 1, 2, 1, 3, 8, 1];
/// lldpRemEntry.
static LLDP_REM: [u32; 10] = [1, 0, 8802, 1, 1, 2, 1, 4, 1, 1];
/// lldpRemManAddrEntry.
static LLDP_REM_MAN: [u32; 10] = [1, 0, 8802, 1, 1, 2, 1, 4, 2, 1];
/// lldpXPnoLocEntry (LLDP-EXT-PNO-MIB).
static PNO_LOC: [u32; 13] = [1, 0, 8802, 1, 1, 2, 1, 5, 3791, 1, 2, 1, 1];
/// lldpXPnoRemEntry.
static PNO_REM: [u32; 13] = [1, 0, 8802, 1, 1, 2, 1, 5, 3791, 1, 3, 1, 1];
/// lldpXdot3LocPortEntry (LLDP-EXT-DOT3-MIB).
static DOT3_LOC: [u32; 13] = [1, 0, 8802, 1, 1, 2, 1, 5, 4623, 1, 2, 1, 1];
/// lldpXdot3RemPortEntry.
static DOT3_REM: [u32; 13] = [1, 0, 8802, 1, 1, 2, 1, 5, 4623, 1, 3, 1, 1];

/// One object: the OID of its group or table entry, its arc under it, and its identity.
pub struct Obj {
    /// OID of the scalar group or table entry.
    pub entry: &'static [u32],
    /// The object's arc under `entry` (the scalar or the column).
    pub col: u32,
    /// Identity.
    pub id: Id,
}

macro_rules! o {
    ($id:expr, $entry:ident, $col:expr) => {
        Obj {
            entry: &$entry,
            col: $col,
            id: $id,
        }
    };
}

/// Every object, in OID order (checked by a unit test).
pub static OBJECTS: &[Obj] = &[
    o!(Id::Config(1), LLDP_CONFIG, 1),
    o!(Id::Config(2), LLDP_CONFIG, 2),
    o!(Id::Config(3), LLDP_CONFIG, 3),
    o!(Id::Config(4), LLDP_CONFIG, 4),
    o!(Id::Config(5), LLDP_CONFIG, 5),
    o!(Id::PortConfig(2), LLDP_PORT_CONFIG, 2),
    o!(Id::PortConfig(3), LLDP_PORT_CONFIG, 3),
    o!(Id::PortConfig(4), LLDP_PORT_CONFIG, 4),
    o!(Id::ConfigManAddrPorts, LLDP_CONFIG_MAN, 1),
    o!(Id::Stats(1), LLDP_STATS, 1),
    o!(Id::Stats(2), LLDP_STATS, 2),
    o!(Id::Stats(3), LLDP_STATS, 3),
    o!(Id::Stats(4), LLDP_STATS, 4),
    o!(Id::Stats(5), LLDP_STATS, 5),
    o!(Id::StatsTx, LLDP_STATS_TX, 2),
    o!(Id::StatsRx(2), LLDP_STATS_RX, 2),
    o!(Id::StatsRx(3), LLDP_STATS_RX, 3),
    o!(Id::StatsRx(4), LLDP_STATS_RX, 4),
    o!(Id::StatsRx(5), LLDP_STATS_RX, 5),
    o!(Id::StatsRx(6), LLDP_STATS_RX, 6),
    o!(Id::StatsRx(7), LLDP_STATS_RX, 7),
    o!(Id::LocChassisIdSubtype, LLDP_LOC, 1),
    o!(Id::LocChassisId, LLDP_LOC, 2),
    o!(Id::LocSysName, LLDP_LOC, 3),
    o!(Id::LocSysDesc, LLDP_LOC, 4),
    o!(Id::LocPort(2), LLDP_LOC_PORT, 2),
    o!(Id::LocPort(3), LLDP_LOC_PORT, 3),
    o!(Id::LocPort(4), LLDP_LOC_PORT, 4),
    o!(Id::LocManAddr(3), LLDP_LOC_MAN, 3),
    o!(Id::LocManAddr(4), LLDP_LOC_MAN, 4),
    o!(Id::LocManAddr(5), LLDP_LOC_MAN, 5),
    o!(Id::LocManAddr(6), LLDP_LOC_MAN, 6),
    o!(Id::Rem(4), LLDP_REM, 4),
    o!(Id::Rem(5), LLDP_REM, 5),
    o!(Id::Rem(6), LLDP_REM, 6),
    o!(Id::Rem(7), LLDP_REM, 7),
    o!(Id::Rem(9), LLDP_REM, 9),
    o!(Id::RemManAddr(3), LLDP_REM_MAN, 3),
    o!(Id::RemManAddr(4), LLDP_REM_MAN, 4),
    o!(Id::RemManAddr(5), LLDP_REM_MAN, 5),
    o!(Id::PnoLoc(1), PNO_LOC, 1),
    o!(Id::PnoLoc(2), PNO_LOC, 2),
    o!(Id::PnoLoc(3), PNO_LOC, 3),
    o!(Id::PnoLoc(4), PNO_LOC, 4),
    o!(Id::PnoLoc(5), PNO_LOC, 5),
    o!(Id::PnoLoc(6), PNO_LOC, 6),
    o!(Id::PnoRem(1), PNO_REM, 1),
    o!(Id::PnoRem(2), PNO_REM, 2),
    o!(Id::PnoRem(3), PNO_REM, 3),
    o!(Id::PnoRem(4), PNO_REM, 4),
    o!(Id::PnoRem(5), PNO_REM, 5),
    o!(Id::PnoRem(6), PNO_REM, 6),
    o!(Id::Dot3Loc(1), DOT3_LOC, 1),
    o!(Id::Dot3Loc(2), DOT3_LOC, 2),
    o!(Id::Dot3Loc(3), DOT3_LOC, 3),
    o!(Id::Dot3Loc(4), DOT3_LOC, 4),
    o!(Id::Dot3Rem(1), DOT3_REM, 1),
    o!(Id::Dot3Rem(2), DOT3_REM, 2),
    o!(Id::Dot3Rem(3), DOT3_REM, 3),
    o!(Id::Dot3Rem(4), DOT3_REM, 4),
    o!(Id::SysDescr, SYS, 1),
    o!(Id::SysObjectId, SYS, 2),
    o!(Id::SysUpTime, SYS, 3),
    o!(Id::SysContact, SYS, 4),
    o!(Id::SysName, SYS, 5),
    o!(Id::SysLocation, SYS, 6),
    o!(Id::SysServices, SYS, 7),
    o!(Id::IfNumber, IFACES, 1),
    o!(Id::If(1), IF_ENTRY, 1),
    o!(Id::If(2), IF_ENTRY, 2),
    o!(Id::If(3), IF_ENTRY, 3),
    o!(Id::If(4), IF_ENTRY, 4),
    o!(Id::If(5), IF_ENTRY, 5),
    o!(Id::If(6), IF_ENTRY, 6),
    o!(Id::If(7), IF_ENTRY, 7),
    o!(Id::If(8), IF_ENTRY, 8),
];

/// Number of interfaces: the PROFINET interface (ifIndex 1) and its ports (2, 3).
pub const IFS: u32 = 3;
/// Number of LLDP ports.
pub const PORTS: u32 = 2;

impl Id {
    /// Writable objects (sysContact, sysName, sysLocation).
    pub fn writable(self) -> bool {
        matches!(self, Id::SysContact | Id::SysName | Id::SysLocation)
    }
    /// How many candidate rows the object has (scalars 1).
    fn rows(self) -> u32 {
        match self {
            Id::If(_) => IFS,
            Id::LocPort(_)
            | Id::PortConfig(_)
            | Id::StatsTx
            | Id::StatsRx(_)
            | Id::Rem(_)
            | Id::RemManAddr(_)
            | Id::PnoLoc(_)
            | Id::PnoRem(_)
            | Id::Dot3Loc(_)
            | Id::Dot3Rem(_) => PORTS,
            _ => 1,
        }
    }
    /// Instance suffix of row `r` (0-based), or `None` when that row does not exist.
    fn instance(self, r: u32, dev: &Device) -> Option<([u32; INST], usize)> {
        let port = r + 1;
        let mut i = [0; INST];
        let n = match self {
            Id::If(_)
            | Id::LocPort(_)
            | Id::PnoLoc(_)
            | Id::Dot3Loc(_)
            | Id::PortConfig(_)
            | Id::StatsTx
            | Id::StatsRx(_) => {
                i[0] = port;
                1
            }
            // lldpLocManAddrSubtype ipV4 (1), then the address as a length-prefixed string
            Id::LocManAddr(_) | Id::ConfigManAddrPorts => {
                let m = dev.man_addr?;
                addr_index(&mut i, 0, &m);
                6
            }
            // lldpRemTimeMark 0, lldpRemLocalPortNum, lldpRemIndex 1
            Id::Rem(_) | Id::PnoRem(_) | Id::Dot3Rem(_) | Id::RemManAddr(_) => {
                let n = dev.neighbor(port)?;
                let has = match self {
                    Id::PnoRem(_) => n.pno.is_some(),
                    Id::Dot3Rem(_) => n.mac_phy.is_some(),
                    _ => true,
                };
                if !has {
                    return None;
                }
                i[1] = port;
                i[2] = 1;
                if let Id::RemManAddr(_) = self {
                    addr_index(&mut i, 3, &n.man_addr?);
                    9
                } else {
                    3
                }
            }
            _ => 1,
        };
        Some((i, n))
    }
}

/// Longest instance suffix (lldpRemManAddrTable: time mark, port, index, subtype, length, 4 octets).
const INST: usize = 9;

/// `1.4.a.b.c.d` (ipV4, length 4, the address) at `at`.
fn addr_index(i: &mut [u32; INST], at: usize, m: &crate::ManAddr) {
    let [a, b, c, d] = m.ipv4;
    for (k, v) in [1, 4, a.into(), b.into(), c.into(), d.into()]
        .into_iter()
        .enumerate()
    {
        if let Some(x) = i.get_mut(at + k) {
            *x = v;
        }
    }
}

/// zeroDotZero: the Management Address TLV this device sends and keeps carries no OID.
const ZERO_DOT_ZERO: [u32; 2] = [0, 0];

/// TruthValue: true (1), false (2).
fn truth(b: bool) -> Val<'static> {
    Val::Int(if b { 1 } else { 2 })
}

fn pno_val<'a>(c: u32, p: &crate::Pno, nos: &'a [u8]) -> Val<'a> {
    match c {
        1 => Val::Gauge(p.delay.line),
        2 => Val::Gauge(p.delay.tx),
        3 => Val::Gauge(p.delay.rx),
        4 => Val::Int(i32::from(p.rt2 & 0x3)),
        5 => Val::Int(i32::from(p.rt3 & 0x7)),
        _ => Val::Str(nos),
    }
}

fn dot3_val(c: u32, m: &crate::MacPhy) -> Val<'_> {
    match c {
        1 => truth(m.autoneg & 1 != 0),
        2 => truth(m.autoneg & 2 != 0),
        3 => Val::Str(&m.advertised),
        _ => Val::Int(i32::from(m.mau_type)),
    }
}

fn man_addr_val(c: u32, m: Option<&crate::ManAddr>) -> Val<'static> {
    match (c, m) {
        (_, None) => Val::Int(0),
        (1, Some(m)) => Val::Int(i32::from(m.if_subtype)),
        (2, Some(m)) => Val::Int(i32::try_from(m.if_id).unwrap_or(i32::MAX)),
        _ => Val::Oid(&ZERO_DOT_ZERO),
    }
}

/// The OID of object `o` with instance suffix `inst`.
pub fn full(o: &Obj, inst: &[u32]) -> Option<Oid> {
    let mut x = Oid::from_arcs(o.entry)?;
    x.push(o.col)?;
    for &a in inst {
        x.push(a)?;
    }
    Some(x)
}

/// Exact lookup: (object, row) for an OID.
pub fn find(oid: &[u32], dev: &Device) -> Lookup {
    for o in OBJECTS {
        let rest = oid
            .strip_prefix(o.entry)
            .and_then(|r| r.split_first())
            .and_then(|(&c, rest)| (c == o.col).then_some(rest));
        if let Some(rest) = rest {
            for r in 0..o.id.rows() {
                if let Some((i, n)) = o.id.instance(r, dev) {
                    if i.get(..n) == Some(rest) {
                        return Lookup::Found(o.id, r);
                    }
                }
            }
            return Lookup::NoInstance;
        }
    }
    Lookup::NoObject
}

/// Result of [`find`].
pub enum Lookup {
    /// The instance exists: object and row.
    Found(Id, u32),
    /// The object exists, the instance does not (noSuchInstance).
    NoInstance,
    /// No such object (noSuchObject).
    NoObject,
}

/// The first instance strictly after `oid`, with its full OID.
pub fn next(oid: &[u32], dev: &Device) -> Option<(Id, u32, Oid)> {
    for o in OBJECTS {
        for r in 0..o.id.rows() {
            if let Some((i, n)) = o.id.instance(r, dev) {
                let f = full(o, i.get(..n).unwrap_or(&[]))?;
                if f.arcs() > oid {
                    return Some((o.id, r, f));
                }
            }
        }
    }
    None
}

/// sysObjectID: under 32473, the enterprise number RFC 5612 reserves for
/// documentation, until the vendor's own is set (the project has none; the
/// vendor ID 0xFEFE is a test ID as well).
const ENTERPRISE: [u32; 8] = [1, 3, 6, 1, 4, 1, 32473, 1];

/// The value of object `id` at row `r`.
pub fn value<'a>(id: Id, r: u32, agent: &'a Agent, dev: &'a Device<'a>) -> Val<'a> {
    let port = r + 1;
    match id {
        Id::SysDescr | Id::LocSysDesc => Val::Str(dev.descr),
        Id::SysObjectId => Val::Oid(&ENTERPRISE),
        Id::SysUpTime => Val::Ticks(dev.uptime_cs),
        Id::SysContact => Val::Str(agent.sys_contact.get()),
        Id::SysName | Id::LocSysName => Val::Str(agent.sys_name.get()),
        Id::SysLocation => Val::Str(agent.sys_location.get()),
        // physical (1) + applications (64)
        Id::SysServices => Val::Int(0x42),
        Id::IfNumber => Val::Int(IFS as i32),
        Id::If(c) => match c {
            1 => Val::Int(port as i32),
            2 => Val::Str(match port {
                1 => b"PROFINET interface",
                2 => b"port-001",
                _ => b"port-002",
            }),
            // ethernetCsmacd
            3 => Val::Int(6),
            4 => Val::Int(1500),
            5 => Val::Gauge(if port == 1 || dev.link(port - 1) {
                100_000_000
            } else {
                0
            }),
            6 => Val::Str(dev.mac(port - 1)),
            7 => Val::Int(1),
            _ => Val::Int(if port == 1 || dev.link(port - 1) { 1 } else { 2 }),
        },
        // what the LLDPDU's chassis ID TLV sends (profinet::lldp::build_frame,
        // IEC 61158-6-10): local(7), the NameOfStation, once named; before,
        // macAddress(4), the interface MAC
        Id::LocChassisIdSubtype => Val::Int(if dev.name_of_station.is_empty() { 4 } else { 7 }),
        Id::LocChassisId if dev.name_of_station.is_empty() => Val::Str(dev.mac(0)),
        Id::LocChassisId => Val::Str(dev.name_of_station),
        Id::LocPort(c) => match c {
            // locallyAssigned(7): the PROFINET port name
            2 => Val::Int(7),
            3 | 4 => Val::Str(if port == 1 { b"port-001" } else { b"port-002" }),
            _ => Val::Int(0),
        },
        Id::Rem(c) => match dev.neighbor(port) {
            None => Val::Int(0),
            Some(n) => match c {
                4 => Val::Int(i32::from(n.chassis_subtype)),
                5 => Val::Str(n.chassis_id),
                6 => Val::Int(i32::from(n.port_subtype)),
                7 => Val::Str(n.port_id),
                _ => Val::Str(n.sys_name),
            },
        },
        Id::Config(c) => {
            let l = &dev.lldp;
            let v = match c {
                1 => l.tx_interval,
                2 => l.hold,
                3 => l.reinit_delay,
                4 => l.tx_delay,
                _ => l.notification_interval,
            };
            Val::Int(i32::try_from(v).unwrap_or(i32::MAX))
        }
        Id::PortConfig(c) => match c {
            // txAndRx(3)
            2 => Val::Int(3),
            // no notifications
            3 => truth(false),
            _ => Val::Str(core::slice::from_ref(&dev.lldp.tlvs_tx)),
        },
        Id::Stats(c) => {
            let s = &dev.lldp.stats;
            match c {
                1 => Val::Ticks(s.last_change_cs),
                // ZeroBasedCounter32 (a Gauge32)
                2 => Val::Gauge(s.inserts),
                3 => Val::Gauge(s.deletes),
                4 => Val::Gauge(s.drops),
                _ => Val::Gauge(s.ageouts),
            }
        }
        Id::StatsTx => Val::Counter(dev.lldp.stats.tx.get(r as usize).copied().unwrap_or(0)),
        Id::StatsRx(c) => {
            let x = dev.lldp.stats.rx.get(r as usize).copied().unwrap_or_default();
            match c {
                2 => Val::Counter(x.discarded),
                3 => Val::Counter(x.errors),
                4 => Val::Counter(x.frames),
                5 => Val::Counter(x.tlvs_discarded),
                6 => Val::Counter(x.tlvs_unrecognized),
                _ => Val::Gauge(x.ageouts),
            }
        }
        Id::ConfigManAddrPorts => Val::Str(&dev.man_addr_ports),
        // lldpLocManAddrLen: subtype and address octets (5)
        Id::LocManAddr(3) => Val::Int(5),
        Id::LocManAddr(c) => man_addr_val(c.saturating_sub(3), dev.man_addr.as_ref()),
        Id::RemManAddr(c) => man_addr_val(
            c.saturating_sub(2),
            dev.neighbor(port).and_then(|n| n.man_addr.as_ref()),
        ),
        Id::PnoLoc(c) => match dev.port(port) {
            Some(p) => pno_val(c, &p.pno, dev.name_of_station),
            None => Val::Int(0),
        },
        Id::PnoRem(c) => match dev.neighbor(port) {
            Some(n) => pno_val(c, &n.pno.unwrap_or_default(), n.sys_name),
            None => Val::Int(0),
        },
        Id::Dot3Loc(c) => match dev.port(port) {
            Some(p) => dot3_val(c, &p.mac_phy),
            None => Val::Int(0),
        },
        Id::Dot3Rem(c) => match dev.neighbor(port).and_then(|n| n.mac_phy.as_ref()) {
            Some(m) => dot3_val(c, m),
            None => Val::Int(0),
        },
    }
}

/// MIB-II system's OID (for tests and callers).
pub const SYS_PREFIX: &[u32] = &[1, 3, 6, 1, 2, 1, 1];
/// lldpLocalSystemData's OID.
pub const LLDP_LOC_PREFIX: &[u32] = &[1, 0, 8802, 1, 1, 2, 1, 3];
