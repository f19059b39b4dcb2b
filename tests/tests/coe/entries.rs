//! Every entry through the mailbox: reads with the declared size, writes of the range ends and
//! the default (PreOp-only entries refused later), and bad writes with the exact abort code of
//! spec §6.5 and nothing changed (E-016, E-063, E-064, E-071 … E-076).

use super::*;

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
