use super::*;
use crate::PdoLayout;
use od::{CommState, Dictionary};
use std::vec::Vec;

/// Mapping entry: index << 16 | sub << 8 | bit length.
const fn m(index: u16, sub: u8, bits: u8) -> u32 {
    (index as u32) << 16 | (sub as u32) << 8 | bits as u32
}

/// Writes `entries` into `pdo` as a startup list would (Pre-Op).
fn map(objects: &mut DriveObjects, pdo: u16, entries: &[u32]) {
    let items: Vec<_> = entries.iter().map(|e| e.to_le_bytes()).collect();
    write_list(objects, pdo, &items);
}

fn assign(objects: &mut DriveObjects, index: u16, pdos: &[u16]) {
    let items: Vec<_> = pdos.iter().map(|p| p.to_le_bytes()).collect();
    write_list(objects, index, &items);
}

/// A list object as a startup list writes it (Pre-Op): count 0, the
/// entries from sub-index 1, then the count.
fn write_list<const N: usize>(objects: &mut DriveObjects, index: u16, items: &[[u8; N]]) {
    objects.write(index, 0, &[0], CommState::PreOp).unwrap();
    for (sub, item) in (1u8..).zip(items) {
        objects.write(index, sub, item, CommState::PreOp).unwrap();
    }
    objects
        .write(index, 0, &[items.len() as u8], CommState::PreOp)
        .unwrap();
}

#[test]
fn default_layout_offsets_match_the_spec() {
    let objects = DriveObjects::new();
    let img = PdoImage::compile(&objects).unwrap();
    assert_eq!((img.rx().bytes(), img.tx().bytes()), (23, 29));
    assert_eq!(
        (objects.process_data_bytes()),
        Some((img.rx().bytes(), img.tx().bytes()))
    );
    let rx: Vec<_> = img
        .rx()
        .entries()
        .iter()
        .map(|e| (e.byte_offset(), e.index, e.bits))
        .collect();
    assert_eq!(
        rx,
        [
            (0, 0x6040, 16),
            (2, 0x6060, 8),
            (3, 0x607A, 32),
            (7, 0x60FF, 32),
            (11, 0x60B1, 32),
            (15, 0x60B2, 16),
            (17, 0x6071, 16),
            (19, 0x60FE, 32),
        ]
    );
    assert_eq!(img.tx().entries()[2].index, 0x6064);
    assert_eq!(img.tx().entries()[2].byte_offset(), 3);
    assert_eq!(img.tx().entries()[9].byte_offset(), 27);
}

#[test]
fn outputs_decode_little_endian_with_sign() {
    let mut objects = DriveObjects::new();
    let img = PdoImage::compile(&objects).unwrap();
    let mut rx = [0u8; 23];
    rx[0..2].copy_from_slice(&0x000Fu16.to_le_bytes());
    rx[2] = (-1i8) as u8;
    rx[3..7].copy_from_slice(&(-123_456i32).to_le_bytes());
    rx[7..11].copy_from_slice(&0x1234_5678i32.to_le_bytes());
    rx[17..19].copy_from_slice(&(-300i16).to_le_bytes());
    rx[19..23].copy_from_slice(&0xDEAD_BEEFu32.to_le_bytes());
    assert_eq!(img.apply_outputs(&rx, &mut objects), 8);
    assert_eq!(objects.get(0x6040, 0), Ok(0x000F));
    assert_eq!(objects.get(0x6060, 0), Ok(-1));
    assert_eq!(objects.get(0x607A, 0), Ok(-123_456));
    assert_eq!(objects.get(0x60FF, 0), Ok(0x1234_5678));
    assert_eq!(objects.get(0x6071, 0), Ok(-300));
    assert_eq!(objects.get(0x60FE, 1), Ok(0xDEAD_BEEF));

    // a short image: the entries it covers only
    let mut short = DriveObjects::new();
    assert_eq!(img.apply_outputs(&rx[..7], &mut short), 3);
    assert_eq!(short.get(0x607A, 0), Ok(-123_456));
    assert_eq!(short.get(0x60FF, 0), Ok(0));

    img.restore_rx_defaults(&mut objects);
    for (index, sub) in [(0x6040, 0), (0x6060, 0), (0x607A, 0), (0x6071, 0), (0x60FE, 1)] {
        let default = find(index).unwrap().1.info.entry(sub).unwrap().default;
        assert_eq!(objects.get(index, sub), Ok(default), "{index:04X}h");
    }
}

#[test]
fn leaving_op_restores_set_points_and_captured_parameters() {
    let mut objects = DriveObjects::new();
    objects.set(0x6060, 0, 9).unwrap(); // a saved/configured A541 (csv)
    objects.set(0x6040, 0, 0x0006).unwrap(); // an SDO-written controlword
    let mut img = PdoImage::compile(&objects).unwrap();
    img.capture_fallbacks(&objects);
    let mut rx = [0u8; 23];
    rx[0] = 0x0F;
    rx[2] = 1;
    rx[3] = 5;
    img.apply_outputs(&rx, &mut objects);
    assert_eq!(objects.get(0x6060, 0), Ok(1));
    img.restore_rx_defaults(&mut objects);
    assert_eq!(objects.get(0x6060, 0), Ok(9), "parameter: the value before Op");
    assert_eq!(objects.get(0x6040, 0), Ok(0), "set-point: the declared default");
    assert_eq!(objects.get(0x607A, 0), Ok(0));
}

#[test]
fn inputs_encode_little_endian_with_sign() {
    let mut objects = DriveObjects::new();
    let img = PdoImage::compile(&objects).unwrap();
    objects.set(0x6041, 0, 0x0237).unwrap();
    objects.set(0x6061, 0, -1).unwrap();
    objects.set(0x6064, 0, -2).unwrap();
    objects.set(0x6077, 0, -1000).unwrap();
    objects.set(0x60FD, 0, 0x8000_0001).unwrap();
    let mut tx = [0xAAu8; 29];
    img.fill_inputs(&objects, &mut tx);
    assert_eq!(&tx[0..2], &[0x37, 0x02]);
    assert_eq!(tx[2], 0xFF);
    assert_eq!(&tx[3..7], &[0xFE, 0xFF, 0xFF, 0xFF]);
    assert_eq!(&tx[11..13], &(-1000i16).to_le_bytes());
    assert_eq!(&tx[17..21], &[0x01, 0, 0, 0x80]);
    // a short buffer: no panic, the entries that fit
    let mut short = [0u8; 5];
    img.fill_inputs(&objects, &mut short);
    assert_eq!(short, [0x37, 0x02, 0xFF, 0, 0]);
}

/// E-034/E-032: the direct slot copy of byte-aligned integer entries
/// decodes and encodes exactly what the copy through the dictionary
/// does, on every layout, and it is the path the default layouts take.
#[test]
fn e034_slot_copy_equals_the_dictionary_copy() {
    for layout in [PdoLayout::Standard, PdoLayout::Ip, PdoLayout::Vl] {
        let mut objects = DriveObjects::new();
        objects.apply_map(layout).unwrap();
        let img = PdoImage::compile(&objects).unwrap();
        let mut slow = img.clone();
        for e in slow.rx.entries.iter_mut().chain(slow.tx.entries.iter_mut()) {
            e.slot = None;
        }
        // no copy program either: every entry through the dictionary
        (slow.rx.program, slow.tx.program) = (Program::NONE, Program::NONE);
        let with_slots = img
            .rx
            .entries()
            .iter()
            .chain(img.tx.entries())
            .filter(|e| e.slot.is_some());
        assert_eq!(
            with_slots.count(),
            img.rx.entries().len() + img.tx.entries().len(),
            "{layout:?}"
        );
        let rx: Vec<u8> = (0..img.rx.bytes()).map(|i| (i * 37 + 201) as u8).collect();
        let (mut a, mut b) = (objects.clone(), objects.clone());
        assert_eq!(img.apply_outputs(&rx, &mut a), slow.apply_outputs(&rx, &mut b));
        assert_eq!(a, b, "{layout:?}");
        a.set(0x6041, 0, 0x1637).unwrap();
        a.set(0x6064, 0, -123_456).unwrap();
        a.set(0x6044, 0, -77).unwrap();
        let (mut fast_tx, mut slow_tx) = (
            std::vec![0x55u8; img.tx.bytes()],
            std::vec![0xAAu8; img.tx.bytes()],
        );
        img.fill_inputs(&a, &mut fast_tx);
        slow.fill_inputs(&a, &mut slow_tx);
        assert_eq!(fast_tx, slow_tx, "{layout:?}");
    }
}

/// Runs `img`'s RxPDO copy program and its per-entry copy on two copies
/// of `objects` with each of `frames` in turn (whole, longer and cut
/// short), then its TxPDO program and per-entry copy with buffers of
/// several lengths, and asserts that they agree: the count, the objects,
/// the configuration generation, the bytes. Returns the dictionary the
/// program wrote.
fn program_equals_entry_copy(
    img: &PdoImage,
    objects: &DriveObjects,
    frames: &[Vec<u8>],
    label: &str,
) -> DriveObjects {
    let (mut a, mut b) = (objects.clone(), objects.clone());
    for (k, frame) in frames.iter().enumerate() {
        let n = img.rx.apply_each(frame, &mut b);
        assert_eq!(img.apply_outputs(frame, &mut a), n, "{label}: frame {k}");
        assert_eq!(a, b, "{label}: frame {k}");
        assert_eq!(a.config_generation(), b.config_generation(), "{label}: frame {k}");
    }
    // every TxPDO entry a distinct value (strings included)
    for (k, e) in img.tx.entries().iter().enumerate() {
        let raw: Vec<u8> = (0..e.info.data_type().bytes())
            .map(|i| (k * 41 + i * 7 + 3) as u8)
            .collect();
        let _ = b.set_bytes(e.index, e.sub, &raw);
    }
    let bytes = img.tx.bytes();
    for len in [bytes, bytes + 2, bytes.saturating_sub(1), bytes / 2, 0] {
        let (mut fast, mut slow) = (std::vec![0x55u8; len], std::vec![0xAAu8; len]);
        img.fill_inputs(&b, &mut fast);
        img.tx.fill_each(&b, &mut slow);
        assert_eq!(fast, slow, "{label}: {len} of {bytes} TxPDO bytes");
    }
    a
}

/// An RxPDO image of `bytes` bytes, byte `i` = `i * 37 + seed`.
fn frame(bytes: usize, seed: usize) -> Vec<u8> {
    (0..bytes).map(|i| (i * 37 + seed) as u8).collect()
}

/// E-034/E-032: the copy program decodes and encodes exactly what the
/// per-entry copy does (the entries, gaps, entries off byte boundaries,
/// strings, configuration entries, byte slices shorter or longer than
/// the image), and a configuration entry written with the value it holds
/// is no configuration change, with another value it is.
#[test]
fn e034_copy_program_equals_the_entry_copy() {
    // the layouts, both channels of each direction (the csp run of the
    // end-to-end test): all entries in the program
    for layout in [PdoLayout::Standard, PdoLayout::Ip, PdoLayout::Vl] {
        let mut objects = DriveObjects::new();
        objects.apply_map(layout).unwrap();
        assign(&mut objects, 0x1C12, &[0x1600, 0x1601]);
        assign(&mut objects, 0x1C13, &[0x1A00, 0x1A01]);
        let img = PdoImage::compile(&objects).unwrap();
        for ch in [&img.rx, &img.tx] {
            let p = &ch.program;
            assert!(p.usable() && !p.others, "{layout:?}");
            assert_eq!(p.entries, ch.entries().len(), "{layout:?}");
            assert!((0..GROUPS).map(|g| p.group(g).unwrap().len()).sum::<usize>() <= ch.entries().len());
        }
        assert_eq!(img.tx.program.whole_len, img.tx.bytes(), "{layout:?}: no zeroing");
        let rx = img.rx.bytes();
        let frames = [frame(rx, 201), frame(rx, 201), frame(rx, 7), frame(rx - 3, 90)];
        program_equals_entry_copy(&img, &objects, &frames, &std::format!("{layout:?}"));
    }
    // standard: each axis' block of the RAM image holds the layout's values
    // in its order (objects::layout), so axis A's TxPDO is two runs,
    // 6041h..60FDh (21 bytes: 8 + 8 + 4 + 1) and 60E4h:01..A67 (8 bytes;
    // 60E4h's count lies between them in RAM): 5 copies for its 10 entries;
    // both axes' (axis B's in its own block, the same runs) 10 copies for 20
    // entries, and the RxPDO's 16 entries 10 copies (6040h; 607Ah..6071h in
    // two of 8; 6060h; 60FEh:01 on its own, 60FEh's count lying before it in
    // RAM; no configuration entry, C-130)
    let mut objects = DriveObjects::new();
    objects.apply_map(PdoLayout::Standard).unwrap();
    let ops =
        |p: &Program| -> std::vec::Vec<usize> { (0..GROUPS).map(|g| p.group(g).unwrap().len()).collect() };
    let img = PdoImage::compile(&objects).unwrap();
    assert_eq!(ops(&img.tx.program), [1, 0, 1, 3, 0]);
    assign(&mut objects, 0x1C12, &[0x1600, 0x1601]);
    assign(&mut objects, 0x1C13, &[0x1A00, 0x1A01]);
    let img = PdoImage::compile(&objects).unwrap();
    assert_eq!(ops(&img.tx.program), [2, 0, 2, 6, 0]);
    assert_eq!(ops(&img.rx.program), [2, 2, 2, 4, 0]);
    assert_eq!((img.tx.entries().len(), img.rx.entries().len()), (20, 16));

    // gaps, configuration entries of 1, 2 and 4 bytes (6065h, 60C2h:02,
    // 605Ah; set-points 6060h and 60FEh:01 of 1601h), an entry off byte boundaries,
    // a string, and adjacent entries (60B1h, 60B2h)
    let mut objects = DriveObjects::new();
    map(
        &mut objects,
        0x1600,
        &[
            m(0x6040, 0, 16),
            m(0, 0, 8),
            m(0x6065, 0, 32),
            m(0x60C2, 2, 8),
            m(0x605A, 0, 16),
            m(0, 0, 4),
            m(0x6071, 0, 16),
            m(0, 0, 4),
            m(0x607A, 0, 32),
            m(0x60B1, 0, 32),
            m(0x60B2, 0, 16),
        ],
    );
    map(
        &mut objects,
        0x1601,
        &[m(0x6840, 0, 16), m(0x6060, 0, 8), m(0x60FE, 1, 32)],
    );
    assign(&mut objects, 0x1C12, &[0x1600, 0x1601]);
    // E72 (STR16) through the runtime (no mapping check)
    let e72 = crate::parameter_index(4, 72);
    objects.set(0x1601, 4, i64::from(m(e72, 0, 128))).unwrap();
    objects.set(0x1601, 0, 4).unwrap();
    map(
        &mut objects,
        0x1A00,
        &[
            m(0x6041, 0, 16),
            m(0x10F3, 4, 1),
            m(0, 0, 7),
            m(0x6061, 0, 8),
            m(0x6064, 0, 32),
            m(0x60F4, 0, 32),
            m(0x60FD, 0, 32),
            m(0, 0, 16),
            m(0x6077, 0, 16),
        ],
    );
    objects.set(0x1A00, 10, i64::from(m(e72, 0, 128))).unwrap();
    objects.set(0x1A00, 0, 10).unwrap();
    let img = PdoImage::compile(&objects).unwrap();
    let p = &img.rx.program;
    assert!(p.usable() && p.others && img.tx.program.whole_len == usize::MAX);
    let config_ops = p
        .group(CONFIG)
        .unwrap()
        .iter()
        .map(|op| op.width())
        .collect::<Vec<_>>();
    assert_eq!(
        config_ops,
        [4, 1, 2],
        "6065h, 60C2h:02, 605Ah (60FEh:01 is none, C-130)"
    );
    let rx = img.rx.bytes();
    assert_eq!(rx, 2 + 1 + 4 + 1 + 2 + 3 + 4 + 4 + 2 + 2 + 1 + 4 + 16);
    let (first, other) = (frame(rx, 201), frame(rx, 202));
    let frames = [
        first.clone(),
        first.clone(),
        other.clone(),
        other[..rx - 1].to_vec(),
        first[..13].to_vec(),
        [other.as_slice(), &[1, 2, 3]].concat(),
    ];
    program_equals_entry_copy(&img, &objects, &frames, "mixed");
    // the configuration generation: the same values again are no change,
    // other values of the four configuration entries (the three above and
    // the string E72) are four
    let mut a = objects.clone();
    img.apply_outputs(&first, &mut a);
    let generation = a.config_generation();
    assert_eq!(img.apply_outputs(&first, &mut a), 12);
    assert_eq!(a.config_generation(), generation, "same values");
    img.apply_outputs(&other, &mut a);
    assert_eq!(a.config_generation(), generation.wrapping_add(4), "other values");
    assert_eq!(
        a.get(0x6065, 0),
        Ok(i64::from(u32::from_le_bytes(other[3..7].try_into().unwrap())))
    );

    // 6040h twice: the later one wins, so no program (mapping order)
    let mut objects = DriveObjects::new();
    map(
        &mut objects,
        0x1600,
        &[m(0x6040, 0, 16), m(0x607A, 0, 32), m(0x6040, 0, 16)],
    );
    let img = PdoImage::compile(&objects).unwrap();
    assert!(!img.rx.program.usable() && img.tx.program.usable());
    let a = program_equals_entry_copy(&img, &objects, &[frame(8, 1)], "twice");
    assert_eq!(
        a.get(0x6040, 0),
        Ok(i64::from(u16::from_le_bytes([6 * 37 + 1, (7 * 37 + 1) as u8])))
    );
}

/// E-034 with issue 36: the standard layout of axis A alone and of both
/// axes is recognised in both directions, and its straight-line copy moves
/// what the per-entry copy does (the objects after RxPDO frames of several
/// lengths, the TxPDO bytes); the same PDOs in another order, the standard
/// PDO with an entry more, or one entry of another object are not
/// recognised and copy through the program, as before.
#[test]
fn e034_standard_layout_copies_straight_as_the_entry_copy() {
    let cases: [(&[u16], &[u16], u8); 4] = [
        (&[0x1600], &[0x1A00], 1),
        (&[0x1600, 0x1601], &[0x1A00, 0x1A01], 2),
        (&[0x1601, 0x1600], &[0x1A01, 0x1A00], 0),
        (&[0x1601], &[0x1A01], 0),
    ];
    for (rx_pdos, tx_pdos, axes) in cases {
        let mut objects = DriveObjects::new();
        objects.apply_map(PdoLayout::Standard).unwrap();
        assign(&mut objects, 0x1C12, rx_pdos);
        assign(&mut objects, 0x1C13, tx_pdos);
        let img = PdoImage::compile(&objects).unwrap();
        let label = std::format!("{rx_pdos:04X?}");
        assert_eq!(
            (img.rx.program.standard, img.tx.program.standard),
            (axes, axes),
            "{label}"
        );
        let rx = img.rx.bytes();
        let frames = [frame(rx, 3), frame(rx, 90), frame(rx + 5, 11), frame(rx - 1, 4)];
        program_equals_entry_copy(&img, &objects, &frames, &label);
    }
    // the standard PDO with an entry more, or one entry of another object
    let standard: Vec<u32> = crate::pdo_maps::RX_A
        .iter()
        .map(|e| m(e.index, e.sub, e.data_type.bits() as u8))
        .collect();
    let (mut more, mut other) = (standard.clone(), standard.clone());
    more.push(m(0x6072, 0, 16));
    *other.last_mut().unwrap() = m(0x60FE, 2, 32);
    for entries in [&more, &other] {
        let mut objects = DriveObjects::new();
        map(&mut objects, 0x1600, entries);
        assign(&mut objects, 0x1C12, &[0x1600]);
        let img = PdoImage::compile(&objects).unwrap();
        assert_eq!(img.rx.program.standard, 0, "{entries:08X?}");
        let rx = img.rx.bytes();
        program_equals_entry_copy(&img, &objects, &[frame(rx, 5), frame(rx, 6)], "other");
    }
}

/// C-130 with issue 36: the standard RxPDO's digital outputs (60FEh:01,
/// 68FEh:01) are a process output the master may change every frame, not
/// a configuration entry: a frame that changes them (and only them) moves
/// neither the dictionary's nor either axis' configuration generation
/// (which would make both axes read their whole snapshot and configure
/// again in the next control cycle), and the value is stored; a frame that
/// changes the modes of operation or the target position moves neither as
/// well, while a mapped parameter (6065h) still does.
#[test]
fn c130_digital_outputs_in_the_rxpdo_are_no_configuration_change() {
    let mut objects = DriveObjects::new();
    objects.apply_map(PdoLayout::Standard).unwrap();
    assign(&mut objects, 0x1C12, &[0x1600, 0x1601]);
    let img = PdoImage::compile(&objects).unwrap();
    let generations = |o: &DriveObjects| {
        (
            o.config_generation(),
            o.axis_config_generation(0),
            o.axis_config_generation(1),
        )
    };
    let mut rx = std::vec![0u8; img.rx.bytes()];
    img.apply_outputs(&rx, &mut objects);
    let before = generations(&objects);
    for (k, value) in [0x0000_0001u32, 0x8000_0000, 0x0001_0000].into_iter().enumerate() {
        // 60FEh:01 at bytes 19..23 of axis A's 23, 68FEh:01 at 42..46
        rx[19..23].copy_from_slice(&value.to_le_bytes());
        rx[42..46].copy_from_slice(&(!value).to_le_bytes());
        rx[3..7].copy_from_slice(&(k as i32 * 1000).to_le_bytes());
        img.apply_outputs(&rx, &mut objects);
        assert_eq!(objects.get(0x60FE, 1), Ok(i64::from(value)));
        assert_eq!(objects.get(0x68FE, 1), Ok(i64::from(!value)));
        assert_eq!(generations(&objects), before, "frame {k}");
    }
    // a mapped parameter is still configuration
    let mut objects = DriveObjects::new();
    map(&mut objects, 0x1600, &[m(0x60FE, 1, 32), m(0x6065, 0, 32)]);
    assign(&mut objects, 0x1C12, &[0x1600]);
    let img = PdoImage::compile(&objects).unwrap();
    let before = generations(&objects);
    img.apply_outputs(&[1, 0, 0, 0, 0x10, 0x27, 0, 0], &mut objects);
    assert_eq!(objects.get(0x6065, 0), Ok(10_000));
    let after = generations(&objects);
    assert!(after.0 != before.0 && after.1 != before.1, "{before:?} {after:?}");
}

#[test]
fn remapped_layouts_with_gaps_and_two_pdos() {
    let mut objects = DriveObjects::new();
    objects.apply_map(PdoLayout::Vl).unwrap();
    // 1601h: a gap of 8 bits then axis B's controlword
    map(&mut objects, 0x1601, &[m(0, 0, 8), m(0x6840, 0, 16)]);
    assign(&mut objects, 0x1C12, &[0x1600, 0x1601]);
    let img = PdoImage::compile(&objects).unwrap();
    assert_eq!(img.rx().bytes(), 5 + 3);
    assert_eq!(objects.process_data_bytes().unwrap().0, 8);
    let rx = [0x06, 0x00, 0x02, 0x10, 0xFF, 0xEE, 0x07, 0x00];
    assert_eq!(img.apply_outputs(&rx, &mut objects), 4);
    assert_eq!(objects.get(0x6040, 0), Ok(6));
    assert_eq!(objects.get(0x6060, 0), Ok(2));
    assert_eq!(objects.get(0x6042, 0), Ok(-240));
    assert_eq!(objects.get(0x6840, 0), Ok(7), "after the gap");

    let mut tx = [0u8; 5];
    objects.set(0x6044, 0, -2).unwrap();
    img.fill_inputs(&objects, &mut tx);
    assert_eq!(&tx[3..5], &[0xFE, 0xFF]);
}

#[test]
fn bit_packed_entries() {
    let mut objects = DriveObjects::new();
    // 10F3h:04 (BOOL, TxPDO) between two byte-sized entries: 6041h then
    // the BOOL at bit 16, 7 bits of gap, 6061h at bit 24
    map(
        &mut objects,
        0x1A00,
        &[m(0x6041, 0, 16), m(0x10F3, 4, 1), m(0, 0, 3), m(0x6061, 0, 8)],
    );
    let img = PdoImage::compile(&objects).unwrap();
    assert_eq!(img.tx().bits(), 28);
    assert_eq!(img.tx().bytes(), 4);
    objects.set(0x6041, 0, 0x1234).unwrap();
    objects.set(0x10F3, 4, 1).unwrap();
    objects.set(0x6061, 0, -3).unwrap();
    let mut tx = [0u8; 4];
    img.fill_inputs(&objects, &mut tx);
    // -3 = FDh from bit 20 on: low nibble D at bits 20..24, high F in byte 3
    assert_eq!(tx, [0x34, 0x12, 0x01 | 0xD0, 0x0F]);

    // the helpers both ways at an odd offset
    let mut buf = [0u8; 3];
    insert(&mut buf, 5, 16, &0xBEEFu64.to_le_bytes());
    let mut out = [0u8; 8];
    assert!(extract(&buf, 5, 16, &mut out));
    assert_eq!(u16::from_le_bytes([out[0], out[1]]), 0xBEEF);
    assert!(!extract(&buf, 9, 16, &mut out), "beyond the buffer");
}

#[test]
fn unaligned_rx_entries_are_decoded() {
    let mut objects = DriveObjects::new();
    // a 4-bit gap puts the controlword at bit 4
    map(&mut objects, 0x1600, &[m(0, 0, 4), m(0x6040, 0, 16), m(0, 0, 4)]);
    let img = PdoImage::compile(&objects).unwrap();
    assert_eq!(img.rx().bytes(), 3);
    let rx = [0xF0, 0xED, 0x0B];
    assert_eq!(img.apply_outputs(&rx, &mut objects), 1);
    assert_eq!(objects.get(0x6040, 0), Ok(0xBEDF));
}

#[test]
fn rx_template_subindices_resolve_to_the_runtime_numbering() {
    // A00 "Save values" (2000h): element 0 is subindex 0 in the "EtherCAT
    // Rx" template and subindex 1 in the runtime numbering
    let a00 = crate::parameter_index(0, 0);
    assert_eq!(resolve(a00, 0, false).map(|e| e.sub()), Some(1));
    assert_eq!(resolve(a00, 2, false).map(|e| e.sub()), Some(3));
    assert_eq!(resolve(a00, 1, true).map(|e| e.sub()), Some(1));
    assert_eq!(resolve(a00, 3, false), None, "three elements");
    // standard objects are the same in both templates
    assert_eq!(resolve(0x6040, 0, false).map(|e| e.sub()), Some(0));
    assert_eq!(resolve(0x60FE, 1, false).map(|e| e.sub()), Some(1));
    let mut objects = DriveObjects::new();
    objects.set_template(Template::Rx);
    let img = PdoImage::compile(&objects).unwrap();
    assert_eq!((img.rx().bytes(), img.tx().bytes()), (23, 29));
}

#[test]
fn compile_refuses_what_it_cannot_serve() {
    assert_eq!(resolve(0x6040, 1, true), None);
    assert_eq!(resolve(0x5555, 0, true), None);
    assert_eq!(PdoImage::default(), PdoImage::EMPTY);
    assert!(PdoImage::EMPTY.rx().entries().is_empty());
    // the bus checks keep such entries out; the runtime `set` does not
    let mut objects = DriveObjects::new();
    objects.set(0x1600, 2, i64::from(m(0x5555, 0, 16))).unwrap();
    assert_eq!(
        PdoImage::compile(&objects),
        Err(PdoImageError::Entry {
            pdo: 0x1600,
            index: 0x5555,
            sub: 0,
            kind: EntryFault::Unknown
        })
    );
    objects.set(0x1600, 2, i64::from(m(0x6060, 0, 16))).unwrap();
    assert_eq!(
        PdoImage::compile(&objects),
        Err(PdoImageError::Entry {
            pdo: 0x1600,
            index: 0x6060,
            sub: 0,
            kind: EntryFault::BitLength
        })
    );
    // 24 gaps of 255 bits in each of four PDOs: beyond 384 bytes
    let mut objects = DriveObjects::new();
    for pdo in 0x1600..=0x1602u16 {
        objects.set(pdo, 0, 24).unwrap();
        for s in 1..=24 {
            objects.set(pdo, s, 0xFF).unwrap();
        }
    }
    objects.set(0x1C12, 0, 3).unwrap();
    objects.set(0x1C12, 2, 0x1601).unwrap();
    objects.set(0x1C12, 3, 0x1602).unwrap();
    assert!(matches!(
        PdoImage::compile(&objects),
        Err(PdoImageError::TooLong { .. })
    ));
}
