//! The MIB view: MIB-II system and interfaces, LLDP-MIB local and remote data, as an ordered
//! list of objects whose instances are enumerated in lexicographic order.

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
}

const SYS: [u32; 7] = [1, 3, 6, 1, 2, 1, 1];
const LLDP_LOC: [u32; 8] = [1, 0, 8802, 1, 1, 2, 1, 3];

/// One object: its OID (without instance) and identity.
pub struct Obj {
    /// OID prefix.
    pub base: &'static [u32],
    /// Identity.
    pub id: Id,
}

macro_rules! o {
    ($id:expr, $($a:expr),*) => { Obj { base: &[$($a),*], id: $id } };
}

/// Every object, in OID order (checked by a unit test).
pub static OBJECTS: &[Obj] = &[
    o!(Id::LocChassisIdSubtype, 1, 0, 8802, 1, 1, 2, 1, 3, 1),
    o!(Id::LocChassisId, 1, 0, 8802, 1, 1, 2, 1, 3, 2),
    o!(Id::LocSysName, 1, 0, 8802, 1, 1, 2, 1, 3, 3),
    o!(Id::LocSysDesc, 1, 0, 8802, 1, 1, 2, 1, 3, 4),
    o!(Id::LocPort(2), 1, 0, 8802, 1, 1, 2, 1, 3, 7, 1, 2),
    o!(Id::LocPort(3), 1, 0, 8802, 1, 1, 2, 1, 3, 7, 1, 3),
    o!(Id::LocPort(4), 1, 0, 8802, 1, 1, 2, 1, 3, 7, 1, 4),
    o!(Id::Rem(4), 1, 0, 8802, 1, 1, 2, 1, 4, 1, 1, 4),
    o!(Id::Rem(5), 1, 0, 8802, 1, 1, 2, 1, 4, 1, 1, 5),
    o!(Id::Rem(6), 1, 0, 8802, 1, 1, 2, 1, 4, 1, 1, 6),
    o!(Id::Rem(7), 1, 0, 8802, 1, 1, 2, 1, 4, 1, 1, 7),
    o!(Id::Rem(9), 1, 0, 8802, 1, 1, 2, 1, 4, 1, 1, 9),
    o!(Id::SysDescr, 1, 3, 6, 1, 2, 1, 1, 1),
    o!(Id::SysObjectId, 1, 3, 6, 1, 2, 1, 1, 2),
    o!(Id::SysUpTime, 1, 3, 6, 1, 2, 1, 1, 3),
    o!(Id::SysContact, 1, 3, 6, 1, 2, 1, 1, 4),
    o!(Id::SysName, 1, 3, 6, 1, 2, 1, 1, 5),
    o!(Id::SysLocation, 1, 3, 6, 1, 2, 1, 1, 6),
    o!(Id::SysServices, 1, 3, 6, 1, 2, 1, 1, 7),
    o!(Id::IfNumber, 1, 3, 6, 1, 2, 1, 2, 1),
    o!(Id::If(1), 1, 3, 6, 1, 2, 1, 2, 2, 1, 1),
    o!(Id::If(2), 1, 3, 6, 1, 2, 1, 2, 2, 1, 2),
    o!(Id::If(3), 1, 3, 6, 1, 2, 1, 2, 2, 1, 3),
    o!(Id::If(4), 1, 3, 6, 1, 2, 1, 2, 2, 1, 4),
    o!(Id::If(5), 1, 3, 6, 1, 2, 1, 2, 2, 1, 5),
    o!(Id::If(6), 1, 3, 6, 1, 2, 1, 2, 2, 1, 6),
    o!(Id::If(7), 1, 3, 6, 1, 2, 1, 2, 2, 1, 7),
    o!(Id::If(8), 1, 3, 6, 1, 2, 1, 2, 2, 1, 8),
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
            Id::LocPort(_) | Id::Rem(_) => PORTS,
            _ => 1,
        }
    }
    /// Instance suffix of row `r` (0-based), or `None` when that row does not exist.
    fn instance(self, r: u32, dev: &Device) -> Option<([u32; 3], usize)> {
        match self {
            Id::If(_) => Some(([r + 1, 0, 0], 1)),
            Id::LocPort(_) => Some(([r + 1, 0, 0], 1)),
            // lldpRemTimeMark 0, lldpRemLocalPortNum, lldpRemIndex 1
            Id::Rem(_) => dev.neighbor(r + 1).map(|_| ([0, r + 1, 1], 3)),
            _ => Some(([0, 0, 0], 1)),
        }
    }
}

fn full(o: &Obj, inst: &[u32]) -> Option<Oid> {
    let mut x = Oid::from_arcs(o.base)?;
    for &a in inst {
        x.push(a)?;
    }
    Some(x)
}

/// Exact lookup: (object, row) for an OID.
pub fn find(oid: &[u32], dev: &Device) -> Lookup {
    for o in OBJECTS {
        if let Some(rest) = oid.strip_prefix(o.base) {
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
        // macAddress(4)
        Id::LocChassisIdSubtype => Val::Int(4),
        Id::LocChassisId => Val::Str(dev.mac(0)),
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
    }
}

/// sysContact's OID prefix etc. (for tests and callers).
pub const SYS_PREFIX: &[u32] = &SYS;
/// lldpLocalSystemData prefix.
pub const LLDP_LOC_PREFIX: &[u32] = &LLDP_LOC;
