//! Object dictionary tests, named after the spec items they check.

use crate::objects::{self, Object, Value, OBJECTS};
use crate::tests_sdo::{rd, rd_u, PREOP};
use crate::*;
use od::{CommState, Dictionary as _, SdoAbort};
use std::string::String;
use std::vec;
use std::vec::Vec;

fn wr(d: &mut DriveObjects, index: u16, sub: u8, v: u32, n: usize) -> Result<(), SdoAbort> {
    d.write(index, sub, &v.to_le_bytes()[..n], PREOP)
}

/// A dictionary that shows every object (A10[2] = 3).
fn all_visible() -> DriveObjects {
    let mut d = DriveObjects::new();
    wr(&mut d, parameter_index(0, 10), 3, 3, 1).unwrap();
    d
}

#[test]
fn od_doc_is_current() {
    let mut text = String::new();
    doc::write_reference(&mut text).unwrap();
    let docs = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs"));
    let cmd = "cargo test -p drive-core od_doc_is_current";
    let check = desc_xml::check_file_current(docs, "object-dictionary.md", &text, "UPDATE_OD_DOC", cmd);
    assert_eq!(check, Ok(()));
}

#[test]
fn e004_e005_identity() {
    let mut d = DriveObjects::new();
    assert_eq!(rd_u(&mut d, 0x1000, 0), 0x0002_0192);
    assert_eq!(rd(&mut d, 0x1018, 0).unwrap(), [4]);
    assert_eq!(rd_u(&mut d, 0x1018, 1), 0xB9);
    assert_eq!(rd_u(&mut d, 0x1018, 2), u64::from(PRODUCT_CODE));
    assert_eq!(rd_u(&mut d, 0x1018, 3), u64::from(SOFTWARE_BUILD));
    assert_eq!(rd_u(&mut d, 0x1018, 4), u64::from(SERIAL));
}

#[test]
fn e006_strings_and_e52() {
    let mut d = DriveObjects::new();
    assert_eq!(rd(&mut d, 0x1008, 0).unwrap(), DEVICE_NAME.as_bytes());
    assert_eq!(rd(&mut d, 0x1009, 0).unwrap(), HARDWARE_VERSION.as_bytes());
    assert_eq!(rd(&mut d, 0x100A, 0).unwrap(), SOFTWARE_VERSION.as_bytes());
    // E50 = 1008h, E52[1] = 1009h, E52[2] = 1018h:04, E52[3] = 100Ah
    assert_eq!(
        rd(&mut d, parameter_index(4, 50), 0).unwrap(),
        DEVICE_NAME.as_bytes()
    );
    let e52 = parameter_index(4, 52);
    assert_eq!(rd(&mut d, e52, 0).unwrap(), [4]);
    assert_eq!(rd(&mut d, e52, 2).unwrap(), HARDWARE_VERSION.as_bytes());
    assert_eq!(rd_u(&mut d, e52, 3), u64::from(SERIAL));
    assert_eq!(rd(&mut d, e52, 4).unwrap(), SOFTWARE_VERSION.as_bytes());
}

#[test]
fn e007_error_register_is_live() {
    let mut d = DriveObjects::new();
    assert_eq!(rd(&mut d, 0x1001, 0).unwrap(), [0]);
    d.set(0x1001, 0, 0x11).unwrap();
    assert_eq!(rd(&mut d, 0x1001, 0).unwrap(), [0x11]);
    assert_eq!(wr(&mut d, 0x1001, 0, 0, 1), Err(SdoAbort::READ_ONLY));
}

#[test]
fn e008_revision_follows_template() {
    let mut d = DriveObjects::new();
    let sdo_info = rd_u(&mut d, 0x1018, 3);
    d.set_template(Template::Rx);
    let rx = rd_u(&mut d, 0x1018, 3);
    assert_ne!(sdo_info, rx);
    assert_eq!((sdo_info & 1, rx & 1), (1, 0));
    assert_eq!(sdo_info >> 1, rx >> 1, "same build number");
    assert!(!d.sdo_info_enabled());
}

/// Parses the parameter coordinate at the start of a note ("A225 = 1600h" → (0, 225)).
fn coordinate(note: &str) -> Option<(u16, u16)> {
    let mut chars = note.chars();
    let group = chars.next()?;
    let digits: String = chars.take_while(char::is_ascii_digit).collect();
    (group.is_ascii_uppercase() && !digits.is_empty())
        .then(|| (group as u16 - 'A' as u16, digits.parse().unwrap()))
}

#[test]
fn e009_manufacturer_index_formula() {
    assert_eq!(parameter_index(0, 0), 0x2000);
    assert_eq!(parameter_index(25, 511), 0x53FF);
    let mut n = 0;
    for o in OBJECTS
        .iter()
        .filter(|o| (0x2000..0x6000).contains(&o.info.index))
    {
        let (group, line) =
            coordinate(o.note).unwrap_or_else(|| panic!("{:04X}h: note names no parameter", o.info.index));
        assert!(line < 512);
        assert_eq!(o.info.index, parameter_index(group, line), "{}", o.note);
        n += 1;
    }
    assert!(n > 40);
    let mut d = DriveObjects::new();
    assert_eq!(rd_u(&mut d, parameter_index(0, 150), 0), 1000, "A150 at 2096h");
}

#[test]
fn e010_axis_b_parameters_at_plus_8000() {
    let mut d = all_visible();
    for o in OBJECTS
        .iter()
        .filter(|o| o.info.index >= 0xA000 && o.info.index < 0xE000)
    {
        let a = d.object(o.info.index - AXIS_B_MANUFACTURER).unwrap();
        assert_eq!(a.entries, o.info.entries);
        assert!(o.axis);
    }
    d.set(0xA043, 0, 0xBEEF).unwrap();
    assert_eq!(rd_u(&mut d, 0xA043, 0), 0xBEEF);
    assert_eq!(rd_u(&mut d, 0x2043, 0), 0, "own values per axis");
    assert!(d.object(0xA8C9).is_some(), "E201 axis B");
    assert_eq!(
        d.object(0xA096),
        None,
        "global parameters only in the axis-A window"
    );
}

#[test]
fn e011_simple_parameters_sub0_in_both_templates() {
    let mut d = DriveObjects::new();
    let a150 = parameter_index(0, 150);
    assert_eq!(rd_u(&mut d, a150, 0), 1000);
    d.set_template(Template::Rx);
    assert_eq!(rd_u(&mut d, a150, 0), 1000);
    assert_eq!(rd(&mut d, a150, 1), Err(SdoAbort::NO_SUBINDEX));
}

#[test]
fn e012_rx_template_subindex_is_element() {
    let mut d = DriveObjects::new();
    d.set_template(Template::Rx);
    let a10 = parameter_index(0, 10);
    assert_eq!(rd_u(&mut d, a10, 2), 2, "A10[2] at sub 2");
    assert_eq!(rd(&mut d, a10, 4), Err(SdoAbort::NO_SUBINDEX));
    // A225[0] = 1600h:01
    assert_eq!(rd_u(&mut d, 0x20E1, 0), 0x6040_0010);
    let info = d.object(a10).unwrap();
    assert_eq!(
        info.entries.iter().map(|e| e.sub).collect::<Vec<_>>(),
        [0, 1, 2, 3]
    );
}

#[test]
fn e013_sdo_info_template_subindex_plus_one() {
    let mut d = DriveObjects::new();
    let a10 = parameter_index(0, 10);
    assert_eq!(rd(&mut d, a10, 0).unwrap(), [4], "sub 0 = number of elements");
    assert_eq!(rd_u(&mut d, a10, 3), 2, "A10[2] at sub 3");
    wr(&mut d, a10, 3, 3, 1).unwrap();
    d.set_template(Template::Rx);
    assert_eq!(rd_u(&mut d, a10, 2), 3, "same element, other subindex");
    d.set_template(Template::SdoInfo);
    assert_eq!(rd_u(&mut d, 0x20E1, 1), 0x6040_0010, "A225[0] at sub 1");
    assert_eq!(rd(&mut d, 0x20E1, 0).unwrap(), [8], "A225 sub 0 = 1600h:00");
    assert!(d.sdo_info_enabled());
}

#[test]
fn e014_e200_at_28c8() {
    let mut d = DriveObjects::new();
    assert_eq!(parameter_index(4, 200), 0x28C8);
    assert_eq!(d.object(0x28C8).unwrap().name, "Status words");
    d.set(0x28C8, 1, 0x1234).unwrap();
    d.set(0xA8C8, 1, 0x5678).unwrap();
    assert_eq!(rd_u(&mut d, 0x28C8, 1), 0x1234, "SDO Info: sub 1");
    assert_eq!(rd_u(&mut d, 0xA8C8, 1), 0x5678);
    d.set_template(Template::Rx);
    assert_eq!(rd_u(&mut d, 0x28C8, 0), 0x1234, "Rx: sub 0");
    assert_eq!(rd_u(&mut d, 0xA8C8, 0), 0x5678);
    assert_eq!(d.object(0xA8C8).unwrap().index, 0xA8C8);
    assert_eq!(d.object(0xA8C8).unwrap().entries.first().unwrap().sub, 0);
}

#[test]
fn e015_axis_b_at_plus_800() {
    let mut d = DriveObjects::new();
    let a: Vec<&Object> = OBJECTS
        .iter()
        .filter(|o| (0x6000..0x6600).contains(&o.info.index))
        .collect();
    let b: Vec<&Object> = OBJECTS
        .iter()
        .filter(|o| (0x6800..0x6E00).contains(&o.info.index))
        .collect();
    assert_eq!(a.len(), b.len());
    assert!(a.len() >= 66);
    for (a, b) in a.iter().zip(&b) {
        assert_eq!(a.info.index + AXIS_B_CIA402, b.info.index);
        assert_eq!(
            (a.info.name, a.info.entries, a.value),
            (b.info.name, b.info.entries, b.value)
        );
    }
    wr(&mut d, 0x6860, 0, 9, 1).unwrap();
    assert_eq!(rd(&mut d, 0x6060, 0).unwrap(), [8]);
    assert_eq!(rd(&mut d, 0x6860, 0).unwrap(), [9]);
}

#[test]
fn e016_hidden_parameter_refused() {
    let mut d = DriveObjects::new();
    let a293 = parameter_index(0, 293); // level 3, A10[2] = 2 by default
    assert_eq!(rd(&mut d, a293, 0), Err(SdoAbort::NO_OBJECT));
    assert_eq!(wr(&mut d, a293, 0, 1, 2), Err(SdoAbort::NO_OBJECT));
    assert_eq!(d.object(a293), None);
    assert_ne!(d.next_object(Some(a293 - 1)).map(|o| o.index), Some(a293));
    wr(&mut d, parameter_index(0, 10), 3, 3, 1).unwrap();
    assert!(d.object(a293).is_some());
    assert_eq!(d.next_object(Some(a293 - 1)).map(|o| o.index), Some(a293));
    assert_eq!(rd_u(&mut d, a293, 0), 0);
    // E-017: A10[2] = 0 hides A150 (level 1), not the standard objects
    wr(&mut d, parameter_index(0, 10), 3, 0, 1).unwrap();
    assert_eq!(rd(&mut d, parameter_index(0, 150), 0), Err(SdoAbort::NO_OBJECT));
    assert!(rd(&mut d, 0x6041, 0).is_ok());
    // a hidden object cannot be mapped either
    wr(&mut d, parameter_index(0, 10), 3, 3, 1).unwrap();
}

#[test]
fn e018_written_values_ram_until_saved() {
    let mut d = DriveObjects::new();
    wr(&mut d, 0x6060, 0, 9, 1).unwrap();
    assert_eq!(
        d.take_requests(),
        Requests::default(),
        "a write alone saves nothing"
    );
    // A00[0] = 1 requests saving
    wr(&mut d, parameter_index(0, 0), 1, 1, 1).unwrap();
    assert!(d.take_requests().save);
    let mut image = [0u8; PERSISTENT_IMAGE_BYTES];
    assert_eq!(d.persistent_image(&mut image), Ok(PERSISTENT_IMAGE_BYTES));
    assert_eq!(d.persistent_image(&mut [0u8; 4]), Err(ImageError::BufferTooSmall));
    // after a restart: defaults until the image is loaded
    let mut fresh = DriveObjects::new();
    assert_eq!(rd(&mut fresh, 0x6060, 0).unwrap(), [8]);
    fresh.load_persistent(&image).unwrap();
    assert_eq!(rd(&mut fresh, 0x6060, 0).unwrap(), [9]);
    // 1010h:01 "save"; other values 0800 0020h
    assert_eq!(wr(&mut d, 0x1010, 1, 0x1234, 4), Err(SdoAbort::TRANSFER));
    assert!(!d.requests().save);
    wr(&mut d, 0x1010, 1, SAVE_SIGNATURE, 4).unwrap();
    assert!(d.take_requests().save);
    assert_eq!(rd_u(&mut d, 0x1010, 1), 1);
    // 1011h:01 "load": defaults in RAM, PreOp only
    assert_eq!(
        d.write(0x1011, 1, &LOAD_SIGNATURE.to_le_bytes(), CommState::SafeOp),
        Err(SdoAbort::DEVICE_STATE)
    );
    assert_eq!(wr(&mut d, 0x1011, 1, 0, 4), Err(SdoAbort::TRANSFER));
    wr(&mut d, 0x1011, 1, LOAD_SIGNATURE, 4).unwrap();
    assert!(d.take_requests().defaults_restored);
    assert_eq!(rd(&mut d, 0x6060, 0).unwrap(), [8]);
    let mut defaults = [0u8; PERSISTENT_IMAGE_BYTES];
    DriveObjects::new().persistent_image(&mut defaults).unwrap();
    d.persistent_image(&mut image).unwrap();
    assert_eq!(image, defaults);
}

#[test]
fn persistent_image_from_another_layout_refused() {
    let mut d = all_visible();
    let mut image = [0u8; PERSISTENT_IMAGE_BYTES];
    d.persistent_image(&mut image).unwrap();
    let before = d.clone();
    let mut foreign = image;
    foreign[4] ^= 1;
    assert_eq!(d.load_persistent(&foreign), Err(ImageError::ForeignLayout));
    assert_eq!(
        d.load_persistent(&image[..image.len() - 1]),
        Err(ImageError::Malformed)
    );
    let mut bad = image;
    bad[0] = b'X';
    assert_eq!(d.load_persistent(&bad), Err(ImageError::Malformed));
    assert_eq!(d, before);
    // restart request
    wr(&mut d, parameter_index(0, 9), 1, 1, 1).unwrap();
    assert!(d.take_requests().restart);
    // the template is part of the image
    d.set_template(Template::Rx);
    d.persistent_image(&mut image).unwrap();
    let mut fresh = DriveObjects::new();
    fresh.load_persistent(&image).unwrap();
    assert_eq!(fresh.template(), Template::Rx);
    const { assert!(objects::PERSISTENT_BYTES > 400) };
}

#[test]
fn e048_mapping_write_checks() {
    let mut d = DriveObjects::new();
    // entries change only while sub 0 = 0
    assert_eq!(wr(&mut d, 0x1600, 9, 0x6042_0010, 4), Err(SdoAbort::DEVICE_STATE));
    assert_eq!(wr(&mut d, 0x1600, 0, 0, 1), Ok(()));
    // statusword is not RxPDO-mappable; 5555h does not exist; bad length
    assert_eq!(wr(&mut d, 0x1600, 1, 0x6041_0010, 4), Err(SdoAbort::NOT_MAPPABLE));
    assert_eq!(wr(&mut d, 0x1600, 1, 0x5555_0010, 4), Err(SdoAbort::NOT_MAPPABLE));
    assert_eq!(wr(&mut d, 0x1600, 1, 0x6040_0510, 4), Err(SdoAbort::NOT_MAPPABLE));
    assert_eq!(
        wr(&mut d, 0x1600, 1, 0x6040_0020, 4),
        Err(SdoAbort::PARAMETER_INCOMPATIBLE)
    );
    assert_eq!(
        wr(&mut d, 0x1600, 1, 0x6040_0010, 2),
        Err(SdoAbort::LENGTH_TOO_LOW)
    );
    assert_eq!(rd_u(&mut d, 0x1600, 1), 0x6040_0010, "unchanged");
    // a valid remapping: controlword + target velocity + 8-bit gap
    wr(&mut d, 0x1600, 2, 0x60FF_0020, 4).unwrap();
    wr(&mut d, 0x1600, 3, 0x0000_0008, 4).unwrap();
    assert_eq!(wr(&mut d, 0x1600, 0, 25, 1), Err(SdoAbort::PDO_LENGTH));
    wr(&mut d, 0x1600, 0, 3, 1).unwrap();
    assert_eq!(d.process_data_bytes(), Some((7, 29)));
    assert_eq!(
        d.mapping(0x1600).collect::<Vec<_>>(),
        [0x6040_0010, 0x60FF_0020, 8]
    );
    // the count is checked against the entries: entry 4 still maps 60B1h (ok), but
    // a TxPDO-only entry left behind is refused
    wr(&mut d, 0x1600, 0, 0, 1).unwrap();
    wr(&mut d, 0x1600, 4, 0, 4).unwrap();
    assert_eq!(wr(&mut d, 0x1600, 0, 4, 1), Ok(()), "entry 0 = no bits");
    // PreOp only
    assert_eq!(
        d.write(0x1600, 0, &[0], CommState::SafeOp),
        Err(SdoAbort::DEVICE_STATE)
    );
    // channel 4 (FSoE) is not user-configurable (E-052)
    assert_eq!(wr(&mut d, 0x1603, 0, 0, 1), Err(SdoAbort::READ_ONLY));
    // A225 is 1600h (E-048)
    assert_eq!(rd_u(&mut d, 0x20E1, 2), 0x60FF_0020);
    assert_eq!(wr(&mut d, 0x20E1, 2, 0, 4), Err(SdoAbort::DEVICE_STATE));
    // a hidden object cannot be mapped
    wr(&mut d, 0x1A02, 1, 0x2045_0010, 4).unwrap(); // A69 (level 1)
    wr(&mut d, parameter_index(0, 10), 3, 0, 1).unwrap();
    assert_eq!(wr(&mut d, 0x1A02, 0, 1, 1), Err(SdoAbort::NOT_MAPPABLE));
    assert_eq!(wr(&mut d, 0x1A02, 2, 0x2045_0010, 4), Err(SdoAbort::NOT_MAPPABLE));
}

#[test]
fn e049_tx_mapping_and_manufacturer_entries() {
    let mut d = DriveObjects::new();
    wr(&mut d, 0x1A02, 1, 0x20FA_0001, 4).unwrap(); // A250, BOOL
    wr(&mut d, 0x1A02, 2, 0x10F3_0401, 4).unwrap(); // 10F3h:04
    wr(&mut d, 0x1A02, 3, 0x0000_0006, 4).unwrap(); // gap
    wr(&mut d, 0x1A02, 0, 3, 1).unwrap();
    assert_eq!(wr(&mut d, 0x1A02, 4, 0x6040_0010, 4), Err(SdoAbort::DEVICE_STATE));
    wr(&mut d, 0x1A02, 0, 0, 1).unwrap();
    assert_eq!(
        wr(&mut d, 0x1A02, 4, 0x6040_0010, 4),
        Ok(()),
        "controlword is also TxPDO-mappable"
    );
    assert_eq!(
        wr(&mut d, 0x1A02, 5, 0x607E_0008, 4),
        Err(SdoAbort::NOT_MAPPABLE),
        "polarity: RxPDO only"
    );
}

#[test]
fn e054_assignment_checks() {
    let mut d = DriveObjects::new();
    assert_eq!(wr(&mut d, 0x1C12, 2, 0x1601, 2), Err(SdoAbort::DEVICE_STATE));
    wr(&mut d, 0x1C12, 0, 0, 1).unwrap();
    assert_eq!(
        wr(&mut d, 0x1C12, 2, 0x1A01, 2),
        Err(SdoAbort::PARAMETER_INCOMPATIBLE)
    );
    assert_eq!(
        wr(&mut d, 0x1C12, 2, 0x1604, 2),
        Err(SdoAbort::PARAMETER_INCOMPATIBLE)
    );
    assert_eq!(wr(&mut d, 0x1C12, 2, 0x1601, 1), Err(SdoAbort::LENGTH_TOO_LOW));
    assert_eq!(
        wr(&mut d, 0x1C12, 0, 2, 1),
        Err(SdoAbort::PARAMETER_INCOMPATIBLE),
        "sub 2 = 0"
    );
    wr(&mut d, 0x1C12, 2, 0x1600, 2).unwrap();
    assert_eq!(
        wr(&mut d, 0x1C12, 0, 2, 1),
        Err(SdoAbort::PARAMETER_INCOMPATIBLE),
        "1600h twice"
    );
    wr(&mut d, 0x1C12, 2, 0x1601, 2).unwrap();
    assert_eq!(wr(&mut d, 0x1C12, 0, 5, 1), Err(SdoAbort::VALUE_TOO_HIGH));
    wr(&mut d, 0x1C12, 0, 2, 1).unwrap();
    assert_eq!(d.process_data_bytes(), Some((46, 29)));
    assert_eq!(d.assigned_pdos(0x1C12).collect::<Vec<_>>(), [0x1600, 0x1601]);
    // A252 = 1C12h
    assert_eq!(rd_u(&mut d, 0x20FC, 2), 0x1601);
    assert_eq!(
        d.write(0x1C13, 0, &[0], CommState::Op),
        Err(SdoAbort::DEVICE_STATE)
    );
}

/// E-034: the SyncManager lengths follow every mapping change (they are
/// kept between changes, the slave asks each poll).
#[test]
fn e034_sm_lengths_follow_each_mapping_change() {
    let mut d = DriveObjects::new();
    let before = d.process_data_bytes().unwrap();
    assert!(before.0 > 0 && before.1 > 0);
    assert_eq!(d.process_data_bytes().unwrap(), before);
    wr(&mut d, 0x1C13, 0, 0, 1).unwrap();
    assert_eq!(d.process_data_bytes().unwrap(), (before.0, 0));
    wr(&mut d, 0x1C12, 0, 0, 1).unwrap();
    assert_eq!(d.process_data_bytes().unwrap(), (0, 0));
    wr(&mut d, 0x1C13, 0, 1, 1).unwrap();
    assert_eq!(d.process_data_bytes().unwrap(), (0, before.1));
}

#[test]
fn mirrors_and_aliases_have_the_target_types() {
    let d = all_visible();
    for o in OBJECTS.iter() {
        let targets: Vec<(usize, u16, u8)> = match o.value {
            Value::Mirror { index, sub0 } => {
                let t = d.object(index).unwrap();
                let skip = usize::from(!sub0);
                (skip..o.info.entries.len())
                    .map(|k| (k, index, t.entries.get(k).unwrap().sub))
                    .collect()
            }
            Value::Alias(list) => list
                .iter()
                .enumerate()
                .filter(|(_, (i, _))| *i != 0)
                .map(|(k, (i, s))| (k, *i, *s))
                .collect(),
            _ => continue,
        };
        for (k, index, sub) in targets {
            let own = o.info.entries.get(k).unwrap();
            let t = d
                .object(index)
                .unwrap()
                .entries
                .iter()
                .find(|e| e.sub == sub)
                .unwrap();
            assert_eq!(own.data_type, t.data_type, "{:04X}h:{k}", o.info.index);
            assert_eq!(
                own.access.0 & 0x3F,
                t.access.0 & 0x3F,
                "{:04X}h:{k}",
                o.info.index
            );
        }
    }
}

struct Provider {
    statusword: u16,
    acknowledged: Option<u8>,
}

impl LiveValues for Provider {
    fn read(&mut self, index: u16, sub: u8, buf: &mut [u8]) -> Option<Result<usize, SdoAbort>> {
        match (index, sub) {
            (0x6041, 0) => Some(od::DataType::U16.encode(i64::from(self.statusword), buf)),
            (0x10F3, 6) => Some(Ok(3)),
            _ => None,
        }
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        match (index, sub, data) {
            (0x10F3, 3, [0xFF]) => Err(SdoAbort::INVALID_VALUE),
            (0x10F3, 3, [v]) => {
                self.acknowledged = Some(*v);
                Ok(())
            }
            _ => Ok(()),
        }
    }
}

#[test]
fn live_values_from_provider_and_runtime() {
    let mut d = DriveObjects::new();
    let mut p = Provider {
        statusword: 0x0237,
        acknowledged: None,
    };
    let mut buf = [0u8; 32];
    let mut live = d.with_live(&mut p);
    assert_eq!(live.read(0x6041, 0, &mut buf, PREOP), Ok(2));
    assert_eq!(&buf[..2], &[0x37, 0x02]);
    assert_eq!(live.read(0x10F3, 6, &mut buf, PREOP), Ok(3));
    assert_eq!(
        live.write(0x10F3, 3, &[0xFF], PREOP),
        Err(SdoAbort::INVALID_VALUE)
    );
    assert_eq!(live.write(0x10F3, 3, &[7], PREOP), Ok(()));
    assert_eq!(live.read(0x10F3, 1, &mut buf[..1], PREOP), Ok(1));
    assert_eq!(buf[0], 20, "not provided: from the declaration");
    assert_eq!(p.acknowledged, Some(7));
    // without a provider: what the runtime set
    d.set(0x6041, 0, 0x0627).unwrap();
    assert_eq!(rd_u(&mut d, 0x6041, 0), 0x0627);
    assert_eq!(rd_u(&mut d, 0x10F3, 3), 7);
    d.set(0x20FF, 0, 8).unwrap(); // A255 = Op
    assert_eq!(rd_u(&mut d, 0x20FF, 0), 8);
    d.set_bytes(0x2101, 1, b"Er0 L01 L10").unwrap(); // A257[0]
    assert_eq!(rd(&mut d, 0x2101, 1).unwrap(), b"Er0 L01 L10");
    assert_eq!(d.set(0x1000, 0, 1), Err(SdoAbort::READ_ONLY), "constants stay");
    assert_eq!(d.set(0x6041, 0, 0x1_0000), Err(SdoAbort::VALUE_TOO_HIGH));
    assert_eq!(d.get(0x6041, 0), Ok(0x0627));
}

#[test]
fn invalid_enumeration_values() {
    let mut d = DriveObjects::new();
    assert_eq!(wr(&mut d, 0x6060, 0, 5, 1), Err(SdoAbort::INVALID_VALUE));
    assert_eq!(wr(&mut d, 0x6860, 0, 5, 1), Err(SdoAbort::INVALID_VALUE));
    assert_eq!(wr(&mut d, 0x6060, 0, 0xFF, 1), Ok(()), "-1 jog");
    assert_eq!(wr(&mut d, 0x6098, 0, 4, 1), Err(SdoAbort::INVALID_VALUE));
    assert_eq!(wr(&mut d, 0x6098, 0, 37, 1), Ok(()));
    assert_eq!(
        wr(&mut d, parameter_index(0, 150), 0, 300, 2),
        Err(SdoAbort::INVALID_VALUE)
    );
    assert_eq!(wr(&mut d, parameter_index(0, 150), 0, 250, 2), Ok(()));
}

#[test]
fn sdo_info_lists_visible_objects_in_order() {
    let d = DriveObjects::new();
    let mut last = None;
    let mut n = 0;
    while let Some(o) = d.next_object(last) {
        assert!(last.is_none_or(|l| o.index > l));
        last = Some(o.index);
        n += 1;
    }
    let hidden = OBJECTS.iter().filter(|o| o.level > 2).count();
    assert_eq!(n, OBJECTS.len() - hidden);
    assert_eq!(d.next_object(None).unwrap().index, 0x1000);
}

/// Expected abort of a write of `value` to an entry whose checks passed up to the range.
fn range_abort(o: &Object, sub: u8, high: bool) -> SdoAbort {
    let index = match o.value {
        Value::Mirror { index, .. } => index,
        _ => o.info.index,
    };
    match (index, sub) {
        (0x1600..=0x1603 | 0x1A00..=0x1A03, 0) => SdoAbort::PDO_LENGTH,
        _ if high => SdoAbort::VALUE_TOO_HIGH,
        _ => SdoAbort::VALUE_TOO_LOW,
    }
}

/// For every object × {wrong size, out of range, read-only, wrong state,
/// write-only read}: the exact abort code, and nothing changed.
#[test]
fn bad_input_matrix() {
    let mut d = all_visible();
    let mut checked = [0usize; 5];
    for o in OBJECTS.iter() {
        let index = o.info.index;
        for e in o.info.entries {
            let t = e.data_type;
            let n = t.bytes();
            let before = d.clone();
            let mut expect =
                |d: &mut DriveObjects, data: &[u8], state: CommState, code: SdoAbort, k: usize| {
                    assert_eq!(
                        d.write(index, e.sub, data, state),
                        Err(code),
                        "{index:04X}h:{:02X}h {data:02X?}",
                        e.sub
                    );
                    assert_eq!(*d, before, "{index:04X}h:{:02X}h changed", e.sub);
                    checked[k] += 1;
                };
            let zero = vec![0u8; n + 1];
            if !e.access.writable() {
                expect(&mut d, &zero[..n], PREOP, SdoAbort::READ_ONLY, 0);
                continue;
            }
            if !e.access.writable_in(1) {
                expect(&mut d, &zero[..n], CommState::SafeOp, SdoAbort::DEVICE_STATE, 1);
                expect(&mut d, &zero[..n], CommState::Op, SdoAbort::DEVICE_STATE, 1);
            }
            expect(&mut d, &zero, PREOP, SdoAbort::LENGTH_TOO_HIGH, 2);
            if !matches!(t, od::DataType::VisibleString(_)) && n > 0 {
                expect(&mut d, &zero[..n - 1], PREOP, SdoAbort::LENGTH_TOO_LOW, 2);
            }
            if t.is_integer() && o.value != Value::Command {
                for (v, high) in [(e.highest() + 1, true), (e.lowest() - 1, false)] {
                    if v > t.max_value() || v < t.min_value() {
                        continue; // the type's own bounds: no such value on the wire
                    }
                    let mut raw = [0u8; 8];
                    t.encode(v, &mut raw).unwrap();
                    expect(&mut d, &raw[..n], PREOP, range_abort(o, e.sub, high), 3);
                }
            }
        }
        for e in o.info.entries.iter().filter(|e| !e.access.readable()) {
            let mut buf = [0u8; 8];
            assert_eq!(d.read(index, e.sub, &mut buf, PREOP), Err(SdoAbort::WRITE_ONLY));
            checked[4] += 1;
        }
    }
    assert!(checked.iter().all(|&c| c > 0), "{checked:?}");
}

#[test]
fn missing_objects_and_subindices() {
    let mut d = DriveObjects::new();
    for index in [
        0x0000, 0x1002, 0x1604, 0x2001, 0x5FFF, 0x6045, 0x6E00, 0xA000, 0xFFFF,
    ] {
        assert_eq!(rd(&mut d, index, 0), Err(SdoAbort::NO_OBJECT), "{index:04X}h");
        assert_eq!(
            wr(&mut d, index, 0, 0, 1),
            Err(SdoAbort::NO_OBJECT),
            "{index:04X}h"
        );
    }
    assert_eq!(rd(&mut d, 0x6041, 1), Err(SdoAbort::NO_SUBINDEX));
    assert_eq!(rd(&mut d, 0x1C32, 7), Err(SdoAbort::NO_SUBINDEX));
    assert_eq!(wr(&mut d, 0x6092, 3, 0, 4), Err(SdoAbort::NO_SUBINDEX));
    assert_eq!(rd(&mut d, 0x60C4, 6), Err(SdoAbort::WRITE_ONLY));
}

#[test]
fn ram_image_layout() {
    assert_eq!(objects::OFFSETS.len(), OBJECTS.len());
    let total: usize = OBJECTS.iter().map(Object::ram_bytes).sum();
    assert_eq!(total, objects::IMAGE_BYTES);
    // every RAM default reads back as declared
    let mut d = all_visible();
    for o in OBJECTS
        .iter()
        .filter(|o| matches!(o.value, Value::Ram | Value::Live))
    {
        for e in o
            .info
            .entries
            .iter()
            .filter(|e| e.access.readable() && e.data_type.is_integer())
        {
            let expect = if (o.info.index, e.sub) == (parameter_index(0, 10), 3) {
                3
            } else {
                e.default
            };
            assert_eq!(
                d.get(o.info.index, e.sub),
                Ok(expect),
                "{:04X}h:{:02X}h",
                o.info.index,
                e.sub
            );
        }
    }
    let _ = rd(&mut d, 0x1000, 0);
}

/// The resolution cache of `get`/`set` answers exactly what the SDO path
/// reads, for every readable integer entry, on the first (resolving) and
/// the second (cached) access, and after a `set` through the cache.
#[test]
fn e016_cached_get_equals_the_sdo_read_of_every_entry() {
    let mut d = DriveObjects::new();
    let mut checked = 0;
    for o in OBJECTS.iter() {
        for e in o.info.entries {
            if !(e.data_type.is_integer() || e.data_type == od::DataType::F32) {
                continue;
            }
            let mut buf = [0u8; 8];
            let Ok(n) = d.read(o.info.index, e.sub, &mut buf, CommState::PreOp) else {
                continue;
            };
            let Ok(sdo) = e.data_type.decode(&buf[..n]) else {
                continue;
            };
            let first = d.get(o.info.index, e.sub);
            let second = d.get(o.info.index, e.sub);
            assert_eq!(first, Ok(sdo), "{:04X}:{}", o.info.index, e.sub);
            assert_eq!(second, Ok(sdo), "{:04X}:{} cached", o.info.index, e.sub);
            checked += 1;
        }
    }
    assert!(checked > 300, "{checked} entries");
    // a set through the cache lands where the SDO path reads
    d.set(0x6065, 0, 4321).unwrap();
    let mut buf = [0u8; 4];
    assert_eq!(d.read(0x6065, 0, &mut buf, CommState::PreOp), Ok(4));
    assert_eq!(u32::from_le_bytes(buf), 4321);
    // constants stay read-only through the cache
    assert_eq!(d.set(0x1000, 0, 1), Err(SdoAbort::READ_ONLY));
}

/// A [`Slot`] reads and writes exactly what `get`/`set` do, for every
/// integer entry in RAM: the same value, the same refusal of an
/// out-of-range value, the same configuration-generation change.
#[test]
fn slot_access_equals_get_and_set() {
    let mut checked = 0;
    for o in OBJECTS.iter() {
        for e in o.info.entries {
            let od = DriveObjects::new();
            let Some(slot) = od.slot(o.info.index, e.sub) else {
                continue;
            };
            assert_eq!(Ok(od.load_slot(slot)), od.get(o.info.index, e.sub));
            let t = e.data_type;
            let v = od.load_slot(slot);
            let candidates = [
                if v < t.max_value() { v + 1 } else { v - 1 },
                t.max_value().saturating_add(1),
                t.min_value().saturating_sub(1),
            ];
            for value in candidates {
                let (mut by_set, mut by_slot) = (od.clone(), od.clone());
                let ok = by_set.set(o.info.index, e.sub, value).is_ok();
                assert_eq!(
                    by_slot.store_slot(slot, value),
                    ok,
                    "{:04X}:{}",
                    o.info.index,
                    e.sub
                );
                assert_eq!(by_set, by_slot);
                assert_eq!(
                    by_set.config_generation() == od.config_generation(),
                    by_slot.config_generation() == od.config_generation(),
                    "{:04X}:{} generation",
                    o.info.index,
                    e.sub
                );
                let mut raw = [0u8; 9];
                assert!(by_slot.copy_slot_to(slot, &mut raw, 1));
                assert_eq!(
                    raw[1..=t.bytes()],
                    by_set.get(o.info.index, e.sub).unwrap().to_le_bytes()[..t.bytes()]
                );
                assert!(
                    !by_slot.copy_slot_to(slot, &mut raw, 9 - t.bytes() + 1),
                    "past the end"
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 300, "{checked} slots");
}

/// A150's allowed cycle times are written down in three crates (the
/// declaration's enumeration, `motion::cycle` for the axes, `dcsync` for the
/// DC checks): the same six values everywhere (C-144, E-125).
#[test]
fn c144_e125_a150_values_agree_with_the_declaration() {
    let declared: Vec<u32> = crate::objects::enumeration(crate::params::A150, 0)
        .expect("A150 has an enumeration")
        .iter()
        .map(|&us| u32::try_from(us * 1000).unwrap())
        .collect();
    assert_eq!(declared, motion::cycle::APPLICATION_CYCLES_NS);
    assert_eq!(declared, dcsync::validate::A150_VALUES_NS);
}

/// The cycle the drive assumes while A150 holds no allowed value is A150's
/// declared default (C-144), not a second number.
#[test]
fn c144_a150_fallback_is_the_declared_default() {
    let d = DriveObjects::new();
    assert_eq!(
        d.get(crate::params::A150, 0),
        Ok(i64::from(crate::params::A150_FALLBACK_US))
    );
}
