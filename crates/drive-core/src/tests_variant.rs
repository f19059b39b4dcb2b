//! The single-axis device's dictionary ([`Variant::Single`], issue 20),
//! tests named after the spec items they check.

use crate::objects::{self, single, Object, Value, OBJECTS};
use crate::tests_sdo::{rd, rd_u, PREOP};
use crate::variant::is_axis_b;
use crate::*;
use od::{Dictionary as _, SdoAbort};
use std::vec::Vec;

fn single() -> DriveObjects {
    DriveObjects::for_variant(Variant::Single)
}

/// Every object index the bus lists (SDO Info order).
fn listed(d: &DriveObjects) -> Vec<u16> {
    let mut out = Vec::new();
    let mut after = None;
    while let Some(o) = d.next_object(after) {
        out.push(o.index);
        after = Some(o.index);
    }
    out
}

#[test]
fn e084_the_single_axis_device_lists_exactly_the_double_axis_objects_but_axis_b() {
    for level in 0..=3u8 {
        let (mut one, mut two) = (single(), DriveObjects::new());
        for d in [&mut one, &mut two] {
            d.write(parameter_index(0, 10), 3, &[level], PREOP).unwrap();
        }
        let (a, b) = (listed(&one), listed(&two));
        let want: Vec<u16> = b.iter().copied().filter(|&i| !is_axis_b(i)).collect();
        assert_eq!(a, want, "level {level}");
        assert!(
            b.iter().any(|&i| is_axis_b(i)),
            "the double-axis device lists axis B"
        );
        assert!(!a.iter().any(|&i| (0x6800..=0x6FFF).contains(&i)), "no 68xxh");
        assert!(
            !a.iter().any(|&i| (0xA000..=0xDFFF).contains(&i)),
            "no axis-B parameter"
        );
    }
    // every axis-B object of the declaration is a copy of an axis-A one:
    // hiding them hides nothing else
    let one = single();
    for o in OBJECTS.iter().filter(|o| is_axis_b(o.info.index)) {
        let a = match o.info.index {
            i @ 0x6800..=0x6FFF => i - AXIS_B_CIA402,
            i => i - AXIS_B_MANUFACTURER,
        };
        let (_, axis_a) = objects::find(a).unwrap();
        assert_eq!(axis_a.info.name, o.info.name, "{:04X}h", o.info.index);
        assert!(one.object(o.info.index).is_none());
    }
}

#[test]
fn e016_e072_axis_b_objects_are_refused_and_nothing_changes() {
    let mut d = single();
    let before = d.clone();
    for (index, sub) in [
        (0x6840, 0),
        (0x6841, 0),
        (0x687A, 0),
        (0x68C1, 1),
        // E200 of axis B (A8C8h, E-014), A75 of axis B, J401 of axis B
        (0xA8C8, 1),
        (actions::A75 + AXIS_B_MANUFACTURER, 0),
        (objects::records::J401 + AXIS_B_MANUFACTURER, 1),
    ] {
        assert_eq!(
            rd(&mut d, index, sub),
            Err(SdoAbort::NO_OBJECT),
            "{index:04X}h:{sub}"
        );
        assert_eq!(
            d.write(index, sub, &[1, 0], PREOP),
            Err(SdoAbort::NO_OBJECT),
            "{index:04X}h:{sub}"
        );
        assert_eq!(d.object(index), None);
    }
    assert_eq!(d, before, "refused accesses change nothing");
    // the same through the parameter channel (CoE SDO, UDP parameter service)
    let mut live = NoLive;
    let mut buf = [0u8; 4];
    let mut ch = d.parameter_channel(&mut live);
    assert_eq!(ch.read(0x6841, 0, &mut buf, PREOP), Err(SdoAbort::NO_OBJECT));
    // axis A is all there
    assert!(rd(&mut d, 0x6041, 0).is_ok());
    assert!(rd(&mut d, 0x28C8, 1).is_ok());
}

#[test]
fn e058_mapping_an_axis_b_object_is_refused_with_0604_0041() {
    let mut d = single();
    d.write(0x1600, 0, &[0], PREOP).unwrap();
    let before = d.clone();
    for m in [0x6840_0010u32, 0x6841_0010, 0xA043_0010, 0x687A_0020] {
        assert_eq!(
            d.write(0x1600, 1, &m.to_le_bytes(), PREOP),
            Err(SdoAbort::NOT_MAPPABLE),
            "{m:08X}h"
        );
    }
    let m = 0x6841_0010u32;
    assert_eq!(
        d.write(0x1A01, 1, &m.to_le_bytes(), PREOP),
        Err(SdoAbort::NOT_MAPPABLE)
    );
    assert_eq!(d, before);
    // axis A's objects map into the free channel 2
    d.write(0x1601, 1, &0x6040_0010u32.to_le_bytes(), PREOP).unwrap();
    d.write(0x1601, 0, &[1], PREOP).unwrap();
    assert_eq!(d.mapping(0x1601).collect::<Vec<_>>(), [0x6040_0010]);
}

#[test]
fn e005_e006_the_single_axis_identity() {
    let mut d = single();
    assert_eq!(rd_u(&mut d, 0x1018, 2), u64::from(PRODUCT_CODE_SINGLE));
    assert_ne!(PRODUCT_CODE_SINGLE, PRODUCT_CODE, "masters tell the two apart");
    assert_eq!(rd_u(&mut d, 0x1018, 1), u64::from(VENDOR_ID));
    assert_eq!(rd_u(&mut d, 0x1018, 3), u64::from(SOFTWARE_BUILD));
    assert_eq!(rd(&mut d, 0x1008, 0).unwrap(), DEVICE_NAME_SINGLE.as_bytes());
    // E50 = 1008h
    assert_eq!(
        rd(&mut d, parameter_index(4, 50), 0).unwrap(),
        DEVICE_NAME_SINGLE.as_bytes()
    );
    assert_eq!(d.get(0x1018, 2), Ok(i64::from(PRODUCT_CODE_SINGLE)));
    // what SDO Info describes
    let ident = d.object(0x1018).unwrap();
    assert_eq!(ident.entry(2).unwrap().default, i64::from(PRODUCT_CODE_SINGLE));
    // the double-axis device is unchanged
    let mut two = DriveObjects::new();
    assert_eq!(rd_u(&mut two, 0x1018, 2), u64::from(PRODUCT_CODE));
    assert_eq!(rd(&mut two, 0x1008, 0).unwrap(), DEVICE_NAME.as_bytes());
}

#[test]
fn e051_e054_e148_channel_1_is_axis_a_and_channel_2_is_free_and_empty() {
    for template in [Template::SdoInfo, Template::Rx] {
        let mut d = single();
        d.set_template(template);
        assert_eq!(d.assigned_pdos(0x1C12).collect::<Vec<_>>(), [0x1600]);
        assert_eq!(d.assigned_pdos(0x1C13).collect::<Vec<_>>(), [0x1A00]);
        let (rx, tx) = PdoLayout::Standard.entries();
        assert_eq!(d.mapping(0x1600).count(), rx.len());
        assert_eq!(d.mapping(0x1A00).count(), tx.len());
        for pdo in [0x1601, 0x1A01] {
            assert_eq!(d.mapping(pdo).count(), 0, "{pdo:04X}h empty");
            assert_eq!(rd(&mut d, pdo, 0).unwrap(), [0]);
            assert_eq!(rd_u(&mut d, pdo, 1), 0);
        }
        // the mirrors A226/A234 read the same (level 2 = the default A10[2])
        for a in [parameter_index(0, 226), parameter_index(0, 234)] {
            let first = if template == Template::Rx { 0 } else { 1 };
            assert_eq!(rd_u(&mut d, a, first), 0, "{a:04X}h");
        }
        // F050h: axis A's module, none on axis B
        assert_eq!(rd(&mut d, 0xF050, 0).unwrap(), [2]);
        assert_eq!(
            rd_u(&mut d, 0xF050, 1),
            u64::from(module_ident(PdoLayout::Standard, 0))
        );
        assert_eq!(rd_u(&mut d, 0xF050, 2), 0);
        // what SDO Info reports as defaults
        let o = d.object(0x1601).unwrap();
        assert!(o.entries.iter().all(|e| e.default == 0), "1601h defaults");
        assert_eq!(d.object(0xF050).unwrap().entry(2).unwrap().default, 0);
    }
    // a mapping of axis A in channel 2 is no module of axis B
    let mut d = single();
    d.write(0x1601, 1, &0x6040_0010u32.to_le_bytes(), PREOP).unwrap();
    d.write(0x1601, 0, &[1], PREOP).unwrap();
    assert_eq!(d.get(0xF050, 2), Ok(0));
}

#[test]
fn e020_a_set_saved_by_one_variant_does_not_load_into_the_other() {
    let mut image = [0u8; PERSISTENT_IMAGE_BYTES];
    let mut one = single();
    one.write(0x1601, 1, &0x6040_0010u32.to_le_bytes(), PREOP)
        .unwrap();
    one.persistent_image(&mut image).unwrap();
    let mut two = DriveObjects::new();
    let before = two.clone();
    assert_eq!(two.load_persistent(&image), Err(ImageError::ForeignLayout));
    assert_eq!(two, before);
    // its own device loads it
    let mut again = single();
    assert_eq!(again.load_persistent(&image), Ok(()));
    assert_eq!(again.get(0x1601, 1), Ok(0x6040_0010));
    // and the double-axis set (1601h with axis B) does not load into the single-axis device
    DriveObjects::new().persistent_image(&mut image).unwrap();
    assert_eq!(single().load_persistent(&image), Err(ImageError::ForeignLayout));
    assert_ne!(Variant::Single.layout_hash(), Variant::Double.layout_hash());
}

#[test]
fn single_axis_defaults_come_back_with_a_restore() {
    let mut d = single();
    d.write(0x1601, 1, &0x6040_0010u32.to_le_bytes(), PREOP).unwrap();
    d.write(0x1601, 0, &[1], PREOP).unwrap();
    d.restore_defaults();
    assert_eq!(d, single(), "1011h gives the single-axis defaults");
    assert_eq!(d.mapping(0x1601).count(), 0);
}

/// The redeclared objects are the double-axis ones with only defaults, a
/// string value and notes changed: same index, name, code, level, value
/// kind, entries (subindex, name, type, access, range, saved).
#[test]
fn the_single_axis_objects_keep_the_declared_entries() {
    let mut last = 0;
    for r in single::OBJECTS.iter() {
        assert!(r.info.index > last, "sorted");
        last = r.info.index;
        let (_, o): (usize, &Object) = objects::find(r.info.index).unwrap();
        assert_eq!(r.info.name, o.info.name);
        assert_eq!(r.info.code, o.info.code);
        assert_eq!((r.level, r.axis, r.rx), (o.level, o.axis, o.rx));
        match (r.value, o.value) {
            (Value::Text(a), Value::Text(b)) => assert_eq!(a.len(), b.len()),
            (a, b) => assert_eq!(a, b),
        }
        assert_eq!(r.info.entries.len(), o.info.entries.len());
        let mut differ = 0;
        for (a, b) in r.info.entries.iter().zip(o.info.entries.iter()) {
            let what = std::format!("{:04X}h:{}", r.info.index, a.sub);
            assert_eq!(
                (
                    a.sub,
                    a.name,
                    a.data_type,
                    a.access,
                    a.min,
                    a.max,
                    a.unit,
                    a.persistent
                ),
                (
                    b.sub,
                    b.name,
                    b.data_type,
                    b.access,
                    b.min,
                    b.max,
                    b.unit,
                    b.persistent
                ),
                "{what}"
            );
            differ += usize::from(a.default != b.default);
        }
        // the "EtherCAT Rx" views are the double-axis ones
        assert_eq!(r.view(false).entries.len(), o.view(false).entries.len());
        let text = matches!(r.value, Value::Text(_));
        assert!(differ > 0 || text, "{:04X}h differs in something", r.info.index);
    }
    assert_eq!(Variant::Double.redeclared().len(), 0);
}

#[test]
fn the_double_axis_dictionary_is_the_default() {
    assert_eq!(DriveObjects::new(), DriveObjects::for_variant(Variant::Double));
    assert_eq!(Variant::default(), Variant::Double);
    assert_ne!(single(), DriveObjects::new());
}

/// E-148 (and the ESI modules of E-149): every layout on every axis the
/// device has is reported in F050h with that axis's own ident (axis B's
/// with [`AXIS_B_MODULE`]), the other axis unchanged; axis A's layout in
/// channel 2 is a user module there, not axis A's module; the single-axis
/// device refuses axis B's maps and keeps F050h:02 = 0.
#[test]
fn e148_every_layout_on_every_axis_has_its_own_module_ident() {
    let mut seen = Vec::new();
    for axis in 0..2u16 {
        for layout in PdoLayout::ALL {
            let mut d = DriveObjects::new();
            let other = d.module_ident(1 - axis);
            d.apply_axis_map(axis, layout).unwrap();
            let ident = module_ident(layout, axis);
            assert_eq!(d.module_ident(axis), ident, "{layout:?} on axis {axis}");
            assert_eq!(rd_u(&mut d, 0xF050, axis as u8 + 1), u64::from(ident));
            assert_eq!(d.module_ident(1 - axis), other, "the other axis unchanged");
            assert_eq!(ident & USER_MODULE, 0, "a system module");
            assert_eq!(ident & AXIS_B_MODULE != 0, axis == 1);
            assert_eq!(ident & !AXIS_B_MODULE, module_ident(layout, 0));
            seen.push(ident);
        }
    }
    seen.sort_unstable();
    seen.dedup();
    assert_eq!(seen.len(), 6, "six distinct system modules");
    // the defaults: the standard layout on both axes, each with its ident
    let mut d = DriveObjects::new();
    assert_eq!(
        rd_u(&mut d, 0xF050, 1),
        u64::from(module_ident(PdoLayout::Standard, 0))
    );
    assert_eq!(
        rd_u(&mut d, 0xF050, 2),
        u64::from(module_ident(PdoLayout::Standard, 1))
    );
    let declared = d.object(0xF050).unwrap();
    assert_eq!(
        declared.entry(2).unwrap().default,
        i64::from(module_ident(PdoLayout::Standard, 1))
    );
    // axis A's objects in channel 2: a user module of axis B
    let (rx, tx) = PdoLayout::Ip.entries();
    for (pdo, entries) in [(0x1601u16, rx), (0x1A01, tx)] {
        d.write(pdo, 0, &[0], PREOP).unwrap();
        for (sub, e) in (1u8..).zip(entries) {
            d.write(pdo, sub, &e.mapping_value().to_le_bytes(), PREOP)
                .unwrap();
        }
        d.write(pdo, 0, &[entries.len() as u8], PREOP).unwrap();
    }
    let user = d.module_ident(1);
    assert_eq!(user & USER_MODULE, USER_MODULE, "{user:08X}h");
    assert_eq!(rd_u(&mut d, 0xF050, 2), u64::from(user));
    // the single-axis device has no axis-B module
    let mut one = single();
    assert_eq!(
        one.apply_axis_map(1, PdoLayout::Standard),
        Err(SdoAbort::NOT_MAPPABLE)
    );
    assert_eq!(rd_u(&mut one, 0xF050, 2), 0);
    one.apply_axis_map(0, PdoLayout::Vl).unwrap();
    assert_eq!(
        rd_u(&mut one, 0xF050, 1),
        u64::from(module_ident(PdoLayout::Vl, 0))
    );
}
