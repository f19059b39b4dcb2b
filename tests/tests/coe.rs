//! The CoE SDO server and the drive's object dictionary through a real master:
//! every entry read and written over the mailbox (ethercrab moves the frames,
//! `CoeClient` builds them from the spec's byte layouts), the abort codes of
//! spec §6.5 for every kind of bad input, SDO Information (§7), segmented
//! transfers and complete access.

use drive_ecat::objects::{enumeration, Object, Value, OBJECTS};
use drive_ecat::{revision, DriveObjects, Template};
use drive_tests::objects as device_objects;
use drive_tests::{init, line, variant, with_master, with_sdo, CoeClient, UploadKind, MAILBOX_LEN};
use ecat::{CommState, DataType, Dictionary, SdoAbort};
use hil_sim::sim::Simulation;
use std::cell::RefCell;

/// A10[2], the CoE access level of a fresh drive.
const LEVEL: u8 = 2;
/// Largest value a normal upload carries: mailbox data − CoE header − 8.
const NORMAL_MAX: usize = MAILBOX_LEN - 6 - 2 - 8;

const NO_OBJECT: u32 = SdoAbort::NO_OBJECT.0;
const NO_SUBINDEX: u32 = SdoAbort::NO_SUBINDEX.0;
const WRITE_ONLY: u32 = SdoAbort::WRITE_ONLY.0;
const READ_ONLY: u32 = SdoAbort::READ_ONLY.0;
const DEVICE_STATE: u32 = SdoAbort::DEVICE_STATE.0;
const LENGTH_TOO_LOW: u32 = SdoAbort::LENGTH_TOO_LOW.0;
const LENGTH_TOO_HIGH: u32 = SdoAbort::LENGTH_TOO_HIGH.0;
const VALUE_TOO_LOW: u32 = SdoAbort::VALUE_TOO_LOW.0;
const VALUE_TOO_HIGH: u32 = SdoAbort::VALUE_TOO_HIGH.0;
const INVALID_VALUE: u32 = SdoAbort::INVALID_VALUE.0;
const PDO_LENGTH: u32 = SdoAbort::PDO_LENGTH.0;
const TRANSFER: u32 = SdoAbort::TRANSFER.0;
const TOGGLE_BIT: u32 = SdoAbort::TOGGLE_BIT.0;
const UNSUPPORTED_ACCESS: u32 = SdoAbort::UNSUPPORTED_ACCESS.0;
const PARAMETER_INCOMPATIBLE: u32 = SdoAbort::PARAMETER_INCOMPATIBLE.0;

/// Access bits of [`od::Access`] by state: 0 PreOp, 1 SafeOp, 2 Op.
const PREOP: u8 = 0;
const SAFEOP: u8 = 1;

fn visible(o: &Object) -> bool {
    o.level <= LEVEL
}

/// PDO mapping and assignment objects and their A225… mirrors: their entries
/// follow the CiA 301 sequence (sub 0 = 0 first), tested in `pdo.rs` and below.
fn pdo_object(index: u16) -> bool {
    matches!(
        index,
        0x1600..=0x1603 | 0x1A00..=0x1A03 | 0x1C12 | 0x1C13 | 0x20E1..=0x20EC | 0x20FC | 0x20FD
    )
}

/// Mapping objects (and their mirrors), whose sub 0 is checked against the
/// PDO length first (0604 0042h).
fn mapping_object(index: u16) -> bool {
    matches!(index, 0x1600..=0x1603 | 0x1A00..=0x1A03 | 0x20E1..=0x20EC)
}

fn encode(t: DataType, v: i64) -> Vec<u8> {
    v.to_le_bytes()[..t.bytes()].to_vec()
}

fn objects(sim: &RefCell<Simulation>) -> DriveObjects {
    sim.borrow().drives()[0].drive.objects().clone()
}

/// What a bus write may change and the runtime does not: every integer entry
/// of the RAM image outside the live objects, the persistent image (strings
/// included), the template and the pending requests.
fn settled(sim: &RefCell<Simulation>) -> (Vec<i64>, Vec<u8>, Template, drive_ecat::Requests) {
    let o = objects(sim);
    let values = device_objects()
        .filter(|obj| obj.value == Value::Ram)
        .flat_map(|obj| obj.info.entries.iter().map(move |e| (obj.info.index, e)))
        .filter(|(_, e)| e.data_type.is_integer())
        .map(|(i, e)| o.get(i, e.sub).unwrap())
        .collect();
    let mut image = vec![0u8; drive_ecat::PERSISTENT_IMAGE_BYTES];
    o.persistent_image(&mut image).unwrap();
    (values, image, o.template(), o.requests())
}

/// The value the drive's dictionary holds for `index`:`sub`, read locally.
fn local_read(sim: &RefCell<Simulation>, index: u16, sub: u8) -> Vec<u8> {
    // the longest entry: A280's 255 bytes
    let mut buf = [0u8; 512];
    let n = sim.borrow_mut().drives_mut()[0]
        .drive
        .read_object(index, sub, &mut buf, CommState::PreOp)
        .unwrap();
    buf[..n].to_vec()
}

#[test]
fn e063_e064_e071_e072_e016_every_entry_reads_with_its_declared_size() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        let mut c = CoeClient::new();
        let (mut read, mut hidden, mut write_only) = (0, 0, 0);
        let device = variant();
        for o in OBJECTS.iter() {
            let index = o.info.index;
            let o = device.declared(o);
            for e in o.info.entries {
                let at = format!("{index:04X}h:{:02X}h {}", e.sub, e.name);
                let got = c.upload_kind(&sd, index, e.sub, false).await;
                if !device.has_object(index) {
                    assert_eq!(got, Err(NO_OBJECT), "not on the single-axis device: {at}");
                    hidden += 1;
                    continue;
                }
                if !visible(o) {
                    assert_eq!(got, Err(NO_OBJECT), "E-016 hidden {at}");
                    hidden += 1;
                    continue;
                }
                if !e.access.readable() {
                    assert_eq!(got, Err(WRITE_ONLY), "E-071 write-only {at}");
                    write_only += 1;
                    continue;
                }
                if o.value == Value::Provided && index == drive_ecat::params::T11 && e.sub > 0 {
                    // no trace recorded: the scope's data blocks are 0800 0022h until one is complete
                    assert_eq!(got, Err(DEVICE_STATE), "trace data without a trace: {at}");
                    read += 1;
                    continue;
                }
                let (data, kind) = got.unwrap_or_else(|a| panic!("{at}: abort {a:08X}h"));
                let declared = e.data_type.bytes();
                match e.data_type {
                    DataType::VisibleString(_) => assert!(data.len() <= declared, "{at}"),
                    // an empty diagnosis-message slot reads as 0 bytes (ETG.1020)
                    DataType::OctetString(_) if o.value == Value::Live => {
                        assert!(data.len() <= declared, "{at}")
                    }
                    _ => assert_eq!(data.len(), declared, "declared size of {at}"),
                }
                let expected_kind = match data.len() {
                    1..=4 => UploadKind::Expedited,
                    n if n <= NORMAL_MAX => UploadKind::Normal,
                    _ => UploadKind::Segmented,
                };
                assert_eq!(kind, expected_kind, "transfer type of {at}");
                // the value: the declaration's for constants and fresh RAM values
                match o.value {
                    Value::Const | Value::Ram | Value::Command if e.data_type.is_integer() => {
                        assert_eq!(e.data_type.decode(&data), Ok(e.default), "default of {at}")
                    }
                    Value::Identity if e.sub == 3 => {
                        assert_eq!(data, revision(Template::SdoInfo).to_le_bytes(), "E-008 revision")
                    }
                    Value::Identity => assert_eq!(e.data_type.decode(&data), Ok(e.default), "{at}"),
                    Value::Text(s) => assert_eq!(data, s.as_bytes(), "{at}"),
                    // the scope's (group T) values are its recorder's, which a
                    // local read without the recorder does not reach: tests/scope.rs
                    Value::Provided => {}
                    _ => assert_eq!(data, local_read(&sim, index, e.sub), "{at}"),
                }
                read += 1;
            }
        }
        assert!(read > 500, "{read} entries read");
        assert!(
            hidden > 0 && write_only > 0,
            "{hidden} hidden, {write_only} write-only"
        );
        // E-072: unknown object and subindex
        assert_eq!(c.upload(&sd, 0x5000, 0).await, Err(NO_OBJECT));
        assert_eq!(c.upload(&sd, 0x1018, 5).await, Err(NO_SUBINDEX));
        assert_eq!(c.upload(&sd, 0x6040, 1).await, Err(NO_SUBINDEX));
    });
}

/// Values to write to a writable integer entry: the ends of its range (or of
/// its enumeration), then its default (so the drive ends as it started).
/// (`od::EntryInfo` cannot be named here: the tests reach it through `drive`.)
fn write_values(index: u16, sub: u8, name: &str, (lowest, highest, default): (i64, i64, i64)) -> Vec<i64> {
    let mut v = match enumeration(index, sub) {
        Some(list) => vec![list[0], list[list.len() - 1]],
        // an action's "Start" = 1 starts it (save, restart): only its default
        None if name == "Start" => vec![],
        None => vec![lowest, highest],
    };
    v.push(default);
    v
}

#[test]
fn e063_e064_e076_writable_entries_take_range_ends_and_default_preop_only_refused_later() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        let mut c = CoeClient::new();
        let mut written = 0;
        let start = settled(&sim);
        for o in device_objects().filter(|o| visible(o)) {
            let index = o.info.index;
            // live objects (10F3h) and the scope's (group T, provided by its recorder) check
            // writes against their own state: tested on their own;
            // so are the DC-link window's A35/A38, each checked against the other and A40
            // where written (drive_core::stage: tests_stage.rs, PKW, SOEM's chopper.py)
            let window = [drive_ecat::params::A35, drive_ecat::params::A38].contains(&index);
            if pdo_object(index)
                || o.value == Value::Command
                || matches!(o.value, Value::Live | Value::Provided)
                || window
            {
                continue;
            }
            for e in o.info.entries {
                if !e.access.writable_in(PREOP) || !e.data_type.is_integer() {
                    continue;
                }
                let at = format!("{index:04X}h:{:02X}h {}", e.sub, e.name);
                for v in write_values(index, e.sub, e.name, (e.lowest(), e.highest(), e.default)) {
                    let bytes = encode(e.data_type, v);
                    let r = c.download(&sd, index, e.sub, &bytes).await;
                    assert_eq!(r, Ok(()), "write {v} to {at}");
                    if e.access.readable() {
                        assert_eq!(c.upload(&sd, index, e.sub).await, Ok(bytes), "read back {at}");
                    } else {
                        assert_eq!(objects(&sim).get(index, e.sub), Ok(v), "write-only {at}");
                    }
                    written += 1;
                }
            }
        }
        assert!(written > 200, "{written} writes");
        assert_eq!(settled(&sim), start, "every default written back last");

        // Safe-Op, then Op: entries writable in every state take their default,
        // Pre-Op-only entries answer 0800 0022h and keep their value
        c.hand_over(&sd).await;
        let group = group.into_safe_op(md).await.expect("PRE-OP -> SAFE-OP");
        let sd = group.subdevice(md, 0).unwrap();
        let (accepted, refused) = state_writes(&sim, &sd, &mut c, SAFEOP).await;
        assert!(
            accepted > 50 && refused > 50,
            "{accepted} accepted, {refused} refused"
        );
        let group = group.into_op(md).await.expect("SAFE-OP -> OP");
        let sd = group.subdevice(md, 0).unwrap();
        let (accepted_op, refused_op) = state_writes(&sim, &sd, &mut c, 2).await;
        assert_eq!(
            (accepted_op, refused_op),
            (accepted, refused),
            "Op = Safe-Op rights"
        );
    });
}

/// Writes the present value of every visible integer entry writable in some
/// state, in ESM state `bit`: accepted where the access bits allow it, else
/// 0800 0022h with nothing changed. Returns (accepted, refused).
async fn state_writes<S>(
    sim: &RefCell<Simulation>,
    sd: &ethercrab::SubDeviceRef<'_, S>,
    c: &mut CoeClient,
    bit: u8,
) -> (usize, usize) {
    let (mut accepted, mut refused) = (0, 0);
    for o in device_objects().filter(|o| visible(o)) {
        let index = o.info.index;
        if index == 0x1010 {
            continue; // a command: any value but "save" is 0800 0020h
        }
        for e in o.info.entries {
            if !e.access.writable() || !e.data_type.is_integer() {
                continue;
            }
            let at = format!("{index:04X}h:{:02X}h in state bit {bit}", e.sub);
            let bytes = if o.value == Value::Provided {
                // the recorder's value (the RAM image has none)
                c.upload(sd, index, e.sub).await.unwrap()
            } else {
                encode(e.data_type, objects(sim).get(index, e.sub).unwrap())
            };
            let before = settled(sim);
            let r = c.download(sd, index, e.sub, &bytes).await;
            if e.access.writable_in(bit) {
                assert_eq!(r, Ok(()), "{at}");
                accepted += 1;
            } else {
                assert_eq!(r, Err(DEVICE_STATE), "{at}");
                assert_eq!(settled(sim), before, "refused write changed nothing: {at}");
                refused += 1;
            }
        }
    }
    (accepted, refused)
}

/// A value in `lowest..=highest` outside the enumeration `list`.
fn not_in(list: &[i64], lowest: i64, highest: i64) -> Option<i64> {
    let start = list.iter().copied().min()?.max(lowest);
    (start..=highest).find(|v| !list.contains(v))
}

#[test]
fn e071_e073_e074_e016_bad_writes_get_the_exact_abort_and_change_nothing() {
    let sim = line(1);
    with_sdo(&sim, async |sd, c| {
        let mut cases = 0usize;
        let start = settled(&sim);
        let device = variant();
        for o in OBJECTS.iter() {
            let index = o.info.index;
            let o = device.declared(o);
            // an object the single-axis device does not have is refused as a hidden one
            let visible = |o: &Object| visible(o) && device.has_object(index);
            for e in o.info.entries {
                let n = e.data_type.bytes();
                // the recorder's answer (a local read has no recorder); T11's
                // blocks have none without a trace (0800 0022h): zeros of its size
                let provided = if visible(o) && o.value == Value::Provided {
                    Some(c.upload(sd, index, e.sub).await)
                } else {
                    None
                };
                let current = if let Some(answer) = &provided {
                    answer.clone().unwrap_or_else(|_| vec![0; n])
                } else if visible(o) {
                    local_value(&sim, index, e.sub, e.access.readable())
                } else {
                    vec![0; n]
                };
                let mut bad: Vec<(Vec<u8>, u32, &str)> = Vec::new();
                if !visible(o) {
                    bad.push((current.clone(), NO_OBJECT, "E-016 hidden"));
                } else if !e.access.writable() {
                    bad.push((current.clone(), READ_ONLY, "read-only"));
                    if n > 1 {
                        // the access right is checked before the size
                        bad.push((vec![0; n - 1], READ_ONLY, "read-only, short"));
                    }
                } else if e.data_type.is_string() {
                    if let DataType::VisibleString(len) = e.data_type {
                        let long = vec![b'x'; usize::from(len) + 1];
                        bad.push((long, LENGTH_TOO_HIGH, "string too long"));
                    }
                } else if e.access.writable_in(PREOP) {
                    bad.push((vec![0x5A; n - 1], LENGTH_TOO_LOW, "one byte short"));
                    bad.push((vec![0x5A; n + 1], LENGTH_TOO_HIGH, "one byte long"));
                    let t = e.data_type;
                    if let Some(min) = e.min.filter(|&m| m > t.min_value()) {
                        bad.push((encode(t, min - 1), VALUE_TOO_LOW, "min - 1"));
                    }
                    if let Some(max) = e.max.filter(|&m| m < t.max_value()) {
                        // a mapping's count is checked as a PDO length first (§5.3)
                        let code = if mapping_object(index) && e.sub == 0 {
                            PDO_LENGTH
                        } else {
                            VALUE_TOO_HIGH
                        };
                        bad.push((encode(t, max + 1), code, "max + 1"));
                    }
                    if let Some(v) =
                        enumeration(index, e.sub).and_then(|list| not_in(list, e.lowest(), e.highest()))
                    {
                        bad.push((encode(t, v), INVALID_VALUE, "not in the enumeration"));
                    }
                    if o.value == Value::Command {
                        bad.push((encode(t, 0), TRANSFER, "command without signature"));
                    }
                    // CiA 301: mapping/assignment entries change only while sub 0 = 0
                    if pdo_object(index) && e.sub > 0 && objects(&sim).get(index, 0) != Ok(0) {
                        bad.push((current.clone(), DEVICE_STATE, "entry while sub 0 != 0"));
                    }
                }
                for (data, code, what) in bad {
                    let before = settled(&sim);
                    let r = if data.len() > 64 {
                        // longer than one mailbox frame holds: in segments
                        c.download_segmented(sd, index, e.sub, &data, false)
                            .await
                            .map(|_| ())
                    } else if data.is_empty() || data.len() > 4 {
                        c.download_normal(sd, index, e.sub, &data, false).await
                    } else {
                        c.download_expedited(sd, index, e.sub, &data).await
                    };
                    let at = format!("{index:04X}h:{:02X}h {} ({what}, {data:02x?})", e.sub, e.name);
                    assert_eq!(r, Err(code), "{at}");
                    assert_eq!(settled(&sim), before, "refused write changed nothing: {at}");
                    if visible(o) && e.access.readable() {
                        let before = provided.clone().unwrap_or_else(|| Ok(current.clone()));
                        assert_eq!(c.upload(sd, index, e.sub).await, before, "{at}");
                    }
                    cases += 1;
                }
            }
        }
        assert!(cases > 1000, "{cases} refused writes");
        // unknown object and subindex (E-072)
        assert_eq!(c.download(sd, 0x5000, 0, &[1]).await, Err(NO_OBJECT));
        assert_eq!(c.download(sd, 0x6040, 1, &[1, 0]).await, Err(NO_SUBINDEX));
        assert_eq!(settled(&sim), start, "nothing changed");
    });
}

/// The present value of `index`:`sub` from the drive's dictionary (integers
/// of write-only entries through `get`).
fn local_value(sim: &RefCell<Simulation>, index: u16, sub: u8, readable: bool) -> Vec<u8> {
    if readable {
        local_read(sim, index, sub)
    } else {
        let o = objects(sim);
        let t = drive_ecat::objects::find(index)
            .unwrap()
            .1
            .info
            .entry(sub)
            .unwrap()
            .data_type;
        encode(t, o.get(index, sub).unwrap())
    }
}

/// The object's data type as SDO Info reports it (ETG.1000.6): the entry type
/// of a VAR, the element type of an ARRAY, the standard structure of a RECORD.
fn object_type(o: &Object) -> u16 {
    match o.info.code.code() {
        7 => o.info.entries.get(0).unwrap().data_type.code(),
        8 => o
            .info
            .entries
            .iter()
            .find(|e| e.sub >= 1)
            .unwrap()
            .data_type
            .code(),
        _ => match o.info.index {
            0x1018 => 0x0023,
            0x1600..=0x17FF | 0x1A00..=0x1BFF => 0x0021,
            0x1C32 | 0x1C33 => 0x0029,
            _ => 0x002A,
        },
    }
}

/// The bytes of each default/min/max value in an entry description.
fn value_size(t: DataType) -> usize {
    match t {
        DataType::Bool | DataType::F32 => 0,
        t if t.is_string() => 0,
        t => t.bytes(),
    }
}

#[test]
fn e080_e081_e082_e084_sdo_info_lists_and_descriptions_match_the_dictionary() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        let mut c = CoeClient::new();
        let shown: Vec<&Object> = device_objects().filter(|o| visible(o)).collect();
        let all: Vec<u16> = shown.iter().map(|o| o.info.index).collect();
        let mappable = |rx: bool| -> Vec<u16> {
            shown
                .iter()
                .filter(|o| {
                    o.info.entries.iter().any(|e| {
                        if rx {
                            e.access.rx_mappable()
                        } else {
                            e.access.tx_mappable()
                        }
                    })
                })
                .map(|o| o.info.index)
                .collect()
        };
        assert!(
            all.len() < device_objects().count(),
            "some objects are hidden at level {LEVEL}"
        );
        // E-080: all, RxPDO- and TxPDO-mappable (fragmented: the lists are long)
        assert_eq!(c.od_list(&sd, 1).await, all, "OD list: all visible objects");
        let rx = c.od_list(&sd, 2).await;
        assert_eq!(rx, mappable(true), "RxPDO-mappable objects");
        assert!(rx.contains(&0x6040) && !rx.contains(&0x6041) && !rx.contains(&0x1000));
        let tx = c.od_list(&sd, 3).await;
        assert_eq!(tx, mappable(false), "TxPDO-mappable objects");
        assert!(tx.contains(&0x6041) && tx.contains(&0x10F3) && !tx.contains(&0x1000));
        // E-081: backup and settings lists are empty
        assert_eq!(c.od_list(&sd, 4).await, Vec::<u16>::new());
        assert_eq!(c.od_list(&sd, 5).await, Vec::<u16>::new());
        // list type 0: the five lengths
        let (op, d) = c.info(&sd, 1, &0u16.to_le_bytes()).await;
        assert_eq!(op, 2);
        let lengths: Vec<u16> = d.chunks(2).map(|b| u16::from_le_bytes([b[0], b[1]])).collect();
        assert_eq!(
            lengths,
            [0, all.len() as u16, rx.len() as u16, tx.len() as u16, 0, 0]
        );

        // E-082: every visible object's description and every entry's
        for o in &shown {
            let index = o.info.index;
            let d = c.object_desc(&sd, index).await.unwrap();
            assert_eq!(d.name, o.info.name, "{index:04X}h name");
            assert_eq!(d.code, o.info.code.code(), "{index:04X}h object code");
            assert_eq!(d.data_type, object_type(o), "{index:04X}h data type");
            assert_eq!(d.max_sub, o.info.max_sub(), "{index:04X}h max subindex");
            for e in o.info.entries {
                let at = format!("{index:04X}h:{:02X}h", e.sub);
                let d = c
                    .entry_desc(&sd, index, e.sub, 0x77, value_size(e.data_type))
                    .await
                    .unwrap();
                assert_eq!(d.name, e.name, "{at} name");
                assert_eq!(d.data_type, e.data_type.code(), "{at} data type");
                assert_eq!(d.bit_len, e.data_type.bits(), "{at} bit length");
                assert_eq!(d.access, e.access.0, "{at} access, mapping, backup bits");
                let mut expected = Vec::new();
                if value_size(e.data_type) > 0 {
                    let n = value_size(e.data_type);
                    expected.push(e.default.to_le_bytes()[..n].to_vec());
                    for v in [e.min, e.max].into_iter().flatten() {
                        expected.push(v.to_le_bytes()[..n].to_vec());
                    }
                }
                assert_eq!(d.values, expected, "{at} default, min, max");
                assert_eq!(d.value_info & 0x07, 0x07, "{at} value info");
            }
        }

        // a sample, spelled out
        let d = c.object_desc(&sd, 0x1018).await.unwrap();
        assert_eq!((d.data_type, d.max_sub, d.code), (0x0023, 4, 9));
        assert_eq!(d.name, "Identity object");
        let d = c.object_desc(&sd, 0x1600).await.unwrap();
        assert_eq!((d.data_type, d.max_sub, d.code), (0x0021, 24, 9));
        let d = c.entry_desc(&sd, 0x1600, 1, 0x17, 4).await.unwrap();
        assert_eq!((d.data_type, d.bit_len, d.access), (0x0007, 32, 0x000F));
        assert_eq!(
            d.values,
            [0x6040_0010u32.to_le_bytes().to_vec()],
            "default mapping"
        );
        let d = c.object_desc(&sd, 0x6040).await.unwrap();
        assert_eq!(
            (d.data_type, d.max_sub, d.code, d.name.as_str()),
            (6, 0, 7, "Controlword")
        );
        let d = c.entry_desc(&sd, 0x6040, 0, 0x07, 2).await.unwrap();
        assert_eq!(
            (d.data_type, d.bit_len, d.access),
            (6, 16, 0x00FF),
            "rw, Rx and Tx"
        );
        let d = c.entry_desc(&sd, 0x6041, 0, 0x07, 2).await.unwrap();
        assert_eq!((d.data_type, d.bit_len, d.access), (6, 16, 0x0087), "ro, Tx");
        // A10 access level: an array, element e at subindex e + 1 (E-013)
        let a10 = drive_ecat::parameter_index(0, 10);
        let d = c.object_desc(&sd, a10).await.unwrap();
        assert_eq!(
            (d.data_type, d.max_sub, d.code, d.name.as_str()),
            (5, 4, 8, "Access level")
        );
        let d = c.entry_desc(&sd, a10, 3, 0x77, 1).await.unwrap();
        assert_eq!(d.name, "CANopen and EtherCAT");
        assert_eq!(d.values, [vec![2], vec![0], vec![3]], "default 2, range 0..3");
        assert_eq!(d.access, 0x003F, "rw in every state, not mappable");

        // errors: unknown and hidden objects, unknown subindex
        assert_eq!(c.object_desc(&sd, 0x5000).await, Err(NO_OBJECT));
        let hidden = device_objects().find(|o| !visible(o)).unwrap().info.index;
        assert_eq!(c.object_desc(&sd, hidden).await, Err(NO_OBJECT), "E-084");
        assert_eq!(c.entry_desc(&sd, 0x1018, 9, 0, 0).await, Err(NO_SUBINDEX));

        // E-085: SDO Info in Safe-Op and Op too. The number of requests above
        // grows with the dictionary, so this client's last counter is any of
        // 1..7: hand the mailbox over, or ethercrab's next request is dropped
        // as a repeat whenever its counter happens to be the same.
        c.hand_over(&sd).await;
        let group = group.into_op(md).await.expect("PRE-OP -> OP");
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(c.od_list(&sd, 3).await, tx);
        assert_eq!(c.object_desc(&sd, 0x6041).await.unwrap().name, "Statusword");
    });
}

/// E-083: A268 selects what the OD lists show: [0] index area (0 the
/// standard area, 1 the manufacturer area 2000h…5FFFh and axis B's
/// A000h…DFFFh, 2 all), [1] a bit per manufacturer group A…Z. Objects left
/// out keep their descriptions; a value beyond the range is refused and
/// changes nothing.
#[test]
fn e083_a268_selects_the_listed_objects() {
    let sim = line(1);
    let a268 = drive_ecat::parameter_index(0, 268);
    with_sdo(&sim, async |sd, c| {
        let manufacturer = |i: &u16| matches!(i & 0x7FFF, 0x2000..=0x5FFF);
        let all = c.od_list(sd, 1).await;
        assert!(all.iter().any(manufacturer) && all.iter().any(|i| !manufacturer(i)));
        // standard area only
        c.download(sd, a268, 1, &[0]).await.unwrap();
        let standard = c.od_list(sd, 1).await;
        assert_eq!(
            standard,
            all.iter()
                .copied()
                .filter(|i| !manufacturer(i))
                .collect::<Vec<_>>()
        );
        let tx = c.od_list(sd, 3).await;
        assert!(
            tx.contains(&0x6041) && !tx.iter().any(manufacturer),
            "TxPDO list too"
        );
        let (_, d) = c.info(sd, 1, &0u16.to_le_bytes()).await;
        assert_eq!(
            u16::from_le_bytes([d[2], d[3]]) as usize,
            standard.len(),
            "list lengths follow"
        );
        assert_eq!(
            c.object_desc(sd, a268).await.unwrap().name,
            "SDO Info object selection",
            "a left-out object keeps its description"
        );
        // manufacturer area, groups A (bit 0) and I (bit 8) only
        c.download(sd, a268, 1, &[1]).await.unwrap();
        c.download(sd, a268, 2, &0x0101u32.to_le_bytes()).await.unwrap();
        let chosen = c.od_list(sd, 1).await;
        let in_a_or_i = |i: &u16| manufacturer(i) && matches!(((i & 0x7FFF) - 0x2000) >> 9, 0 | 8);
        assert_eq!(chosen, all.iter().copied().filter(in_a_or_i).collect::<Vec<_>>());
        assert!(chosen.contains(&a268) && chosen.contains(&drive_ecat::parameter_index(8, 22)));
        // all, groups as chosen: the standard area again beside A and I
        c.download(sd, a268, 1, &[2]).await.unwrap();
        let mixed = c.od_list(sd, 1).await;
        let want: Vec<u16> = all
            .iter()
            .copied()
            .filter(|i| !manufacturer(i) || in_a_or_i(i))
            .collect();
        assert_eq!(mixed, want);
        // out of range: refused, the selection unchanged
        assert_eq!(
            c.download(sd, a268, 1, &[3]).await,
            Err(0x0609_0031),
            "value too high"
        );
        assert_eq!(c.od_list(sd, 1).await, want);
        c.download(sd, a268, 2, &0x03FF_FFFFu32.to_le_bytes())
            .await
            .unwrap();
        assert_eq!(c.od_list(sd, 1).await, all, "the defaults list everything");
    });
}

#[test]
fn e012_e013_e079_manufacturer_array_in_both_templates() {
    let sim = line(1);
    let a10 = drive_ecat::parameter_index(0, 10);
    with_sdo(&sim, async |sd, c| {
        // "EtherCAT Rx SDO Info": A10[2] at subindex 3, sub 0 = element count
        assert_eq!(c.upload(sd, a10, 0).await, Ok(vec![4]));
        c.download(sd, a10, 2, &[1]).await.unwrap(); // A10[1] (DS6)
        assert_eq!(c.upload(sd, a10, 2).await, Ok(vec![1]));
        assert_eq!(c.upload(sd, a10, 3).await, Ok(vec![2]));
        assert_eq!(c.upload(sd, a10, 4).await, Ok(vec![2]));
        assert_eq!(
            c.upload(sd, 0x1018, 3).await,
            Ok(revision(Template::SdoInfo).to_le_bytes().to_vec())
        );
        assert_eq!(c.entry_desc(sd, a10, 2, 0, 1).await.unwrap().name, "DS6");

        // "EtherCAT Rx": element = subindex, no SDO Info, revision bit 0 clear
        sim.borrow_mut().drives_mut()[0]
            .drive
            .objects_mut()
            .set_template(Template::Rx);
        assert_eq!(c.upload(sd, a10, 1).await, Ok(vec![1]), "A10[1] at subindex 1");
        assert_eq!(c.upload(sd, a10, 2).await, Ok(vec![2]), "A10[2] at subindex 2");
        assert_eq!(c.upload(sd, a10, 0).await, Ok(vec![2]), "sub 0 = element 0");
        assert_eq!(c.upload(sd, a10, 4).await, Err(NO_SUBINDEX));
        c.download(sd, a10, 1, &[2]).await.unwrap();
        assert_eq!(objects(&sim).get(a10, 2), Ok(2), "same value, SDO-Info numbering");
        assert_eq!(
            c.upload(sd, 0x1018, 3).await,
            Ok(revision(Template::Rx).to_le_bytes().to_vec())
        );
        // simple parameters and CiA 402 objects keep subindex 0 (E-011)
        assert_eq!(c.upload(sd, 0x6060, 0).await, Ok(vec![8]));
        let reply = c.try_request(sd, &[0x00, 0x80, 3, 0, 0, 0, 0x18, 0x10]).await;
        let (kind, data) = reply.expect_err("E-079: no SDO Info in the Rx template");
        assert_eq!(kind, 0, "mailbox error reply");
        assert_eq!(
            u16::from_le_bytes([data[2], data[3]]),
            ecat::mailbox::MailboxError::SERVICE_NOT_SUPPORTED.0
        );
    });
}

/// E72 "User configuration identification": a writable VISIBLE_STRING(16).
const E72: u16 = drive_ecat::parameter_index(4, 72);

#[test]
fn e065_e067_e068_segmented_download_byte_for_byte_and_toggle_error() {
    let sim = line(1);
    let [i0, i1] = E72.to_le_bytes();
    with_sdo(&sim, async |sd, c| {
        // the manual's example: 16 bytes 01h…10h in three 7-byte segments
        let data: Vec<u8> = (1..=16).collect();
        let replies = c.download_segmented(sd, E72, 0, &data, false).await.unwrap();
        assert_eq!(
            replies,
            [
                vec![0x60, i0, i1, 0, 0, 0, 0, 0],
                vec![0x20, 0, 0, 0, 0, 0, 0, 0],
                vec![0x30, 0, 0, 0, 0, 0, 0, 0],
                vec![0x20, 0, 0, 0, 0, 0, 0, 0],
            ],
            "S §9.3.2.3 download example"
        );
        // read back: the whole value fits the mailbox, so a normal upload
        let r = c.sdo(sd, &[0x40, i0, i1, 0, 0, 0, 0, 0]).await.unwrap();
        let mut expected = vec![0x41, i0, i1, 0, 16, 0, 0, 0];
        expected.extend_from_slice(&data);
        assert_eq!(r, expected, "normal upload response, size 16");

        // a shorter string through segments: read back without padding
        c.download_segmented(sd, E72, 0, b"axis cfg 7", false)
            .await
            .unwrap();
        assert_eq!(c.upload(sd, E72, 0).await, Ok(b"axis cfg 7".to_vec()));
        // too long for STRING(16), in segments: 0607 0012h, value kept
        let long = [b'y'; 17];
        assert_eq!(
            c.download_segmented(sd, E72, 0, &long, false).await,
            Err(LENGTH_TOO_HIGH)
        );
        assert_eq!(c.upload(sd, E72, 0).await, Ok(b"axis cfg 7".to_vec()));

        // E-068: the second segment repeats toggle 0
        let r = c.sdo(sd, &[0x21, i0, i1, 0, 16, 0, 0, 0]).await.unwrap();
        assert_eq!(r[0], 0x60);
        let r = c
            .sdo(sd, &[0x00, b'a', b'b', b'c', b'd', b'e', b'f', b'g'])
            .await
            .unwrap();
        assert_eq!(r[0], 0x20);
        let r = c.sdo(sd, &[0x00, b'h', b'i', b'j', b'k', b'l', b'm', b'n']).await;
        assert_eq!(r, Err(TOGGLE_BIT));
        assert_eq!(
            c.upload(sd, E72, 0).await,
            Ok(b"axis cfg 7".to_vec()),
            "nothing written"
        );
        // the transfer ended with the abort: a further segment is unknown (0504 0001h)
        let r = c.sdo(sd, &[0x10, b'o', b'p', 0, 0, 0, 0, 0]).await;
        assert_eq!(r, Err(SdoAbort::INVALID_COMMAND.0));

        // a segment longer than 7 bytes (ETG.1000.6): as long as the mailbox data says
        let r = c.sdo(sd, &[0x21, i0, i1, 0, 12, 0, 0, 0]).await.unwrap();
        assert_eq!(r[0], 0x60);
        let mut seg = vec![0x01];
        seg.extend_from_slice(b"twelve bytes");
        let r = c.sdo(sd, &seg).await.unwrap();
        assert_eq!(r[0], 0x20, "last segment acknowledged");
        assert_eq!(c.upload(sd, E72, 0).await, Ok(b"twelve bytes".to_vec()));
        c.download_segmented(sd, E72, 0, b"axis cfg 7", false)
            .await
            .unwrap();

        // E-069: a segmented download left idle for more than 1 s times out
        let r = c.sdo(sd, &[0x21, i0, i1, 0, 16, 0, 0, 0]).await.unwrap();
        assert_eq!(r[0], 0x60);
        {
            let mut s = sim.borrow_mut();
            let t = s.now().as_ns() + ecat::coe::SDO_TIMEOUT.as_ns() + 1_000_000;
            s.advance_to(nanos::Nanos::from_ns(t));
        }
        let r = c.sdo(sd, &[0x00, b'a', b'b', b'c', b'd', b'e', b'f', b'g']).await;
        assert_eq!(r, Err(SdoAbort::TIMEOUT.0));
        assert_eq!(c.upload(sd, E72, 0).await, Ok(b"axis cfg 7".to_vec()));
    });
}

#[test]
fn e066_e068_e078_segmented_complete_upload_of_10f3h_and_toggle_error() {
    let sim = line(1);
    with_sdo(&sim, async |sd, c| {
        // 10F3h from sub 0: 2 + 6 + 20 × 28 bytes, more than one mailbox
        let (data, kind) = c.upload_kind(sd, 0x10F3, 0, true).await.unwrap();
        assert_eq!(kind, UploadKind::Segmented);
        let mut expected = vec![25, 0];
        for sub in 1..=25u8 {
            let mut v = local_read(&sim, 0x10F3, sub);
            let e = drive_ecat::objects::find(0x10F3)
                .unwrap()
                .1
                .info
                .entry(sub)
                .unwrap();
            v.resize(e.data_type.bytes(), 0);
            expected.extend_from_slice(&v);
        }
        assert_eq!(data.len(), 568);
        assert_eq!(
            data, expected,
            "complete access layout: sub 0 as 16 bits, then each entry"
        );

        // E-068: an upload segment with the wrong toggle bit
        let r = c.sdo(sd, &[0x50, 0xF3, 0x10, 0, 0, 0, 0, 0]).await.unwrap();
        assert_eq!(r[..8], [0x41, 0xF3, 0x10, 0, 0x38, 0x02, 0, 0], "size only, 568");
        let r = c.sdo(sd, &[0x60, 0, 0, 0, 0, 0, 0, 0]).await.unwrap();
        assert_eq!(r[0] & 0xF0, 0x00, "first segment, toggle 0");
        let r = c.sdo(sd, &[0x60, 0, 0, 0, 0, 0, 0, 0]).await;
        assert_eq!(r, Err(TOGGLE_BIT));
        // the abort ended it: a new upload starts cleanly
        assert_eq!(c.upload_kind(sd, 0x10F3, 0, true).await.unwrap().0, expected);
    });
}

#[test]
fn e078_complete_access_upload_1018h_1600h_and_download_1c12h_in_cia301_order() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        let mut c = CoeClient::new();
        // 1018h from sub 0 and from sub 1
        let mut identity = vec![4, 0];
        for v in [
            drive_ecat::VENDOR_ID,
            variant().product_code(),
            revision(Template::SdoInfo),
            drive_ecat::SERIAL,
        ] {
            identity.extend_from_slice(&v.to_le_bytes());
        }
        assert_eq!(
            c.upload_kind(&sd, 0x1018, 0, true).await,
            Ok((identity.clone(), UploadKind::Normal))
        );
        assert_eq!(
            c.upload_kind(&sd, 0x1018, 1, true).await.unwrap().0,
            identity[2..]
        );
        // 1600h: the 8 entries of the default RxPDO
        let rx_default: Vec<u32> = vec![
            0x6040_0010,
            0x6060_0008,
            0x607A_0020,
            0x60FF_0020,
            0x60B1_0020,
            0x60B2_0010,
            0x6071_0010,
            0x60FE_0120,
        ];
        let mut map = vec![8, 0];
        rx_default
            .iter()
            .for_each(|m| map.extend_from_slice(&m.to_le_bytes()));
        assert_eq!(c.upload_kind(&sd, 0x1600, 0, true).await.unwrap().0, map);
        // complete access needs an ARRAY or RECORD from sub 0 or 1
        assert_eq!(c.upload_kind(&sd, 0x6040, 0, true).await, Err(UNSUPPORTED_ACCESS));
        assert_eq!(c.upload_kind(&sd, 0x1018, 2, true).await, Err(UNSUPPORTED_ACCESS));

        // 1C12h: two RxPDOs (the entries are written while sub 0 = 0, CiA 301)
        let assign = [2, 0, 0x00, 0x16, 0x02, 0x16];
        c.download_normal(&sd, 0x1C12, 0, &assign, true).await.unwrap();
        assert_eq!(c.upload_kind(&sd, 0x1C12, 0, true).await.unwrap().0, assign);
        assert_eq!(c.upload(&sd, 0x1C12, 2).await, Ok(vec![0x02, 0x16]));
        // refused before anything is written: count above 4, data too short
        let before = settled(&sim);
        let five = [5, 0, 0, 0x16, 1, 0x16, 2, 0x16, 3, 0x16, 0, 0x16];
        assert_eq!(
            c.download_normal(&sd, 0x1C12, 0, &five, true).await,
            Err(VALUE_TOO_HIGH)
        );
        assert_eq!(
            c.download_normal(&sd, 0x1C12, 0, &[2, 0, 0, 0x16], true).await,
            Err(LENGTH_TOO_LOW)
        );
        assert_eq!(settled(&sim), before, "nothing written");
        // a TxPDO in the RxPDO assignment: refused by the entry write, after
        // sub 0 = 0; the old assignment comes back, nothing changed
        assert_eq!(
            c.download_normal(&sd, 0x1C12, 0, &[1, 0, 0x00, 0x1A], true).await,
            Err(PARAMETER_INCOMPATIBLE)
        );
        assert_eq!(c.upload_kind(&sd, 0x1C12, 0, true).await.unwrap().0, assign);
        assert_eq!(settled(&sim), before, "the refused assignment changed nothing");
        // the mailbox fuzz target's finding: an expedited complete download
        // of 1600h:01 (size not indicated: four bytes 6Eh, entry 6E6Eh:6Eh)
        // was refused with 0604 0041h after sub 0 = 0, and the default
        // mapping was gone
        assert_eq!(
            c.download_normal(&sd, 0x1600, 1, &[0x6E; 4], true).await,
            Err(SdoAbort::NOT_MAPPABLE.0)
        );
        assert_eq!(c.upload_kind(&sd, 0x1600, 0, true).await.unwrap().0, map);
        assert_eq!(settled(&sim), before, "the refused mapping changed nothing");
        // back to the default
        c.download_normal(&sd, 0x1C12, 0, &[1, 0, 0x00, 0x16], true)
            .await
            .unwrap();
        assert_eq!(
            c.upload_kind(&sd, 0x1C12, 0, true).await.unwrap().0,
            [1, 0, 0x00, 0x16]
        );

        // 1600h in segments with complete access: a new mapping and back
        let mut short = vec![2, 0];
        short.extend_from_slice(&0x6040_0010u32.to_le_bytes());
        short.extend_from_slice(&0x60FF_0020u32.to_le_bytes());
        c.download_segmented(&sd, 0x1600, 0, &short, true).await.unwrap();
        assert_eq!(c.upload_kind(&sd, 0x1600, 0, true).await.unwrap().0, short);
        assert_eq!(objects(&sim).process_data_bytes(), Some((6, 29)));
        c.download_segmented(&sd, 0x1600, 0, &map, true).await.unwrap();
        assert_eq!(c.upload_kind(&sd, 0x1600, 0, true).await.unwrap().0, map);
        assert_eq!(objects(&sim).process_data_bytes(), Some((23, 29)));

        // not in Safe-Op: 0800 0022h, nothing written
        let group = group.into_safe_op(md).await.expect("PRE-OP -> SAFE-OP");
        let sd = group.subdevice(md, 0).unwrap();
        let before = settled(&sim);
        assert_eq!(
            c.download_normal(&sd, 0x1C12, 0, &[1, 0, 0x01, 0x16], true).await,
            Err(DEVICE_STATE)
        );
        assert_eq!(settled(&sim), before);
    });
}

#[test]
fn e078_ethercrab_complete_access_from_subindex_1_to_assignment_and_mapping() {
    // ethercrab's `SubIndex::Complete` is complete access from subindex 1
    // (sub 0 not in the data): the entries, then sub 0 = their number
    use ethercrab::SubIndex::Complete;
    let sim = line(1);
    with_sdo(&sim, async |sd, c| {
        let assign: [u8; 2] = sd.sdo_read(0x1C12, Complete).await.expect("CA upload from sub 1");
        assert_eq!(assign, [0x00, 0x16]);
        sd.sdo_write(0x1C12, Complete, 0x1602u16)
            .await
            .expect("CA download from sub 1 of 1C12h");
        assert_eq!(
            c.upload_kind(sd, 0x1C12, 0, true).await.unwrap().0,
            [1, 0, 0x02, 0x16]
        );
        sd.sdo_write(0x1C12, Complete, 0x1600u16).await.unwrap();
        // a one-entry RxPDO: controlword only
        sd.sdo_write(0x1600, Complete, 0x6040_0010u32)
            .await
            .expect("CA download from sub 1 of 1600h");
        assert_eq!(c.upload(sd, 0x1600, 0).await, Ok(vec![1]));
        assert_eq!(objects(&sim).process_data_bytes(), Some((2, 29)));
        // a refused entry puts the mapping back, as from sub 0
        assert_eq!(
            c.download_normal(sd, 0x1600, 1, &0x6041_0010u32.to_le_bytes(), true)
                .await,
            Err(SdoAbort::NOT_MAPPABLE.0)
        );
        assert_eq!(c.upload(sd, 0x1600, 0).await, Ok(vec![1]));
        assert_eq!(
            c.upload(sd, 0x1600, 1).await,
            Ok(0x6040_0010u32.to_le_bytes().to_vec())
        );
    });
}

#[test]
fn e016_e017_e084_access_level_a10_2_decides_what_coe_sees() {
    let sim = line(1);
    let a10 = drive_ecat::parameter_index(0, 10);
    let a293 = drive_ecat::parameter_index(0, 293); // PLL gain, level 3
    let a150 = drive_ecat::parameter_index(0, 150); // cycle time, level 1
    with_sdo(&sim, async |sd, c| {
        for level in [0u8, 1, 3, 2] {
            c.download(sd, a10, 3, &[level]).await.unwrap();
            let expected: Vec<u16> = device_objects()
                .filter(|o| o.level <= level)
                .map(|o| o.info.index)
                .collect();
            assert_eq!(c.od_list(sd, 1).await, expected, "E-084 at level {level}");
            let a150_read = c.upload(sd, a150, 0).await;
            let a293_write = c.download(sd, a293, 0, &[0, 0]).await;
            if level >= 1 {
                assert_eq!(a150_read, Ok(1000u16.to_le_bytes().to_vec()));
            } else {
                assert_eq!(a150_read, Err(NO_OBJECT), "E-016 hidden at level 0");
            }
            if level >= 3 {
                assert_eq!(a293_write, Ok(()));
            } else {
                assert_eq!(a293_write, Err(NO_OBJECT), "E-016 hidden at level {level}");
            }
        }
    });
}
