use super::*;
use ecat::sii::{build_sii, categories, find_category, records, sii_string, sii_word, EEPROM_BYTES};
use esc::sii::{category, config_checksum, word};
use od::{Dictionary as _, SdoAbort};

fn image() -> ([u8; EEPROM_BYTES], usize) {
    let mut img = [0u8; EEPROM_BYTES];
    let n = build_sii(&DEVICE, &mut img).unwrap();
    (img, n)
}

fn u16_at(b: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([b[at], b[at + 1]])
}

#[test]
fn e005_identity_in_sii() {
    let (img, _) = image();
    let w32 = |w| u32::from(sii_word(&img, w).unwrap()) | u32::from(sii_word(&img, w + 1).unwrap()) << 16;
    assert_eq!(w32(word::VENDOR_ID), 0xB9);
    assert_eq!(w32(word::PRODUCT_CODE), PRODUCT_CODE);
    assert_eq!(w32(word::REVISION), SOFTWARE_BUILD);
    assert_eq!(w32(word::SERIAL), 0);
    assert_eq!(
        sii_word(&img, word::CHECKSUM),
        Some(u16::from(config_checksum(&img[..14])))
    );
    let strings = find_category(&img, category::STRINGS).unwrap();
    let general = find_category(&img, category::GENERAL).unwrap();
    assert_eq!(sii_string(strings, general[3]), Some(&b"SC6"[..]));
    assert_eq!(sii_string(strings, general[2]), Some(&b"SC6A062"[..]));
    assert_eq!(sii_string(strings, general[0]), Some(&b"Drives"[..]));
    // string 1 is the device's type, as in vendor SIIs: SOEM names the
    // slave after it
    assert_eq!(sii_string(strings, 1), Some(&b"SC6A062"[..]));
    assert_eq!(general[2], 1, "order index");
    // two MII ports (E-001)
    assert_eq!(u16_at(general, 16), 0x0011);
}

#[test]
fn e003_mailbox_and_protocols_in_sii() {
    let (img, _) = image();
    for base in [word::BOOT_RX_MAILBOX_OFFSET, word::STD_RX_MAILBOX_OFFSET] {
        assert_eq!(sii_word(&img, base), Some(0x1000));
        assert_eq!(sii_word(&img, base + 1), Some(256));
        assert_eq!(sii_word(&img, base + 2), Some(0x1100));
        assert_eq!(sii_word(&img, base + 3), Some(256));
    }
    // CoE and EoE (E-003), and FoE for the firmware download (issue 8)
    assert_eq!(sii_word(&img, word::MAILBOX_PROTOCOL), Some(0x000E));
    let general = find_category(&img, category::GENERAL).unwrap();
    assert_eq!(general[5] & 1, 1, "CoE SDO");
    assert_eq!(general[7], 1, "EoE");
    assert_eq!(general[6], 1, "FoE");
}

#[test]
fn e055_sync_manager_and_fmmu_categories() {
    let (img, _) = image();
    let sm = find_category(&img, category::SYNC_MANAGER).unwrap();
    let sms: heapless::Vec<&[u8], 4> = records(sm, 8).collect();
    assert_eq!(sms.len(), 4);
    assert_eq!(sms[0], &[0x00, 0x10, 0x00, 0x01, 0x26, 0, 1, 1]);
    assert_eq!(sms[1], &[0x00, 0x11, 0x00, 0x01, 0x22, 0, 1, 2]);
    assert_eq!(sms[2], &[0x00, 0x12, 0, 0, 0x64, 0, 1, 3]);
    assert_eq!(sms[3], &[0x00, 0x1A, 0, 0, 0x20, 0, 1, 4]);
    assert_eq!(find_category(&img, category::FMMU), Some(&[1, 2, 3, 0][..]));
}

/// Walks a PDO category: (index, SM, bit total) per PDO.
fn pdos(data: &[u8]) -> heapless::Vec<(u16, u8, u32), 4> {
    let mut out = heapless::Vec::new();
    let mut pos = 0;
    while pos + 8 <= data.len() {
        let n = usize::from(data[pos + 2]);
        let bits = (0..n).map(|i| u32::from(data[pos + 8 + 8 * i + 5])).sum();
        out.push((u16_at(data, pos), data[pos + 3], bits)).unwrap();
        pos += 8 + 8 * n;
    }
    assert_eq!(pos, data.len());
    out
}

#[test]
fn e048_e049_pdo_categories_and_sizes() {
    assert_eq!(DEVICE.output_bytes(), 23);
    assert_eq!(DEVICE.input_bytes(), 29);
    let (img, _) = image();
    let rx = find_category(&img, category::RXPDO).unwrap();
    let tx = find_category(&img, category::TXPDO).unwrap();
    // 1600h on SM2, 1601h not assigned by default
    assert_eq!(pdos(rx).as_slice(), &[(0x1600, 2, 184), (0x1601, 0xFF, 184)]);
    assert_eq!(pdos(tx).as_slice(), &[(0x1A00, 3, 232), (0x1A01, 0xFF, 232)]);
    // first TxPDO entry: 6041h:00, UINT16, 16 bit
    assert_eq!(&tx[8..10], &[0x41, 0x60]);
    assert_eq!(tx[8 + 4], 0x06);
    assert_eq!(tx[8 + 5], 16);
}

#[test]
fn e015_axis_b_pdo_entries_offset() {
    let b: heapless::Vec<u16, 10> = TX_B_ENTRIES.iter().map(|e| e.index).collect();
    assert_eq!(
        b.as_slice(),
        &[0x6841, 0x6861, 0x6864, 0x686C, 0x6877, 0x68F4, 0x68FD, 0x68E4, 0xA8C9, 0xA043]
    );
    assert_eq!(TX_A_ENTRIES[8].index, 0x28C9);
    assert_eq!(TX_A_ENTRIES[9].index, 0x2043);
    assert_eq!(RX_B_ENTRIES[0].index, 0x6840);
}

/// E-108: the SII's DC category has three op modes, "DC enabled (SYNC0)"
/// (assign-activate 0300h) first, the default a configuration tool offers.
#[test]
fn e108_dc_category_lists_sync0_first_of_three_op_modes() {
    let (img, _) = image();
    let dc = find_category(&img, category::DC).unwrap();
    let modes: heapless::Vec<&[u8], 3> = records(dc, 24).collect();
    assert_eq!(modes.len(), 3);
    assert_eq!(u16_at(modes[0], 14), 0x0300);
    assert_eq!(u16_at(modes[1], 14), 0);
    assert_eq!(u16_at(modes[2], 14), 0);
    let strings = find_category(&img, category::STRINGS).unwrap();
    assert_eq!(sii_string(strings, modes[0][18]), Some(&b"DC"[..]));
    assert!(categories(&img).any(|c| c.kind == category::DC));
}

fn read(index: u16, sub: u8) -> Result<heapless::Vec<u8, 64>, SdoAbort> {
    let mut buf = [0u8; 64];
    let n = DriveObjects::new().read(index, sub, &mut buf, od::CommState::PreOp)?;
    Ok(heapless::Vec::from_slice(&buf[..n]).unwrap())
}

fn read_u32(index: u16, sub: u8) -> u32 {
    let v = read(index, sub).unwrap();
    let mut b = [0u8; 4];
    b[..v.len()].copy_from_slice(&v);
    u32::from_le_bytes(b)
}

#[test]
fn e004_e005_identity_objects() {
    assert_eq!(read_u32(0x1000, 0), 0x0002_0192);
    assert_eq!(read(0x1018, 0).unwrap().as_slice(), &[4]);
    assert_eq!(read_u32(0x1018, 1), 0xB9);
    assert_eq!(read_u32(0x1018, 2), PRODUCT_CODE);
    assert_eq!(read_u32(0x1018, 3), SOFTWARE_BUILD);
    assert_eq!(read_u32(0x1018, 4), 0);
    assert_eq!(read(0x1018, 5), Err(SdoAbort::NO_SUBINDEX));
    assert_eq!(read(0x1008, 0).unwrap().as_slice(), b"SC6");
    assert_eq!(read(0x1234, 0), Err(SdoAbort::NO_OBJECT));
}

#[test]
fn e055_sm_communication_types() {
    assert_eq!(read(0x1C00, 0).unwrap().as_slice(), &[4]);
    for s in 1..=4u8 {
        assert_eq!(read(0x1C00, s).unwrap().as_slice(), &[s]);
    }
    assert_eq!(read(0x1C00, 5), Err(SdoAbort::NO_SUBINDEX));
}

/// What ethercrab 0.7.1's `configure_pdos_coe` does: 1C12h:00 (u8), subs
/// 1..=n (u16), each PDO's :00 (u8) and :01.. (u32 mapping), summing bit lengths.
fn ethercrab_bits(assign: u16) -> u32 {
    let n = read(assign, 0).unwrap();
    assert_eq!(n.len(), 1);
    let mut bits = 0;
    for i in 1..=n[0] {
        let pdo = read(assign, i).unwrap();
        assert_eq!(pdo.len(), 2);
        let pdo = u16::from_le_bytes([pdo[0], pdo[1]]);
        let m = read(pdo, 0).unwrap();
        assert_eq!(m.len(), 1);
        for s in 1..=m[0] {
            let v = read(pdo, s).unwrap();
            assert_eq!(v.len(), 4);
            bits += u32::from(v[0]);
        }
    }
    bits
}

#[test]
fn e054_pdo_assignment_as_ethercrab_reads_it() {
    assert_eq!(ethercrab_bits(0x1C12), 23 * 8);
    assert_eq!(ethercrab_bits(0x1C13), 29 * 8);
    assert_eq!(read_u32(0x1C12, 1), 0x1600);
    assert_eq!(read_u32(0x1C12, 2), 0);
    assert_eq!(read_u32(0x1C13, 1), 0x1A00);
    assert_eq!(read(0x1C13, 5), Err(SdoAbort::NO_SUBINDEX));
}

#[test]
fn e048_e050_mapping_objects() {
    assert_eq!(read_u32(0x1600, 1), 0x6040_0010);
    assert_eq!(read_u32(0x1600, 8), 0x60FE_0120);
    assert_eq!(read_u32(0x1600, 9), 0);
    assert_eq!(read_u32(0x1A00, 9), 0x28C9_0010);
    assert_eq!(read_u32(0x1A01, 10), 0xA043_0010);
    // sub 0 = number of mapped entries (decision, see docs/conformance.md)
    assert_eq!(read(0x1600, 0).unwrap().as_slice(), &[8]);
    assert_eq!(read(0x1A01, 0).unwrap().as_slice(), &[10]);
    for pdo in [0x1602, 0x1603, 0x1A02, 0x1A03] {
        assert_eq!(read(pdo, 0).unwrap().as_slice(), &[0]);
        assert_eq!(read_u32(pdo, 24), 0);
    }
    assert_eq!(read(0x1600, 25), Err(SdoAbort::NO_SUBINDEX));
    assert_eq!(read(0x1604, 0), Err(SdoAbort::NO_OBJECT));
}

#[test]
fn writes_to_missing_and_read_only_objects() {
    let mut d = DriveObjects::new();
    assert_eq!(
        d.write(0x1018, 1, &[0; 4], od::CommState::PreOp),
        Err(SdoAbort::READ_ONLY)
    );
    assert_eq!(
        d.write(0x5000, 0, &[0], od::CommState::PreOp),
        Err(SdoAbort::NO_OBJECT)
    );
}

/// The SII's revision is the dictionary's 1018h:03 (E-005).
#[test]
fn e005_sii_revision_equals_1018_03() {
    let mut d = DriveObjects::new();
    let mut buf = [0u8; 4];
    let n = d.read(0x1018, 3, &mut buf, od::CommState::PreOp).unwrap();
    assert_eq!(n, 4);
    assert_eq!(DEVICE.identity.revision, u32::from_le_bytes(buf), "SII = OD");
}

#[test]
fn pdo_maps_of_device_equal_od_defaults() {
    let mut d = DriveObjects::new();
    for pdo in DEVICE.rx_pdos.iter().chain(DEVICE.tx_pdos) {
        assert_eq!(rd(&mut d, pdo.index, 0), [pdo.entries.len() as u8]);
        for (i, e) in pdo.entries.iter().enumerate() {
            assert_eq!(rd_u(&mut d, pdo.index, i as u8 + 1), u64::from(e.mapping_value()));
        }
    }
    assert_eq!(
        d.assigned_pdos(0x1C12).collect::<std::vec::Vec<_>>(),
        DEVICE.rx_assign
    );
    assert_eq!(
        d.assigned_pdos(0x1C13).collect::<std::vec::Vec<_>>(),
        DEVICE.tx_assign
    );
    assert_eq!(
        d.process_data_bytes(),
        Some((DEVICE.output_bytes(), DEVICE.input_bytes()))
    );
    // every default mapping entry is valid: re-enabling each PDO passes the checks
    for pdo in DEVICE.rx_pdos.iter().chain(DEVICE.tx_pdos) {
        let n = pdo.entries.len() as u32;
        wr(&mut d, pdo.index, 0, 0);
        wr(&mut d, pdo.index, 0, n);
    }
}

fn rd(d: &mut DriveObjects, index: u16, sub: u8) -> std::vec::Vec<u8> {
    let mut buf = [0u8; 64];
    let n = d.read(index, sub, &mut buf, od::CommState::PreOp).unwrap();
    buf[..n].to_vec()
}

fn rd_u(d: &mut DriveObjects, index: u16, sub: u8) -> u64 {
    rd(d, index, sub)
        .iter()
        .rev()
        .fold(0u64, |v, &b| (v << 8) | u64::from(b))
}

fn wr(d: &mut DriveObjects, index: u16, sub: u8, value: u32) {
    d.write(index, sub, &[value as u8], od::CommState::PreOp).unwrap();
}

/// E-143: besides CoE, the UDP parameter service (the dictionary of
/// `Drive::with_eoe`) and `Drive::read_object` are the parameter channel:
/// with A213 = (0, 1) and A310 = 2 they show and take 6081h in inc/s while
/// the dictionary keeps the process data's 0.01 inc/s.
#[test]
fn e143_udp_parameter_service_and_read_object_are_the_parameter_channel() {
    use crate::params::{A213, A310};
    use od::CommState;
    let mut drive = crate::runtime::Drive::new(store::RamFlash::<4096, 2>::new());
    let o = drive.objects_mut();
    o.write(A213, 1, &[0], CommState::PreOp).unwrap();
    o.write(A310, 0, &[2], CommState::PreOp).unwrap();
    o.set(0x6081, 0, 123_456).unwrap();
    let mut b = [0u8; 4];
    drive.read_object(0x6081, 0, &mut b, CommState::PreOp).unwrap();
    assert_eq!(u32::from_le_bytes(b), 1235);
    let (read, wrote) = drive.with_eoe(|_, dict, state| {
        let mut b = [0u8; 4];
        let read = dict.read(0x6081, 0, &mut b, state).map(|_| u32::from_le_bytes(b));
        (read, dict.write(0x6081, 0, &1000u32.to_le_bytes(), state))
    });
    assert_eq!((read, wrote), (Ok(1235), Ok(())));
    assert_eq!(drive.objects().get(0x6081, 0), Ok(100_000));
}
