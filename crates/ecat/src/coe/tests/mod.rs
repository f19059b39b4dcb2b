//! CoE server tests against a small dictionary (spec §6–7, E-062..E-085):
//! the dictionary and the request helpers; the tests, by topic, in the submodules.

extern crate std;
use std::collections::BTreeMap;
use std::vec;
use std::vec::Vec;

use super::*;
use crate::sdo_info::opcode;
use od::{Access, DataType, EntryInfo, ObjectCode, ObjectInfo};

mod complete_access;
mod robustness;
mod sdo_info;
mod transfer;

const fn entry(sub: u8, name: &'static str, data_type: DataType, access: Access) -> EntryInfo {
    EntryInfo::new(sub, name, data_type, access)
}

const fn ranged(e: EntryInfo, min: i64, max: i64, default: i64) -> EntryInfo {
    EntryInfo {
        min: Some(min),
        max: Some(max),
        default,
        ..e
    }
}

const RW: Access = Access::RW;

static E_ASSIGN: [EntryInfo; 2] = [
    ranged(entry(0, "Number of assigned PDOs", DataType::U8, RW), 0, 4, 0),
    entry(1, "PDO", DataType::U16, RW),
];
static E_WORD: [EntryInfo; 1] = [ranged(
    entry(0, "Word", DataType::U16, Access::RW.with(Access::RXPDO)),
    -5,
    60000,
    100,
)];
static E_OCTETS: [EntryInfo; 1] = [entry(0, "Octets", DataType::OctetString(16), RW)];
static E_RECORD: [EntryInfo; 4] = [
    entry(0, "Highest sub-index", DataType::U8, RW),
    entry(1, "First", DataType::U16, Access::RW.with(Access::TXPDO)),
    ranged(entry(2, "Second", DataType::U32, RW), 0, 1000, 7),
    entry(3, "Third", DataType::U8, Access::RW_PREOP),
];
static E_WO: [EntryInfo; 1] = [entry(0, "Secret", DataType::U32, Access::WO)];
static E_RO: [EntryInfo; 1] = [entry(0, "Version", DataType::U32, Access::RO.with(Access::TXPDO))];
static E_BIG: [EntryInfo; 1] = [entry(0, "Big", DataType::OctetString(5000), RW)];
static E_PREOP: [EntryInfo; 1] = [entry(0, "PreOp only", DataType::I16, Access::RW_PREOP)];

const fn object(
    index: u16,
    name: &'static str,
    code: ObjectCode,
    entries: &'static [EntryInfo],
) -> ObjectInfo {
    ObjectInfo {
        index,
        name,
        code,
        entries: od::Entries::slice(entries),
    }
}

static OBJECTS: [ObjectInfo; 8] = [
    object(0x1C12, "RxPDO assign", ObjectCode::Array, &E_ASSIGN),
    object(0x2000, "Word", ObjectCode::Var, &E_WORD),
    object(0x2001, "Octets", ObjectCode::Var, &E_OCTETS),
    object(0x2002, "Record", ObjectCode::Record, &E_RECORD),
    object(0x2003, "Secret", ObjectCode::Var, &E_WO),
    object(0x2004, "Version", ObjectCode::Var, &E_RO),
    object(0x2005, "Big", ObjectCode::Var, &E_BIG),
    object(0x2006, "PreOp only", ObjectCode::Var, &E_PREOP),
];

static E_MANY: [EntryInfo; 1] = [entry(0, "Many", DataType::U8, Access::RO)];
const MANY_N: usize = 100;
static MANY: [ObjectInfo; MANY_N] = {
    let mut a = [object(0x3000, "Many", ObjectCode::Var, &E_MANY); MANY_N];
    let mut i = 0;
    while i < MANY_N {
        a[i].index = 0x3000 + i as u16;
        i += 1;
    }
    a
};

/// The test dictionary: values by (index, sub), every write logged.
struct Dict {
    values: BTreeMap<(u16, u8), Vec<u8>>,
    writes: Vec<(u16, u8, Vec<u8>)>,
    reads: usize,
    many: bool,
    /// Refuse writes to this entry with this code.
    refuse: Option<(u16, u8, SdoAbort)>,
    /// Refuse writes of exactly this value to this entry with this code.
    refuse_value: Option<(u16, u8, Vec<u8>, SdoAbort)>,
}

impl Dict {
    fn new() -> Self {
        let mut values = BTreeMap::new();
        values.insert((0x1C12, 0), vec![2]);
        values.insert((0x1C12, 1), 0x1600u16.to_le_bytes().to_vec());
        values.insert((0x1C12, 2), 0x1601u16.to_le_bytes().to_vec());
        values.insert((0x2000, 0), vec![0x34, 0x12]);
        values.insert((0x2001, 0), (1..=16).collect());
        values.insert((0x2002, 0), vec![3]);
        values.insert((0x2002, 1), vec![0x11, 0x11]);
        values.insert((0x2002, 2), vec![0x22, 0x22, 0x22, 0x22]);
        values.insert((0x2002, 3), vec![0x33]);
        values.insert((0x2004, 0), vec![0xEF, 0xBE, 0xAD, 0xDE]);
        values.insert((0x2005, 0), vec![0x55; 5000]);
        Dict {
            values,
            writes: Vec::new(),
            reads: 0,
            many: false,
            refuse: None,
            refuse_value: None,
        }
    }

    fn all(&self) -> impl Iterator<Item = &'static ObjectInfo> {
        let many: &'static [ObjectInfo] = if self.many { &MANY } else { &[] };
        OBJECTS.iter().chain(many.iter())
    }

    fn entry(&self, index: u16, sub: u8) -> Result<EntryInfo, SdoAbort> {
        let info = self.object(index).ok_or(SdoAbort::NO_OBJECT)?;
        complete::element(info, sub).ok_or(SdoAbort::NO_SUBINDEX)
    }
}

impl Dictionary for Dict {
    fn object(&self, index: u16) -> Option<&'static ObjectInfo> {
        self.all().find(|o| o.index == index)
    }
    fn next_object(&self, after: Option<u16>) -> Option<&'static ObjectInfo> {
        self.all().find(|o| after.is_none_or(|a| o.index > a))
    }
    fn read(&mut self, index: u16, sub: u8, buf: &mut [u8], _: CommState) -> Result<usize, SdoAbort> {
        let e = self.entry(index, sub)?;
        if !e.access.readable() {
            return Err(SdoAbort::WRITE_ONLY);
        }
        self.reads += 1;
        let v = self
            .values
            .get(&(index, sub))
            .cloned()
            .unwrap_or_else(|| vec![0; e.data_type.bytes()]);
        buf.get_mut(..v.len())
            .ok_or(SdoAbort::OUT_OF_MEMORY)?
            .copy_from_slice(&v);
        Ok(v.len())
    }
    fn write(&mut self, index: u16, sub: u8, data: &[u8], state: CommState) -> Result<(), SdoAbort> {
        let e = self.entry(index, sub)?;
        if !e.access.writable_in(state.access_bit()) {
            return Err(if e.access.writable() {
                SdoAbort::DEVICE_STATE
            } else {
                SdoAbort::READ_ONLY
            });
        }
        if data.len() > e.data_type.bytes() {
            return Err(SdoAbort::LENGTH_TOO_HIGH);
        }
        if data.len() < e.data_type.bytes() {
            return Err(SdoAbort::LENGTH_TOO_LOW);
        }
        if let Some((i, s, code)) = self.refuse {
            if (i, s) == (index, sub) {
                return Err(code);
            }
        }
        if let Some((i, s, v, code)) = &self.refuse_value {
            if (*i, *s) == (index, sub) && v == data {
                return Err(*code);
            }
        }
        self.writes.push((index, sub, data.to_vec()));
        self.values.insert((index, sub), data.to_vec());
        Ok(())
    }
}

struct T {
    srv: CoeServer,
    dict: Dict,
    cap: usize,
    now: Nanos,
    state: AlState,
}

impl T {
    fn new(cap: usize) -> Self {
        T {
            srv: CoeServer::new(CoeConfig::ALL),
            dict: Dict::new(),
            cap,
            now: Nanos::ZERO,
            state: AlState::PreOp,
        }
    }
    /// One CoE request (header included); the reply's bytes.
    fn raw(&mut self, req: &[u8]) -> Result<Option<Vec<u8>>, MailboxError> {
        self.now += Nanos::from_ms(1);
        let mut out = vec![0xEE; self.cap];
        let r = self
            .srv
            .handle(req, &mut out, &mut self.dict, self.state, self.now)?;
        Ok(r.map(|n| out[..n].to_vec()))
    }
    /// An SDO request (after the CoE header); the reply, which must exist.
    fn sdo(&mut self, sdo: &[u8]) -> Vec<u8> {
        let mut req = vec![0x00, 0x20];
        req.extend_from_slice(sdo);
        self.raw(&req).unwrap().expect("a reply")
    }
    /// An SDO Info request (opcode, data); the reply.
    fn info(&mut self, op: u8, data: &[u8]) -> Vec<u8> {
        let mut req = vec![0x00, 0x80, op, 0, 0, 0];
        req.extend_from_slice(data);
        self.raw(&req).unwrap().expect("a reply")
    }
    fn fragment(&mut self) -> Option<Vec<u8>> {
        let mut out = vec![0xEE; self.cap];
        let n = self.srv.next_fragment(&mut out, &mut self.dict)?;
        Some(out[..n].to_vec())
    }
}

/// The SDO part of a response (after the CoE header), checking the header
/// says SDO response.
fn resp(r: &[u8]) -> &[u8] {
    assert_eq!(&r[..2], &[0x00, 0x30], "SDO response header");
    &r[2..]
}

/// The abort code of an abort frame (service 2, command 80h) for index:sub.
fn abort(r: &[u8], index: u16, sub: u8) -> u32 {
    assert_eq!(r.len(), 10);
    assert_eq!(&r[..2], &[0x00, 0x20], "abort goes as SDO request");
    assert_eq!(r[2], 0x80);
    assert_eq!(u16::from_le_bytes([r[3], r[4]]), index);
    assert_eq!(r[5], sub);
    u32::from_le_bytes(r[6..10].try_into().unwrap())
}

fn upload_req(index: u16, sub: u8) -> [u8; 8] {
    let [i0, i1] = index.to_le_bytes();
    [0x40, i0, i1, sub, 0, 0, 0, 0]
}
