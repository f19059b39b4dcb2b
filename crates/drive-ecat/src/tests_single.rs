//! The single-axis device on EtherCAT ([`DEVICE_SINGLE`], issue 20): its SII
//! and its runtime.

use super::*;
use crate::axis::{AxisCommand, AxisIo};
use crate::runtime::Drive;
use ecat::sii::{build_sii, find_category, sii_string, sii_word, EEPROM_BYTES};
use esc::sii::{category, word};
use nanos::Nanos;
use od::{CommState, Dictionary as _};
use std::vec::Vec;

type Flash = store::RamFlash<4096, 2>;

fn image(device: &Device) -> [u8; EEPROM_BYTES] {
    let mut img = [0u8; EEPROM_BYTES];
    build_sii(device, &mut img).unwrap();
    img
}

/// (index, SM) of each PDO of a PDO category.
fn pdos(data: &[u8]) -> Vec<(u16, u8)> {
    let mut out = Vec::new();
    let mut pos = 0;
    while pos + 8 <= data.len() {
        out.push((u16::from_le_bytes([data[pos], data[pos + 1]]), data[pos + 3]));
        pos += 8 + 8 * usize::from(data[pos + 2]);
    }
    out
}

#[test]
fn e005_e048_e049_the_single_axis_sii() {
    let img = image(&DEVICE_SINGLE);
    let w32 = |w| u32::from(sii_word(&img, w).unwrap()) | u32::from(sii_word(&img, w + 1).unwrap()) << 16;
    assert_eq!(w32(word::VENDOR_ID), VENDOR_ID);
    assert_eq!(w32(word::PRODUCT_CODE), PRODUCT_CODE_SINGLE);
    assert_eq!(w32(word::REVISION), SOFTWARE_BUILD);
    let strings = find_category(&img, category::STRINGS).unwrap();
    let general = find_category(&img, category::GENERAL).unwrap();
    assert_eq!(sii_string(strings, general[3]), Some(&b"SI6"[..]));
    assert_eq!(sii_string(strings, general[2]), Some(&b"SI6A061"[..]));
    assert_eq!(sii_string(strings, 1), Some(&b"SI6A061"[..]), "SOEM's name");
    // axis A's PDOs only, assigned to SM2/SM3
    let rx = find_category(&img, category::RXPDO).unwrap();
    let tx = find_category(&img, category::TXPDO).unwrap();
    assert_eq!(pdos(rx), [(0x1600, 2)]);
    assert_eq!(pdos(tx), [(0x1A00, 3)]);
    assert_eq!(
        (DEVICE_SINGLE.output_bytes(), DEVICE_SINGLE.input_bytes()),
        (23, 29)
    );
    // the rest of the description is the double-axis device's
    let double = image(&DEVICE);
    assert_eq!(img[..8], double[..8], "ESC configuration area");
    assert_ne!(w32(word::PRODUCT_CODE), PRODUCT_CODE);
    assert_eq!(device(Variant::Single), &DEVICE_SINGLE);
    assert_eq!(device(Variant::Double), &DEVICE);
}

/// The description and the dictionary of each variant agree: identity,
/// default PDOs and assignment, SM lengths.
#[test]
fn e005_e051_each_description_equals_its_dictionary() {
    for variant in Variant::ALL {
        let dev = device(variant);
        let mut d = DriveObjects::for_variant(variant);
        let mut buf = [0u8; 4];
        d.read(0x1018, 2, &mut buf, CommState::PreOp).unwrap();
        assert_eq!(u32::from_le_bytes(buf), dev.identity.product_code, "{variant:?}");
        let mut name = [0u8; 8];
        let n = d.read(0x1008, 0, &mut name, CommState::PreOp).unwrap();
        assert_eq!(&name[..n], dev.name.as_bytes());
        for pdo in dev.rx_pdos.iter().chain(dev.tx_pdos) {
            let mapped: Vec<u32> = d.mapping(pdo.index).collect();
            let declared: Vec<u32> = pdo.entries.iter().map(|e| e.mapping_value()).collect();
            assert_eq!(mapped, declared, "{variant:?} {:04X}h", pdo.index);
        }
        assert_eq!(d.assigned_pdos(0x1C12).collect::<Vec<_>>(), dev.rx_assign);
        assert_eq!(d.assigned_pdos(0x1C13).collect::<Vec<_>>(), dev.tx_assign);
        assert_eq!(
            d.process_data_bytes(),
            Some((dev.output_bytes(), dev.input_bytes()))
        );
    }
    // channel 2 is in the single-axis description neither as a PDO nor mapped
    assert!(DEVICE_SINGLE.pdo(0x1601).is_none() && DEVICE_SINGLE.pdo(0x1A01).is_none());
    let d = DriveObjects::for_variant(Variant::Single);
    assert_eq!(d.mapping(0x1601).count() + d.mapping(0x1A01).count(), 0);
}

/// Axis A runs, axis B stays idle: its objects (set locally, the bus cannot
/// reach them) drive nothing, its command is off, event 52 faults axis A
/// only (one EMCY).
#[test]
fn e051_the_single_axis_drive_runs_axis_a_only() {
    let mut drive = Drive::new_single_axis(Flash::new());
    assert_eq!(drive.variant(), Variant::Single);
    assert_eq!(drive.slave().device(), &DEVICE_SINGLE);
    let io = [AxisIo::ready(0), AxisIo::ready(0)];
    let mut now = Nanos::ZERO;
    let mut last = [AxisCommand::OFF; 2];
    let before_b = drive.objects().get(0x6841, 0).unwrap();
    for cw in [0x0006, 0x0007, 0x000F] {
        for index in [0x6040, 0x6840] {
            drive.objects_mut().set(index, 0, cw).unwrap();
        }
        for _ in 0..5 {
            last = drive.control_cycle(now, &io);
            now += Nanos::from_ms(1);
        }
    }
    assert_eq!(drive.objects().get(0x6041, 0).unwrap() & 0x6F, 0x27, "A enabled");
    assert!(last[0].power_stage);
    assert_eq!(last[1], AxisCommand::OFF, "B idle");
    assert_eq!(
        drive.objects().get(0x6841, 0),
        Ok(before_b),
        "B's objects untouched"
    );
    // event 52: axis A faults, B does not
    drive.raise_event52(6);
    for _ in 0..50 {
        last = drive.control_cycle(now, &io);
        now += Nanos::from_ms(1);
    }
    assert_eq!(drive.objects().get(0x6041, 0).unwrap() & 0x4F, 0x08, "A in Fault");
    assert_eq!(last[1], AxisCommand::OFF);
    assert_eq!(drive.axes()[1].error_register(), 0, "B has no fault");
    // the double-axis drive runs both
    let mut two = Drive::new(Flash::new());
    for index in [0x6040, 0x6840] {
        two.objects_mut().set(index, 0, 0x0006).unwrap();
    }
    for _ in 0..5 {
        two.control_cycle(now, &io);
    }
    assert_eq!(two.objects().get(0x6841, 0).unwrap() & 0x6F, 0x21, "B ready");
}
