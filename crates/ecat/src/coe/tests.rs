//! CoE server tests against a small dictionary (spec §6–7, E-062..E-085).

extern crate std;
use std::collections::BTreeMap;
use std::vec;
use std::vec::Vec;

use super::*;
use crate::sdo_info::opcode;
use od::{Access, DataType, EntryInfo, ObjectCode, ObjectInfo};

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

// ---------------------------------------------------------------- expedited

#[test]
fn e063_expedited_upload_with_size() {
    let mut t = T::new(64);
    let r = t.sdo(&upload_req(0x2000, 0));
    assert_eq!(resp(&r), &[0x4B, 0x00, 0x20, 0x00, 0x34, 0x12, 0, 0]);
    let r = t.sdo(&upload_req(0x2002, 3));
    assert_eq!(resp(&r), &[0x4F, 0x02, 0x20, 0x03, 0x33, 0, 0, 0]);
    let r = t.sdo(&upload_req(0x2004, 0));
    assert_eq!(resp(&r), &[0x43, 0x04, 0x20, 0x00, 0xEF, 0xBE, 0xAD, 0xDE]);
}

#[test]
fn e063_expedited_download_sizes() {
    let mut t = T::new(64);
    // 2Fh: 1 byte, 2Bh: 2 bytes, 23h: 4 bytes, 22h: size not indicated (cut to the entry)
    for (cmd, index, sub, value) in [
        (0x2F, 0x2002, 3, &[0xA1][..]),
        (0x2B, 0x2000, 0, &[0x01, 0x02][..]),
        (0x23, 0x2002, 2, &[0x04, 0x03, 0x02, 0x01][..]),
        (0x22, 0x2000, 0, &[0x0A, 0x0B][..]),
    ] {
        let [i0, i1] = u16::to_le_bytes(index);
        let mut req = [cmd, i0, i1, sub, 0, 0, 0, 0];
        req[4..4 + value.len()].copy_from_slice(value);
        if cmd == 0x22 {
            req[6] = 0xFF; // the unused bytes of a size-less request
        }
        let r = t.sdo(&req);
        assert_eq!(resp(&r), &[0x60, i0, i1, sub, 0, 0, 0, 0]);
        assert_eq!(t.dict.writes.last().unwrap(), &(index, sub, value.to_vec()));
    }
    assert_eq!(t.dict.writes.len(), 4);
}

#[test]
fn e073_expedited_length_mismatch_aborts_0607_0012() {
    let mut t = T::new(64);
    // 27h: 3 bytes to a UINT16
    let r = t.sdo(&[0x27, 0x00, 0x20, 0x00, 1, 2, 3, 0]);
    assert_eq!(abort(&r, 0x2000, 0), 0x0607_0012);
    let r = t.sdo(&[0x2F, 0x02, 0x20, 0x02, 1, 0, 0, 0]);
    assert_eq!(abort(&r, 0x2002, 2), 0x0607_0013);
    assert!(t.dict.writes.is_empty());
}

// ---------------------------------------------------------------- normal

#[test]
fn e064_normal_upload_carries_size_and_data() {
    let mut t = T::new(64);
    let r = t.sdo(&upload_req(0x2001, 0));
    assert_eq!(r.len(), 26);
    let mut expect = vec![0x41, 0x01, 0x20, 0x00, 16, 0, 0, 0];
    expect.extend(1..=16u8);
    assert_eq!(resp(&r), &expect[..]);
    assert!(!t.srv.transfer_in_progress());
    assert_eq!(t.dict.reads, 1);
}

#[test]
fn e064_normal_download_with_data_in_initiate() {
    let mut t = T::new(64);
    let mut req = vec![0x21, 0x01, 0x20, 0x00, 16, 0, 0, 0];
    req.extend((0..16u8).map(|b| b ^ 0xFF));
    let r = t.sdo(&req);
    assert_eq!(resp(&r), &[0x60, 0x01, 0x20, 0x00, 0, 0, 0, 0]);
    assert_eq!(t.dict.writes, vec![(0x2001, 0, req[8..].to_vec())]);
    assert!(!t.srv.transfer_in_progress());
}

#[test]
fn e064_e065_partial_initiate_data_then_long_segment() {
    let mut t = T::new(64);
    // initiate carries 5 of 16 bytes, one 11-byte segment (longer than 7) ends it
    let r = t.sdo(&[0x21, 0x01, 0x20, 0x00, 16, 0, 0, 0, 1, 2, 3, 4, 5]);
    assert_eq!(resp(&r), &[0x60, 0x01, 0x20, 0x00, 0, 0, 0, 0]);
    assert!(t.dict.writes.is_empty());
    let r = t.sdo(&[0x01, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16]);
    assert_eq!(resp(&r), &[0x20, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(t.dict.writes, vec![(0x2001, 0, (1..=16).collect())]);
}

// ---------------------------------------------------------------- segmented (§6.4)

#[test]
fn e065_e067_segmented_download_worked_example() {
    let mut t = T::new(64);
    let exchange: [(&[u8], &[u8]); 4] = [
        (
            &[0x21, 0x01, 0x20, 0x00, 0x10, 0x00, 0x00, 0x00],
            &[0x60, 0x01, 0x20, 0x00, 0x00, 0x00, 0x00, 0x00],
        ),
        (
            &[0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07],
            &[0x20, 0, 0, 0, 0, 0, 0, 0],
        ),
        (
            &[0x10, 0x08, 0x09, 0x0A, 0x0B, 0x0C, 0x0D, 0x0E],
            &[0x30, 0, 0, 0, 0, 0, 0, 0],
        ),
        (
            &[0x0B, 0x0F, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00],
            &[0x20, 0, 0, 0, 0, 0, 0, 0],
        ),
    ];
    for (i, (c, s)) in exchange.iter().enumerate() {
        let r = t.sdo(c);
        assert_eq!(resp(&r), *s, "step {i}");
        // one write, at the end
        assert_eq!(t.dict.writes.len(), usize::from(i == 3), "step {i}");
    }
    assert_eq!(t.dict.writes, vec![(0x2001, 0, (1..=16).collect())]);
}

#[test]
fn e066_e067_segmented_upload_worked_example() {
    // a 16-byte mailbox (10 data bytes): 7-byte segments as in S §9.3.2.3
    let mut t = T::new(10);
    let exchange: [(&[u8], &[u8]); 4] = [
        (
            &[0x40, 0x01, 0x20, 0x00, 0, 0, 0, 0],
            &[0x41, 0x01, 0x20, 0x00, 0x10, 0x00, 0x00, 0x00],
        ),
        (
            &[0x60, 0, 0, 0, 0, 0, 0, 0],
            &[0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07],
        ),
        (
            &[0x70, 0, 0, 0, 0, 0, 0, 0],
            &[0x10, 0x08, 0x09, 0x0A, 0x0B, 0x0C, 0x0D, 0x0E],
        ),
        (
            &[0x60, 0, 0, 0, 0, 0, 0, 0],
            &[0x0B, 0x0F, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00],
        ),
    ];
    for (i, (c, s)) in exchange.iter().enumerate() {
        let r = t.sdo(c);
        assert_eq!(resp(&r), *s, "step {i}");
    }
    assert_eq!(t.dict.reads, 1, "read once at the initiate");
    assert!(!t.srv.transfer_in_progress());
    // the transfer is over: another segment request is unknown
    let r = t.sdo(&[0x70, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0, 0), 0x0504_0001);
}

#[test]
fn e066_segmented_upload_uses_the_mailbox_size() {
    // 20 data bytes: the value (16) does not fit the initiate (10 + 16), one
    // 16-byte segment (segment data = mailbox data − 3) with c = 1, n = 0
    let mut t = T::new(20);
    let r = t.sdo(&upload_req(0x2001, 0));
    assert_eq!(resp(&r), &[0x41, 0x01, 0x20, 0x00, 16, 0, 0, 0]);
    let r = t.sdo(&[0x60, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(r.len(), 19);
    assert_eq!(resp(&r)[0], 0x01);
    assert_eq!(&resp(&r)[1..], &(1..=16).collect::<Vec<u8>>()[..]);
    // a 120-byte value in a 40-byte mailbox: 37-byte segments, last has 9 + padding
    let mut t = T::new(40);
    t.dict.values.insert((0x2005, 0), (0..120).collect());
    let r = t.sdo(&upload_req(0x2005, 0));
    assert_eq!(resp(&r), &[0x41, 0x05, 0x20, 0x00, 120, 0, 0, 0]);
    let mut got = Vec::new();
    let mut toggle = 0;
    loop {
        let r = t.sdo(&[0x60 | toggle, 0, 0, 0, 0, 0, 0, 0]);
        let s = resp(&r);
        assert_eq!(s[0] & 0x10, toggle, "toggle echoed");
        let n = if s.len() == 8 {
            7 - usize::from((s[0] >> 1) & 7)
        } else {
            s.len() - 1
        };
        got.extend_from_slice(&s[1..1 + n]);
        if s[0] & 1 != 0 {
            break;
        }
        toggle ^= 0x10;
    }
    assert_eq!(got, (0..120).collect::<Vec<u8>>());
}

// ---------------------------------------------------------------- aborts

#[test]
fn e068_toggle_error_aborts_0503_0000() {
    let mut t = T::new(64);
    t.sdo(&[0x21, 0x01, 0x20, 0x00, 16, 0, 0, 0]);
    t.sdo(&[0x00, 1, 2, 3, 4, 5, 6, 7]);
    // the second segment must carry t = 1
    let r = t.sdo(&[0x00, 8, 9, 10, 11, 12, 13, 14]);
    assert_eq!(abort(&r, 0x2001, 0), 0x0503_0000);
    assert!(t.dict.writes.is_empty());
    assert!(!t.srv.transfer_in_progress());
    // upload: first segment request with t = 1
    let mut t = T::new(10);
    t.sdo(&upload_req(0x2001, 0));
    let r = t.sdo(&[0x70, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0x2001, 0), 0x0503_0000);
}

#[test]
fn e069_segment_without_transfer_and_unknown_command_abort_0504_0001() {
    let mut t = T::new(64);
    let r = t.sdo(&[0x00, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(abort(&r, 0, 0), 0x0504_0001);
    let r = t.sdo(&[0x60, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0, 0), 0x0504_0001);
    // block download / block upload / ccs 7
    for cmd in [0xC6, 0xA4, 0xE0] {
        let r = t.sdo(&[cmd, 0x00, 0x20, 0x00, 0, 0, 0, 0]);
        assert_eq!(abort(&r, 0x2000, 0), 0x0504_0001, "cmd {cmd:#x}");
    }
    // an upload segment request during a download
    t.sdo(&[0x21, 0x01, 0x20, 0x00, 16, 0, 0, 0]);
    let r = t.sdo(&[0x60, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0x2001, 0), 0x0504_0001);
    assert!(!t.srv.transfer_in_progress());
}

#[test]
fn e069_protocol_timeout_aborts_0504_0000() {
    let mut t = T::new(64);
    t.sdo(&[0x21, 0x01, 0x20, 0x00, 16, 0, 0, 0]);
    t.now += Nanos::from_ms(900); // within the timeout
    let r = t.sdo(&[0x00, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(resp(&r)[0], 0x20);
    t.now += SDO_TIMEOUT + Nanos::from_ns(1);
    t.srv.tick(t.now);
    assert!(!t.srv.transfer_in_progress());
    // the next segment learns about it
    let r = t.sdo(&[0x10, 8, 9, 10, 11, 12, 13, 14]);
    assert_eq!(abort(&r, 0x2001, 0), 0x0504_0000);
    let r = t.sdo(&[0x0B, 15, 16, 0, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0, 0), 0x0504_0001);
    assert!(t.dict.writes.is_empty());
    // upload: timeout seen by handle itself
    let mut t = T::new(10);
    t.sdo(&upload_req(0x2001, 0));
    t.now += 2 * SDO_TIMEOUT;
    let r = t.sdo(&[0x60, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0x2001, 0), 0x0504_0000);
}

#[test]
fn e070_out_of_memory_aborts_0504_0005_before_any_write() {
    let mut t = T::new(64);
    // announced 5000 bytes > 4 KiB
    let r = t.sdo(&[0x21, 0x05, 0x20, 0x00, 0x88, 0x13, 0, 0]);
    assert_eq!(abort(&r, 0x2005, 0), 0x0504_0005);
    assert!(!t.srv.transfer_in_progress());
    // size-less normal download growing past 4 KiB
    t.sdo(&[0x20, 0x05, 0x20, 0x00, 0, 0, 0, 0]);
    let mut toggle = 0u8;
    let mut last = None;
    for _ in 0..(MAX_TRANSFER / 50 + 2) {
        let mut seg = vec![toggle];
        seg.extend([0x77; 50]);
        let r = t.sdo(&seg);
        if r[2] == 0x80 {
            last = Some(r);
            break;
        }
        toggle ^= 0x10;
    }
    assert_eq!(abort(&last.unwrap(), 0x2005, 0), 0x0504_0005);
    // upload of a 5000-byte value: the dictionary cannot fill the 4 KiB buffer
    let r = t.sdo(&upload_req(0x2005, 0));
    assert_eq!(abort(&r, 0x2005, 0), 0x0504_0005);
    assert!(t.dict.writes.is_empty());
}

#[test]
fn e071_access_aborts() {
    let mut t = T::new(64);
    let r = t.sdo(&upload_req(0x2003, 0));
    assert_eq!(abort(&r, 0x2003, 0), 0x0601_0001);
    let r = t.sdo(&[0x23, 0x04, 0x20, 0x00, 1, 2, 3, 4]);
    assert_eq!(abort(&r, 0x2004, 0), 0x0601_0002);
    // complete access to a VAR
    let r = t.sdo(&[0x50, 0x00, 0x20, 0x00, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0x2000, 0), 0x0601_0000);
    // write-only value can be written
    let r = t.sdo(&[0x23, 0x03, 0x20, 0x00, 1, 2, 3, 4]);
    assert_eq!(resp(&r)[0], 0x60);
}

#[test]
fn e072_unknown_object_and_subindex() {
    let mut t = T::new(64);
    let r = t.sdo(&upload_req(0x6000, 0));
    assert_eq!(abort(&r, 0x6000, 0), 0x0602_0000);
    let r = t.sdo(&upload_req(0x2002, 9));
    assert_eq!(abort(&r, 0x2002, 9), 0x0609_0011);
}

#[test]
fn e073_announced_size_mismatch_aborts_0607_0010() {
    let mut t = T::new(64);
    // fewer bytes than announced
    t.sdo(&[0x21, 0x01, 0x20, 0x00, 16, 0, 0, 0]);
    t.sdo(&[0x00, 1, 2, 3, 4, 5, 6, 7]);
    let r = t.sdo(&[0x13, 8, 9, 10, 11, 12, 13, 14]);
    assert_eq!(abort(&r, 0x2001, 0), 0x0607_0010);
    // more bytes than announced
    t.sdo(&[0x21, 0x01, 0x20, 0x00, 10, 0, 0, 0]);
    t.sdo(&[0x00, 1, 2, 3, 4, 5, 6, 7]);
    let r = t.sdo(&[0x11, 8, 9, 10, 11, 12, 13, 14]);
    assert_eq!(abort(&r, 0x2001, 0), 0x0607_0010);
    assert!(t.dict.writes.is_empty());
}

#[test]
fn e077_abort_frame_layout() {
    let mut t = T::new(64);
    let r = t.sdo(&upload_req(0x2003, 0));
    // service 2, 80h, index, subindex, additional code (LSB, MSB), error code, class
    assert_eq!(r, [0x00, 0x20, 0x80, 0x03, 0x20, 0x00, 0x01, 0x00, 0x01, 0x06]);
}

#[test]
fn abort_from_master_cancels_the_transfer_without_reply() {
    let mut t = T::new(64);
    t.sdo(&[0x21, 0x01, 0x20, 0x00, 16, 0, 0, 0]);
    t.sdo(&[0x00, 1, 2, 3, 4, 5, 6, 7]);
    let r = t.raw(&[0x00, 0x20, 0x80, 0x01, 0x20, 0x00, 0, 0, 0x04, 0x05]);
    assert_eq!(r, Ok(None));
    assert!(!t.srv.transfer_in_progress());
    let r = t.sdo(&[0x1B, 8, 9, 0, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0, 0), 0x0504_0001);
    assert!(t.dict.writes.is_empty());
}

#[test]
fn new_initiate_replaces_the_transfer_in_progress() {
    let mut t = T::new(64);
    t.sdo(&[0x21, 0x01, 0x20, 0x00, 16, 0, 0, 0]);
    t.sdo(&[0x00, 1, 2, 3, 4, 5, 6, 7]);
    let r = t.sdo(&upload_req(0x2000, 0));
    assert_eq!(resp(&r)[0], 0x4B);
    let r = t.sdo(&[0x10, 8, 9, 10, 11, 12, 13, 14]);
    assert_eq!(abort(&r, 0, 0), 0x0504_0001);
}

#[test]
fn short_frames_and_unknown_services_are_mailbox_errors() {
    let mut t = T::new(64);
    assert_eq!(
        t.raw(&[0x00, 0x20, 0x40, 0x00, 0x20]),
        Err(MailboxError::SIZE_TOO_SHORT)
    );
    assert_eq!(t.raw(&[0x00]), Err(MailboxError::SIZE_TOO_SHORT));
    assert_eq!(
        t.raw(&[0x00, 0x30, 0x40, 0x00, 0x20, 0x00, 0, 0, 0, 0]),
        Err(MailboxError::SERVICE_NOT_SUPPORTED)
    );
    assert_eq!(
        t.raw(&[0x00, 0x80, 0x01, 0x00]),
        Err(MailboxError::SIZE_TOO_SHORT)
    );
}

#[test]
fn e062_sdo_in_preop_safeop_op() {
    for state in [AlState::PreOp, AlState::SafeOp, AlState::Op] {
        let mut t = T::new(64);
        t.state = state;
        let r = t.sdo(&upload_req(0x2000, 0));
        assert_eq!(resp(&r)[0], 0x4B);
        let r = t.sdo(&[0x2B, 0x06, 0x20, 0x00, 1, 0, 0, 0]);
        if state == AlState::PreOp {
            assert_eq!(resp(&r)[0], 0x60);
        } else {
            // the dictionary's state rule comes through unchanged
            assert_eq!(abort(&r, 0x2006, 0), 0x0800_0022);
        }
    }
}

// ---------------------------------------------------------------- complete access

#[test]
fn e078_complete_access_upload_from_sub0_and_sub1() {
    let mut t = T::new(64);
    // record: sub 0 as 16 bits, then 2 + 4 + 1 bytes
    let r = t.sdo(&[0x50, 0x02, 0x20, 0x00, 0, 0, 0, 0]);
    assert_eq!(
        resp(&r),
        &[0x41, 0x02, 0x20, 0x00, 9, 0, 0, 0, 3, 0, 0x11, 0x11, 0x22, 0x22, 0x22, 0x22, 0x33]
    );
    let r = t.sdo(&[0x50, 0x02, 0x20, 0x01, 0, 0, 0, 0]);
    assert_eq!(
        resp(&r),
        &[0x41, 0x02, 0x20, 0x01, 7, 0, 0, 0, 0x11, 0x11, 0x22, 0x22, 0x22, 0x22, 0x33]
    );
    // array with a template entry: the present count (2), expedited (≤ 4 bytes from sub 1)
    let r = t.sdo(&[0x50, 0x12, 0x1C, 0x00, 0, 0, 0, 0]);
    assert_eq!(
        resp(&r),
        &[0x41, 0x12, 0x1C, 0x00, 6, 0, 0, 0, 2, 0, 0x00, 0x16, 0x01, 0x16]
    );
    let r = t.sdo(&[0x50, 0x12, 0x1C, 0x01, 0, 0, 0, 0]);
    assert_eq!(resp(&r), &[0x43, 0x12, 0x1C, 0x01, 0x00, 0x16, 0x01, 0x16]);
    // only sub 0 or 1
    let r = t.sdo(&[0x50, 0x02, 0x20, 0x02, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0x2002, 2), 0x0601_0000);
}

#[test]
fn e078_complete_access_download_writes_sub0_zero_entries_then_count() {
    let mut t = T::new(64);
    let r = t.sdo(&[
        0x31, 0x12, 0x1C, 0x00, 8, 0, 0, 0, 3, 0, 0x00, 0x16, 0x02, 0x16, 0x03, 0x16,
    ]);
    assert_eq!(resp(&r), &[0x60, 0x12, 0x1C, 0x00, 0, 0, 0, 0]);
    assert_eq!(
        t.dict.writes,
        vec![
            (0x1C12, 0, vec![0]),
            (0x1C12, 1, vec![0x00, 0x16]),
            (0x1C12, 2, vec![0x02, 0x16]),
            (0x1C12, 3, vec![0x03, 0x16]),
            (0x1C12, 0, vec![3]),
        ]
    );
    // expedited complete access from sub 1 (as ethercrab sends it): the same
    // order, sub 0 = the number of entries in the data (the drive's dictionary
    // refuses entries while sub 0 != 0)
    t.dict.writes.clear();
    let r = t.sdo(&[0x33, 0x12, 0x1C, 0x01, 0x10, 0x1A, 0x11, 0x1A]);
    assert_eq!(resp(&r)[0], 0x60);
    assert_eq!(
        t.dict.writes,
        vec![
            (0x1C12, 0, vec![0]),
            (0x1C12, 1, vec![0x10, 0x1A]),
            (0x1C12, 2, vec![0x11, 0x1A]),
            (0x1C12, 0, vec![2]),
        ]
    );
}

#[test]
fn e078_complete_access_download_segmented_record() {
    let mut t = T::new(64);
    t.sdo(&[0x31, 0x02, 0x20, 0x00, 9, 0, 0, 0]);
    t.sdo(&[0x00, 3, 0, 0xAA, 0xAA, 0x05, 0x00, 0x00]);
    // t = 1, n = 5, c = 1
    let r = t.sdo(&[0x1B, 0x00, 0xBB, 0, 0, 0, 0, 0]);
    assert_eq!(resp(&r)[0], 0x30);
    assert_eq!(
        t.dict.writes,
        vec![
            (0x2002, 0, vec![0]),
            (0x2002, 1, vec![0xAA, 0xAA]),
            (0x2002, 2, vec![5, 0, 0, 0]),
            (0x2002, 3, vec![0xBB]),
            (0x2002, 0, vec![3]),
        ]
    );
}

#[test]
fn e078_complete_access_download_checks_before_writing() {
    let mut t = T::new(64);
    // sub 2 above its maximum (1000)
    let r = t.sdo(&[
        0x31, 0x02, 0x20, 0x00, 9, 0, 0, 0, 3, 0, 1, 1, 0xD0, 0x07, 0, 0, 1,
    ]);
    assert_eq!(abort(&r, 0x2002, 0), 0x0609_0031);
    // one byte short / long
    let r = t.sdo(&[0x31, 0x02, 0x20, 0x00, 8, 0, 0, 0, 3, 0, 1, 1, 5, 0, 0, 0]);
    assert_eq!(abort(&r, 0x2002, 0), 0x0607_0013);
    let r = t.sdo(&[0x31, 0x02, 0x20, 0x00, 10, 0, 0, 0, 3, 0, 1, 1, 5, 0, 0, 0, 1, 9]);
    assert_eq!(abort(&r, 0x2002, 0), 0x0607_0012);
    // more entries than the array holds
    let r = t.sdo(&[0x31, 0x12, 0x1C, 0x00, 4, 0, 0, 0, 5, 0, 0, 0]);
    assert_eq!(abort(&r, 0x1C12, 0), 0x0609_0031);
    // sub 3 is writable in PreOp only
    t.state = AlState::SafeOp;
    let r = t.sdo(&[0x31, 0x02, 0x20, 0x00, 9, 0, 0, 0, 3, 0, 1, 1, 5, 0, 0, 0, 1]);
    assert_eq!(abort(&r, 0x2002, 0), 0x0800_0022);
    assert!(t.dict.writes.is_empty());
    // in PreOp the same value goes through
    t.state = AlState::PreOp;
    let r = t.sdo(&[0x31, 0x02, 0x20, 0x00, 9, 0, 0, 0, 3, 0, 1, 1, 5, 0, 0, 0, 1]);
    assert_eq!(resp(&r)[0], 0x60);
    assert_eq!(t.dict.writes.len(), 5);
}

/// A refusal part-way (the dictionary's consistency check on entry 2)
/// aborts with its code and puts entry 1 and sub 0 back: the object reads
/// as before (found by the mailbox fuzz target's oracle: a complete
/// download of 1600h:01 aborted 0604 0041h and left the mapping empty).
#[test]
fn e078_complete_access_refused_entry_puts_the_old_values_back() {
    let mut t = T::new(64);
    t.dict.values.insert((0x1C12, 0), vec![1]);
    t.dict.values.insert((0x1C12, 1), vec![0x01, 0x16]);
    t.dict.values.insert((0x1C12, 2), vec![0x00, 0x00]);
    t.dict.refuse = Some((0x1C12, 2, SdoAbort::PARAMETER_INCOMPATIBLE));
    let r = t.sdo(&[0x31, 0x12, 0x1C, 0x00, 6, 0, 0, 0, 2, 0, 0x00, 0x16, 0x05, 0x16]);
    assert_eq!(abort(&r, 0x1C12, 0), 0x0604_0043);
    assert_eq!(
        t.dict.writes,
        vec![
            (0x1C12, 0, vec![0]),
            (0x1C12, 1, vec![0x00, 0x16]),
            (0x1C12, 1, vec![0x01, 0x16]),
            (0x1C12, 0, vec![1]),
        ]
    );
    assert_eq!(t.dict.values[&(0x1C12, 0)], vec![1]);
    assert_eq!(t.dict.values[&(0x1C12, 1)], vec![0x01, 0x16]);
    // the final sub 0 refused (e.g. 0604 0042h, too long): every entry back
    let mut t = T::new(64);
    t.dict.values.insert((0x1C12, 0), vec![1]);
    t.dict.values.insert((0x1C12, 1), vec![0x01, 0x16]);
    t.dict.refuse_value = Some((0x1C12, 0, vec![2], SdoAbort::PDO_LENGTH));
    let r = t.sdo(&[0x31, 0x12, 0x1C, 0x00, 6, 0, 0, 0, 2, 0, 0x00, 0x16, 0x05, 0x16]);
    assert_eq!(abort(&r, 0x1C12, 0), 0x0604_0042);
    assert_eq!(t.dict.values[&(0x1C12, 0)], vec![1]);
    assert_eq!(t.dict.values[&(0x1C12, 1)], vec![0x01, 0x16]);
}

#[test]
fn e078_complete_access_off_or_without_metadata_aborts_0601_0000() {
    let mut t = T::new(64);
    t.srv = CoeServer::new(CoeConfig {
        sdo_info: true,
        complete_access: false,
    });
    let r = t.sdo(&[0x50, 0x12, 0x1C, 0x00, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0x1C12, 0), 0x0601_0000);
    let mut t = T::new(64);
    let r = t.sdo(&[0x50, 0x00, 0x70, 0x00, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0x7000, 0), 0x0601_0000);
}

// ---------------------------------------------------------------- SDO Info

/// Checks the SDO Info header of `r`: (opcode incl. incomplete bit, fragments left, data).
fn info_parts(r: &[u8]) -> (u8, u16, &[u8]) {
    assert_eq!(&r[..2], &[0x00, 0x80], "SDO Info header");
    assert_eq!(r[3], 0);
    (r[2], u16::from_le_bytes([r[4], r[5]]), &r[6..])
}

fn u16s(b: &[u8]) -> Vec<u16> {
    b.chunks(2).map(|c| u16::from_le_bytes([c[0], c[1]])).collect()
}

#[test]
fn e079_sdo_info_only_when_configured() {
    let mut t = T::new(64);
    t.srv = CoeServer::new(CoeConfig::from_details(crate::desc::coe_details::SDO));
    assert_eq!(
        t.raw(&[0x00, 0x80, 0x01, 0, 0, 0, 0x01, 0x00]),
        Err(MailboxError::SERVICE_NOT_SUPPORTED)
    );
    assert_eq!(
        CoeConfig::from_details(crate::desc::coe_details::SDO_INFO | crate::desc::coe_details::SDO),
        CoeConfig {
            sdo_info: true,
            complete_access: false
        }
    );
}

#[test]
fn e080_sdo_info_od_list_all_rx_tx() {
    let mut t = T::new(128);
    let r = t.info(opcode::OD_LIST_REQ, &[1, 0]);
    let (op, left, data) = info_parts(&r);
    assert_eq!((op, left), (0x02, 0));
    assert_eq!(
        u16s(data),
        [1, 0x1C12, 0x2000, 0x2001, 0x2002, 0x2003, 0x2004, 0x2005, 0x2006]
    );
    let r = t.info(opcode::OD_LIST_REQ, &[2, 0]);
    assert_eq!(u16s(info_parts(&r).2), [2, 0x2000]);
    let r = t.info(opcode::OD_LIST_REQ, &[3, 0]);
    assert_eq!(u16s(info_parts(&r).2), [3, 0x2002, 0x2004]);
    // lengths: all, rx, tx, backup, settings
    let r = t.info(opcode::OD_LIST_REQ, &[0, 0]);
    assert_eq!(u16s(info_parts(&r).2), [0, 8, 1, 2, 0, 0]);
}

#[test]
fn e081_backup_and_settings_lists_are_empty() {
    let mut t = T::new(128);
    for lt in [4u8, 5] {
        let r = t.info(opcode::OD_LIST_REQ, &[lt, 0]);
        assert_eq!(info_parts(&r), (0x02, 0, &[lt, 0][..]));
    }
    // an unknown list type: SDO Info error
    let r = t.info(opcode::OD_LIST_REQ, &[9, 0]);
    assert_eq!(info_parts(&r), (0x07, 0, &0x0800_0000u32.to_le_bytes()[..]));
}

#[test]
fn e080_sdo_info_fragmentation() {
    // 40 data bytes: 34 bytes (17 words) of list per fragment
    let mut t = T::new(40);
    t.dict.many = true;
    let r = t.info(opcode::OD_LIST_REQ, &[1, 0]);
    // 2 + 2 * 108 = 218 bytes → 7 fragments
    let (op, left, data) = info_parts(&r);
    assert_eq!((op, left, data.len()), (0x82, 6, 34));
    assert_eq!(u16s(data)[0], 1);
    let mut all = u16s(data)[1..].to_vec();
    assert!(t.srv.has_fragments());
    let mut expect_left = 5u16;
    while let Some(r) = t.fragment() {
        let (op, left, data) = info_parts(&r);
        assert_eq!(left, expect_left);
        assert_eq!(op, if left > 0 { 0x82 } else { 0x02 });
        all.extend(u16s(data));
        expect_left = expect_left.wrapping_sub(1);
    }
    assert_eq!(expect_left, u16::MAX, "the last one had 0 left");
    let mut expect: Vec<u16> = OBJECTS.iter().map(|o| o.index).collect();
    expect.extend((0..MANY_N as u16).map(|i| 0x3000 + i));
    assert_eq!(all, expect);
    // a new request ends a list in progress
    t.info(opcode::OD_LIST_REQ, &[1, 0]);
    assert!(t.srv.has_fragments());
    t.sdo(&upload_req(0x2000, 0));
    assert!(!t.srv.has_fragments());
    assert!(t.fragment().is_none());
}

#[test]
fn e082_object_description() {
    let mut t = T::new(128);
    let r = t.info(opcode::OBJECT_DESC_REQ, &[0x02, 0x20]);
    let (op, left, data) = info_parts(&r);
    assert_eq!((op, left), (0x04, 0));
    // index, data type (RECORD), max subindex, object code, name
    assert_eq!(&data[..6], &[0x02, 0x20, 0x2A, 0x00, 3, 9]);
    assert_eq!(&data[6..], b"Record");
    let r = t.info(opcode::OBJECT_DESC_REQ, &[0x12, 0x1C]);
    // array of UINT16 with capacity 4 (sub 0 max)
    assert_eq!(&info_parts(&r).2[..6], &[0x12, 0x1C, 0x06, 0x00, 4, 8]);
    let r = t.info(opcode::OBJECT_DESC_REQ, &[0x01, 0x20]);
    assert_eq!(&info_parts(&r).2[..6], &[0x01, 0x20, 0x0A, 0x00, 0, 7]);
    // unknown object
    let r = t.info(opcode::OBJECT_DESC_REQ, &[0x00, 0x70]);
    assert_eq!(info_parts(&r), (0x07, 0, &0x0602_0000u32.to_le_bytes()[..]));
    // a long name is cut to the mailbox
    let mut t = T::new(16);
    let r = t.info(opcode::OBJECT_DESC_REQ, &[0x12, 0x1C]);
    assert_eq!(r.len(), 16);
    assert_eq!(&r[12..], b"RxPD");
}

#[test]
fn e082_entry_description() {
    let mut t = T::new(128);
    let r = t.info(opcode::ENTRY_DESC_REQ, &[0x02, 0x20, 0x01, 0x00]);
    let (op, left, data) = info_parts(&r);
    assert_eq!((op, left), (0x06, 0));
    // index, sub, value info, data type, bit length, access (RW + TxPDO), name
    assert_eq!(
        &data[..10],
        &[0x02, 0x20, 0x01, 0x00, 0x06, 0x00, 16, 0, 0xBF, 0x00]
    );
    assert_eq!(&data[10..], b"First");
    // default, minimum, maximum on request
    let r = t.info(opcode::ENTRY_DESC_REQ, &[0x02, 0x20, 0x02, 0x77]);
    let data = info_parts(&r).2;
    assert_eq!(
        &data[..10],
        &[0x02, 0x20, 0x02, 0x77, 0x07, 0x00, 32, 0, 0x3F, 0x00]
    );
    assert_eq!(&data[10..22], &[7, 0, 0, 0, 0, 0, 0, 0, 0xE8, 0x03, 0, 0]);
    assert_eq!(&data[22..], b"Second");
    // minimum requested but not limited: not supplied
    let r = t.info(opcode::ENTRY_DESC_REQ, &[0x02, 0x20, 0x01, 0x20]);
    assert_eq!(info_parts(&r).2[3], 0x00);
    // signed minimum of a UINT16 entry is sent in the entry's size
    let r = t.info(opcode::ENTRY_DESC_REQ, &[0x00, 0x20, 0x00, 0x20]);
    let data = info_parts(&r).2;
    assert_eq!(&data[3..12], &[0x20, 0x06, 0x00, 16, 0, 0x7F, 0, 0xFB, 0xFF]);
    // array element through the template; RxPDO/TxPDO bits and write-only access
    let r = t.info(opcode::ENTRY_DESC_REQ, &[0x12, 0x1C, 0x03, 0x00]);
    assert_eq!(&info_parts(&r).2[10..], b"PDO");
    let r = t.info(opcode::ENTRY_DESC_REQ, &[0x03, 0x20, 0x00, 0x00]);
    assert_eq!(&info_parts(&r).2[8..10], &[0x38, 0x00]);
    // errors
    let r = t.info(opcode::ENTRY_DESC_REQ, &[0x02, 0x20, 0x04, 0x00]);
    assert_eq!(info_parts(&r), (0x07, 0, &0x0609_0011u32.to_le_bytes()[..]));
    let r = t.info(opcode::ENTRY_DESC_REQ, &[0x12, 0x1C, 0x05, 0x00]);
    assert_eq!(info_parts(&r).2, &0x0609_0011u32.to_le_bytes()[..]);
    let r = t.info(opcode::ENTRY_DESC_REQ, &[0x00, 0x70, 0x00, 0x00]);
    assert_eq!(info_parts(&r).2, &0x0602_0000u32.to_le_bytes()[..]);
    // unknown opcode
    let r = t.info(0x09, &[0, 0]);
    assert_eq!(info_parts(&r), (0x07, 0, &0x0504_0001u32.to_le_bytes()[..]));
}

#[test]
fn e085_sdo_info_in_preop_safeop_op() {
    for state in [AlState::PreOp, AlState::SafeOp, AlState::Op] {
        let mut t = T::new(128);
        t.state = state;
        let r = t.info(opcode::OD_LIST_REQ, &[1, 0]);
        assert_eq!(info_parts(&r).0, 0x02);
    }
}

// ---------------------------------------------------------------- robustness

/// xorshift64*
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

#[test]
fn random_requests_never_panic_and_replies_are_well_formed() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let commands = [
        0x00, 0x01, 0x0B, 0x10, 0x11, 0x20, 0x21, 0x22, 0x23, 0x2B, 0x2F, 0x31, 0x33, 0x40, 0x50, 0x60, 0x70,
        0x80, 0xA0, 0xC0, 0xE0,
    ];
    let indices = [
        0x1C12u16, 0x2000, 0x2001, 0x2002, 0x2003, 0x2004, 0x2005, 0x2006, 0x3000, 0x6000,
    ];
    let mut t = T::new(64);
    t.dict.many = true;
    for i in 0..5000 {
        if i % 500 == 0 {
            t.cap = [0, 4, 9, 10, 16, 40, 64, 122, 506][rng.below(9) as usize];
            t.state = [AlState::Init, AlState::PreOp, AlState::SafeOp, AlState::Op][rng.below(4) as usize];
        }
        let len = rng.below(48) as usize;
        let mut req: Vec<u8> = (0..len).map(|_| rng.next() as u8).collect();
        // mostly plausible: SDO or SDO Info header, known commands and objects
        if len >= 2 && rng.below(4) != 0 {
            req[0] = 0;
            req[1] = if rng.below(3) == 0 { 0x80 } else { 0x20 };
        }
        if len >= 6 && req[1] == 0x20 && rng.below(4) != 0 {
            req[2] = commands[rng.below(commands.len() as u64) as usize];
            let [a, b] = indices[rng.below(indices.len() as u64) as usize].to_le_bytes();
            req[3] = a;
            req[4] = b;
            req[5] = rng.below(5) as u8;
        }
        if len >= 8 && req[1] == 0x80 {
            req[2] = [1, 3, 5, 0x81, 7][rng.below(5) as usize];
            req[6] = rng.below(7) as u8;
            req[7] = if rng.below(2) == 0 { 0 } else { 0x20 };
        }
        if rng.below(50) == 0 {
            t.now += 2 * SDO_TIMEOUT;
        }
        if let Ok(Some(r)) = t.raw(&req) {
            assert!(r.len() <= t.cap && r.len() >= 2, "{req:x?} -> {r:x?}");
            let h = CoeHeader::parse(&r).unwrap();
            assert_eq!(h.number, 0);
            match h.service {
                service::SDO_REQUEST => {
                    assert_eq!(r.len(), 10);
                    assert_eq!(r[2], 0x80);
                }
                service::SDO_RESPONSE => assert!(r.len() >= 10, "{req:x?} -> {r:x?}"),
                service::SDO_INFO => assert!(r.len() >= 6),
                s => panic!("service {s}"),
            }
        }
        if rng.below(2) == 0 {
            if let Some(f) = t.fragment() {
                assert!(f.len() <= t.cap && f.len() >= 6);
                assert_eq!(f[2] & 0x7F, 0x02);
            }
        }
    }
}
