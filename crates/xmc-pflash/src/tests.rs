extern crate std;
use std::vec::Vec;

use crate::*;

mod model;
use model::{Garble, Model, BUSY_GARBAGE};

const K: u32 = 1024;
/// Slot A's first sector (S9).
const S9: u32 = UNCACHED_BASE + 256 * K;
/// The parameter store's first sector (S4).
const S4: u32 = UNCACHED_BASE + 64 * K;
const LIMITS: Limits = Limits {
    page_polls: 10,
    erase_polls: 10,
};

fn driver() -> Pflash<Model> {
    Pflash::new(Model::new(), LIMITS)
}

fn pattern(seed: u8) -> [u8; PAGE] {
    let mut p = [0u8; PAGE];
    for (i, b) in p.iter_mut().enumerate() {
        *b = seed.wrapping_mul(31).wrapping_add(i as u8) | 1;
    }
    p
}

/// The model saw no array read while busy and is back in read mode, flags clear.
fn clean(f: &mut Pflash<Model>) {
    let m = f.bus_mut();
    assert_eq!(m.reads_while_busy, 0, "array read while busy");
    assert!(!m.page_mode(), "left in page mode");
    assert_eq!(
        m.fsr & (fsr::SQER | fsr::PROER | fsr::PFOPER | fsr::VER | fsr::PBUSY),
        0
    );
}

#[test]
fn sector_map_is_the_xmc4800s() {
    assert_eq!(logical_sector(0), Some((0, 16 * K)));
    assert_eq!(logical_sector(112 * K), Some((112 * K, 16 * K)));
    assert_eq!(logical_sector(128 * K), Some((128 * K, 128 * K)));
    assert_eq!(logical_sector(256 * K), Some((256 * K, 256 * K)));
    assert_eq!(logical_sector(1792 * K), Some((1792 * K, 256 * K)));
    assert_eq!(logical_sector(2048 * K), None);
    assert_eq!(logical_sector(192 * K), None);
    assert_eq!(logical_sector(8 * K), None);
    assert_eq!(physical_sector(20 * K), Some((0, 64 * K)));
    assert_eq!(physical_sector(100 * K), Some((64 * K, 64 * K)));
    assert_eq!(physical_sector(200 * K), Some((128 * K, 128 * K)));
    assert_eq!(physical_sector(600 * K), Some((512 * K, 256 * K)));
    assert_eq!(physical_sector(2048 * K), None);
}

#[test]
fn erase_sector_blanks_it_to_zero_and_leaves_neighbours() {
    let mut f = driver();
    f.bus_mut().mem.fill(0x5A);
    f.erase_sector(S4 + 16 * K).unwrap();
    clean(&mut f);
    let m = f.bus_mut();
    assert!(m.at(S4 + 16 * K, 16 * K as usize).iter().all(|&b| b == 0));
    assert_eq!(m.at(S4 + 16 * K - 1, 1), &[0x5A]);
    assert_eq!(m.at(S4 + 32 * K, 1), &[0x5A]);
    assert_eq!(m.started, 1);
}

#[test]
fn erase_sector_issues_exactly_the_documented_sequence() {
    let mut f = driver();
    f.erase_sector(S9).unwrap();
    let w = &f.bus_mut().writes;
    let seq = [
        (0x0C00_5554, 0xF0),
        (0x0C00_5554, 0xF5),
        (0x0C00_5554, 0xAA),
        (0x0C00_AAA8, 0x55),
        (0x0C00_5554, 0x80),
        (0x0C00_5554, 0xAA),
        (0x0C00_AAA8, 0x55),
        (0x0C04_0000, 0x30),
    ];
    assert_eq!(&w[..seq.len()], &seq);
}

#[test]
fn erase_physical_sector_blanks_all_its_logical_sectors() {
    let mut f = driver();
    f.bus_mut().mem.fill(0x5A);
    f.erase_physical_sector(S4).unwrap();
    clean(&mut f);
    let m = f.bus_mut();
    assert!(m.at(S4, 64 * K as usize).iter().all(|&b| b == 0));
    assert_eq!(m.at(S4 - 1, 1), &[0x5A]);
    assert_eq!(m.at(S4 + 64 * K, 1), &[0x5A]);
    assert_eq!(f.erase_physical_sector(S4 + 16 * K), Err(Error::NotSectorStart));
}

#[test]
fn erase_not_at_a_sector_start_is_refused_without_a_command() {
    let mut f = driver();
    assert_eq!(f.erase_sector(S9 + PAGE as u32), Err(Error::NotSectorStart));
    assert_eq!(f.erase_sector(UNCACHED_BASE + SIZE), Err(Error::OutOfRange));
    assert_eq!(f.erase_sector(0x0800_0000), Err(Error::OutOfRange));
    assert!(f.bus_mut().writes.is_empty());
}

#[test]
fn write_page_then_read_back() {
    let mut f = driver();
    let p = pattern(7);
    f.write_page(S9 + 3 * PAGE as u32, &p).unwrap();
    clean(&mut f);
    let mut back = [0u8; PAGE];
    f.read(S9 + 3 * PAGE as u32, &mut back).unwrap();
    assert_eq!(back, p);
    // unaligned reads of any length
    let mut odd = [0u8; 7];
    f.read(S9 + 3 * PAGE as u32 + 5, &mut odd).unwrap();
    assert_eq!(odd, p[5..12]);
    // the neighbours stay erased
    let mut n = [0xFFu8; 4];
    f.read(S9 + 4 * PAGE as u32, &mut n).unwrap();
    assert_eq!(n, [0; 4]);
}

#[test]
fn write_page_loads_the_buffer_in_64_bit_pairs() {
    let mut f = driver();
    let p = pattern(1);
    f.write_page(S9, &p).unwrap();
    let w = &f.bus_mut().writes;
    assert_eq!(
        &w[..3],
        &[(0x0C00_5554, 0xF0), (0x0C00_5554, 0xF5), (0x0C00_5554, 0x50)]
    );
    let loads: Vec<_> = w[3..3 + 64].to_vec();
    for (i, pair) in loads.chunks(2).enumerate() {
        let lo = u32::from_le_bytes(p[8 * i..8 * i + 4].try_into().unwrap());
        let hi = u32::from_le_bytes(p[8 * i + 4..8 * i + 8].try_into().unwrap());
        assert_eq!(pair, &[(0x0C00_55F0, lo), (0x0C00_55F4, hi)]);
    }
    assert_eq!(
        &w[67..71],
        &[
            (0x0C00_5554, 0xAA),
            (0x0C00_AAA8, 0x55),
            (0x0C00_5554, 0xA0),
            (S9, 0xAA)
        ]
    );
}

#[test]
fn write_off_a_page_boundary_is_refused_without_a_command() {
    let mut f = driver();
    // 8-byte aligned (a load-pair boundary) but inside a page: it would straddle two
    assert_eq!(f.write_page(S9 + 8, &pattern(1)), Err(Error::Misaligned));
    assert_eq!(f.program(S9 + 128, &[0x11; PAGE]), Err(Error::Misaligned));
    assert!(f.bus_mut().writes.is_empty());
}

#[test]
fn write_across_a_page_boundary_is_refused() {
    let mut f = driver();
    // more than a page but not whole pages: the rest would spill into the next page
    assert_eq!(f.program(S9, &[0x11; PAGE + 8]), Err(Error::Misaligned));
    assert_eq!(f.program(S9, &[0x11; 8]), Err(Error::Misaligned));
    assert!(f.bus_mut().writes.is_empty());
    assert!(f.bus_mut().at(S9, 2 * PAGE).iter().all(|&b| b == 0));
}

#[test]
fn write_outside_the_pflash_is_refused() {
    let mut f = driver();
    let end = UNCACHED_BASE + SIZE;
    assert_eq!(f.write_page(end, &pattern(1)), Err(Error::OutOfRange));
    assert_eq!(
        f.program(end - PAGE as u32, &[1; 2 * PAGE]),
        Err(Error::OutOfRange)
    );
    assert_eq!(f.write_page(0x0800_0000, &pattern(1)), Err(Error::OutOfRange));
    assert_eq!(f.read(end - 2, &mut [0; 4]), Err(Error::OutOfRange));
    assert!(f.bus_mut().writes.is_empty());
}

#[test]
fn program_writes_several_pages() {
    let mut f = driver();
    let mut data = Vec::new();
    for s in 0..3 {
        data.extend_from_slice(&pattern(s));
    }
    f.program(S4, &data).unwrap();
    clean(&mut f);
    assert_eq!(f.bus_mut().at(S4, data.len()), &data[..]);
    assert_eq!(f.bus_mut().started, 3);
}

/// Writes of `write_page`: 0 Reset to Read, 1 Clear Status, 2 Enter Page Mode,
/// 3..=66 the 32 load pairs, 67..=70 Write Page (AAh, 55h, A0h, AAh to the page).
fn garbled_write_page(nth: usize) -> (Result<(), Error>, Model) {
    let mut m = Model::new();
    let mut g = Garble {
        model: &mut m,
        nth,
        seen: 0,
    };
    let r = Pflash::new(&mut g, LIMITS).write_page(S9, &pattern(2));
    (r, m)
}

#[test]
fn sequence_error_of_a_write_is_surfaced_and_cleared() {
    for nth in [2, 67, 68, 69, 70] {
        let (r, m) = garbled_write_page(nth);
        assert_eq!(r, Err(Error::Sequence), "write {nth}");
        assert_eq!(m.started, 0, "write {nth}");
        assert_eq!(m.fsr & fsr::SQER, 0, "SQER left set after write {nth}");
        assert!(!m.page_mode(), "page mode left on after write {nth}");
    }
}

#[test]
fn garbled_data_is_caught_by_the_read_back() {
    // a data word changed on its way: the chip cannot tell, the read-back does
    for nth in [3, 10, 66] {
        let (r, m) = garbled_write_page(nth);
        assert_eq!(r, Err(Error::ReadBack), "write {nth}");
        assert_eq!(m.started, 1);
    }
}

#[test]
fn sequence_error_of_the_erase_is_surfaced_and_nothing_erased() {
    let mut m = Model::new();
    m.mem.fill(0x77);
    // writes: F0, F5, AA, 55, 80, AA, 55, 30 -> garble the 80h
    let mut g = Garble {
        model: &mut m,
        nth: 4,
        seen: 0,
    };
    let r = Pflash::new(&mut g, LIMITS).erase_sector(S9);
    assert_eq!(r, Err(Error::Sequence));
    assert_eq!(m.started, 0);
    assert!(m.at(S9, 256 * K as usize).iter().all(|&b| b == 0x77));
    assert_eq!(m.fsr & fsr::SQER, 0);
}

#[test]
fn after_a_sequence_error_the_next_write_works() {
    let mut m = Model::new();
    {
        let mut g = Garble {
            model: &mut m,
            nth: 68,
            seen: 0,
        };
        assert_eq!(
            Pflash::new(&mut g, LIMITS).write_page(S9, &pattern(3)),
            Err(Error::Sequence)
        );
    }
    let mut f = Pflash::new(m, LIMITS);
    f.write_page(S9, &pattern(3)).unwrap();
    clean(&mut f);
}

#[test]
fn busy_for_fewer_polls_than_the_bound_completes() {
    let mut f = driver();
    f.bus_mut().busy_polls = LIMITS.page_polls - 1;
    f.write_page(S9, &pattern(4)).unwrap();
    f.bus_mut().busy_polls = LIMITS.erase_polls - 1;
    f.erase_sector(S4).unwrap();
    clean(&mut f);
}

#[test]
fn busy_timeout_is_surfaced() {
    let mut f = driver();
    f.bus_mut().busy_polls = LIMITS.page_polls;
    assert_eq!(f.write_page(S9, &pattern(4)), Err(Error::Timeout));
    assert_eq!(f.bus_mut().reads_while_busy, 0);

    let mut f = driver();
    f.bus_mut().stuck = true;
    assert_eq!(f.erase_sector(S4), Err(Error::Timeout));
    // no array read (the verify) and no command after the timeout: the chip is busy
    let m = f.bus_mut();
    assert_eq!(m.reads_while_busy, 0);
    assert_eq!(m.writes.last(), Some(&(S4, cmd::ERASE_SECTOR)));
}

#[test]
fn protection_error_is_surfaced_and_nothing_changed() {
    let mut f = driver();
    f.bus_mut().protected = 1 << 9;
    assert_eq!(f.write_page(S9, &pattern(5)), Err(Error::Protection));
    assert_eq!(f.erase_sector(S9), Err(Error::Protection));
    clean(&mut f);
    assert_eq!(f.bus_mut().started, 0);
    // S10 is not protected
    f.write_page(S9 + 256 * K, &pattern(5)).unwrap();
}

#[test]
fn program_and_erase_errors_are_surfaced() {
    let mut f = driver();
    f.bus_mut().fail_next = true;
    assert_eq!(f.write_page(S9, &pattern(6)), Err(Error::Operation));
    clean(&mut f);
    f.bus_mut().mem.fill(0x33);
    f.bus_mut().fail_next = true;
    assert_eq!(f.erase_sector(S4), Err(Error::Operation));
    clean(&mut f);
    f.bus_mut().verify_error_next = true;
    assert_eq!(f.erase_sector(S4), Err(Error::Verify));
    clean(&mut f);
}

#[test]
fn erase_verifies_blank() {
    let mut f = driver();
    f.bus_mut().erase_leaves = Some(64 * K + 1000);
    assert_eq!(f.erase_sector(S4), Err(Error::NotBlank));
}

#[test]
fn write_over_a_programmed_page_is_refused_without_a_command() {
    let mut f = driver();
    f.write_page(S9, &pattern(8)).unwrap();
    let n = f.bus_mut().writes.len();
    assert_eq!(f.write_page(S9, &pattern(9)), Err(Error::NotErased));
    assert_eq!(f.bus_mut().writes.len(), n, "no command for a programmed page");
    assert_eq!(f.bus_mut().at(S9, PAGE), &pattern(8));
    // one 1 bit anywhere in the page is enough
    f.bus_mut().mem[(S9 - UNCACHED_BASE) as usize + 2 * PAGE - 1] = 0x80;
    assert_eq!(f.write_page(S9 + PAGE as u32, &pattern(9)), Err(Error::NotErased));
    // after an erase the page is taken again
    f.erase_sector(S9).unwrap();
    f.write_page(S9, &pattern(9)).unwrap();
    clean(&mut f);
}

#[test]
fn errors_map_to_the_flash_trait() {
    assert_eq!(FlashError::from(Error::OutOfRange), FlashError::OutOfRange);
    assert_eq!(FlashError::from(Error::NotSectorStart), FlashError::OutOfRange);
    assert_eq!(FlashError::from(Error::Misaligned), FlashError::Misaligned);
    for e in [
        Error::Sequence,
        Error::Protection,
        Error::Operation,
        Error::Verify,
        Error::PageMode,
        Error::NotStarted,
        Error::Timeout,
        Error::NotBlank,
        Error::NotErased,
        Error::ReadBack,
    ] {
        assert_eq!(FlashError::from(e), FlashError::Device);
    }
}

#[test]
fn limits_scale_with_the_clock() {
    let l = Limits::at_cpu_hz(144_000_000);
    assert_eq!(l.page_polls, 7_200_000);
    assert_eq!(l.erase_polls, 2_880_000_000);
    assert_eq!(Limits::at_cpu_hz(400_000_000).erase_polls, u32::MAX);
    assert_eq!(Limits::at_cpu_hz(1).page_polls, 1);
}

#[test]
fn volatile_bus_only_reaches_pflash_and_fsr() {
    assert!(Volatile::allowed(FSR_ADDR));
    assert!(Volatile::allowed(cmd::A5554));
    assert!(Volatile::allowed(UNCACHED_BASE + SIZE - 4));
    assert!(!Volatile::allowed(UNCACHED_BASE + SIZE));
    assert!(!Volatile::allowed(0x0800_0000));
    assert!(!Volatile::allowed(0x2000_0000));
    assert!(!Volatile::allowed(cmd::A5554 + 1));
}

// --- the Flash trait on top: regions, the store, the boot slots ---

type Params = ParamRegion<Model>;
type Slots = SlotRegion<Model>;

#[test]
fn region_erased_reads_zero_and_maps_sectors() {
    let mut r = Params::new(driver());
    r.pflash_mut().bus_mut().mem.fill(0x44);
    r.erase(3).unwrap();
    let mut b = [0xFFu8; 16];
    r.read(3 * 16 * K, &mut b).unwrap();
    assert_eq!(b, [0; 16], "erased PFLASH reads 00h, passed through");
    let m = r.pflash_mut().bus_mut();
    assert!(m.at(S4 + 48 * K, 16 * K as usize).iter().all(|&b| b == 0));
    assert_eq!(m.at(S4 + 48 * K - 1, 1), &[0x44]);
    assert_eq!(r.erase(4), Err(FlashError::OutOfRange));
    assert_eq!(r.read(64 * K - 2, &mut [0; 4]), Err(FlashError::OutOfRange));
    assert_eq!(r.write(64 * K, &[0; PAGE]), Err(FlashError::OutOfRange));
    assert_eq!(r.write(8, &[0; PAGE]), Err(FlashError::Misaligned));
    assert_eq!(r.write(0, &[0; 8]), Err(FlashError::Misaligned));
    r.pflash_mut().bus_mut().protected = 1 << 4;
    assert_eq!(r.erase(0), Err(FlashError::Device));
}

#[test]
fn slot_region_is_s9_to_s12() {
    let mut r = Slots::new(driver());
    r.write(3 * 256 * K, &pattern(1)).unwrap();
    assert_eq!(
        r.pflash_mut().bus_mut().at(UNCACHED_BASE + 1024 * K, PAGE),
        &pattern(1)
    );
    assert_eq!(r.erase(4), Err(FlashError::OutOfRange));
}

#[test]
fn param_store_saves_and_loads_on_the_pflash() {
    let mut s = store::ParamStore::new(Params::new(driver()));
    let mut out = [0u8; 1000];
    assert_eq!(
        s.load(7, &mut out),
        Err(store::StoreError::NoData),
        "erased: no record"
    );
    let a: Vec<u8> = (0..700u32).map(|i| i as u8).collect();
    let b: Vec<u8> = (0..300u32).map(|i| (i * 7) as u8).collect();
    s.save(&a, 7).unwrap();
    assert_eq!(s.load(7, &mut out), Ok(700));
    assert_eq!(&out[..700], &a[..]);
    s.save(&b, 7).unwrap();
    assert_eq!(s.load(7, &mut out), Ok(300));
    assert_eq!(&out[..300], &b[..]);
    // a save torn by a program error keeps the previous record
    s.flash_mut().pflash_mut().bus_mut().fail_next = true;
    assert!(s.save(&a, 7).is_err());
    assert_eq!(s.load(7, &mut out), Ok(300));
    let m = s.flash_mut().pflash_mut().bus_mut();
    assert_eq!(m.reads_while_busy, 0);
}

#[test]
fn boot_slots_download_trial_and_confirm_on_the_pflash() {
    let mut slots = boot::BootSlots::new(Slots::new(driver()));
    assert_eq!(
        slots.states().unwrap(),
        [boot::SlotState::Empty; 2],
        "erased: empty"
    );
    let body: Vec<u8> = (0..3000u32).map(|i| (i * 13 + 1) as u8).collect();
    // (unsigned, linked for slot A: the boot decision and the marks do not look
    // at the signature)
    let header = boot::ImageHeader::for_body(&body, 2, slots.load_address(boot::Slot::A), 0).to_bytes();
    assert_eq!(slots.begin().unwrap(), boot::Slot::A);
    slots.write(&header).unwrap();
    for c in body.chunks(100) {
        slots.write(c).unwrap();
    }
    slots.finish().unwrap();
    assert_eq!(
        slots.state(boot::Slot::A).unwrap(),
        boot::SlotState::Pending { seq: 1 }
    );
    let d = slots.boot().unwrap().unwrap();
    assert_eq!((d.slot, d.trial), (boot::Slot::A, true));
    assert_eq!(
        slots.state(boot::Slot::A).unwrap(),
        boot::SlotState::Trial { seq: 1 }
    );
    slots.confirm().unwrap();
    assert_eq!(
        slots.state(boot::Slot::A).unwrap(),
        boot::SlotState::Confirmed { seq: 1 }
    );
    let mut flash = slots.into_inner();
    // the body is stored as it executes: plain bytes at slot A + 1 KiB
    let m = flash.pflash_mut().bus_mut();
    assert_eq!(m.at(S9 + 1024, body.len()), &body[..]);
    assert_eq!(m.reads_while_busy, 0);
    assert_ne!(m.at(S9, 4), BUSY_GARBAGE.to_le_bytes());
}
