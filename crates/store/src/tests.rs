extern crate std;
use std::vec::Vec;

use crate::*;

/// 4 sectors of 256 bytes: two per slot, slot capacity 512 − 24 − 8 = 480 bytes.
type Ram = RamFlash<256, 4>;
const LAYOUT: u32 = 0x0001_0002;

fn set(n: u8, len: usize) -> Vec<u8> {
    (0..len)
        .map(|i| n.wrapping_mul(37).wrapping_add(i as u8))
        .collect()
}

fn load(store: &mut ParamStore<Ram>) -> Result<Vec<u8>, StoreError> {
    let mut out = [0u8; 512];
    let n = store.load(LAYOUT, &mut out)?;
    Ok(out[..n].to_vec())
}

#[test]
fn crc32_check_value() {
    assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    assert_eq!(crc32(b""), 0);
}

#[test]
fn e018_load_returns_last_saved_set() {
    let mut store = ParamStore::new(Ram::new());
    assert_eq!(load(&mut store), Err(StoreError::NoData));
    for n in 1..=5u8 {
        let s = set(n, 40 + usize::from(n) * 13);
        store.save(&s, LAYOUT).unwrap();
        assert_eq!(load(&mut store).unwrap(), s);
        // A new store over the same flash (= after a restart) sees the same set.
        let mut again = ParamStore::new(store.flash().clone());
        assert_eq!(load(&mut again).unwrap(), s);
    }
    // Empty payloads are records too.
    store.save(&[], LAYOUT).unwrap();
    assert_eq!(load(&mut store).unwrap(), Vec::<u8>::new());
}

#[test]
fn e018_saves_alternate_slots() {
    let mut store = ParamStore::new(Ram::new());
    store.save(&set(1, 16), LAYOUT).unwrap();
    store.save(&set(2, 16), LAYOUT).unwrap();
    // Both records present: corrupting the newest (slot B, payload byte) falls back to set 1.
    let off = 512 + 24 + 3;
    *store.flash_mut().bytes_mut().nth(off).unwrap() ^= 0x01;
    assert_eq!(load(&mut store).unwrap(), set(1, 16));
    // The next save replaces the corrupt slot, not set 1.
    store.save(&set(3, 16), LAYOUT).unwrap();
    assert_eq!(load(&mut store).unwrap(), set(3, 16));
    store.save(&set(4, 16), LAYOUT).unwrap();
    assert_eq!(load(&mut store).unwrap(), set(4, 16));
}

/// Cuts power at every erase/write of a save, from a flash holding one record and
/// from one holding two, with payload lengths that do and do not fill the last unit.
#[test]
fn e020_power_cut_at_every_step_keeps_previous_set() {
    for (len1, len2) in [(100, 150), (64, 37), (480, 8), (5, 480)] {
        for records_before in [1u8, 2] {
            let mut store = ParamStore::new(Ram::new());
            for n in 0..records_before {
                store.save(&set(n, len1), LAYOUT).unwrap();
            }
            let old = set(records_before - 1, len1);
            let new = set(9, len2);
            let base = store.flash().clone();

            let mut probe = ParamStore::new(base.clone());
            let before = probe.flash().ops();
            probe.save(&new, LAYOUT).unwrap();
            let steps = probe.flash().ops() - before;
            assert!(steps >= 4, "erase ×2, header, payload, commit");

            for k in 0..=steps {
                let mut flash = base.clone();
                flash.cut_after(k);
                let mut store = ParamStore::new(flash);
                let r = store.save(&new, LAYOUT);
                assert_eq!(r.is_ok(), k == steps, "k = {k}");
                store.flash_mut().power_on();
                let got = load(&mut store).unwrap();
                assert!(got == old || got == new, "k = {k}: garbage");
                // Stronger than required: the new set only counts once its commit unit
                // is complete, i.e. when the save returned Ok.
                assert_eq!(&got, if k == steps { &new } else { &old }, "k = {k}");
                // After the cut a new save works.
                let next = set(7, len2 / 2 + 1);
                store.save(&next, LAYOUT).unwrap();
                assert_eq!(load(&mut store).unwrap(), next);
            }
        }
    }
}

#[test]
fn layout_mismatch() {
    let mut store = ParamStore::new(Ram::new());
    store.save(&set(1, 10), LAYOUT).unwrap();
    let mut out = [0u8; 64];
    assert_eq!(store.load(LAYOUT + 1, &mut out), Err(StoreError::LayoutMismatch));
    // The newest set with a matching layout wins, even when a newer one has another layout.
    store.save(&set(2, 10), LAYOUT + 1).unwrap();
    assert_eq!(store.load(LAYOUT, &mut out), Ok(10));
    assert_eq!(&out[..10], &set(1, 10)[..]);
    assert_eq!(store.load(LAYOUT + 1, &mut out), Ok(10));
    assert_eq!(&out[..10], &set(2, 10)[..]);
}

#[test]
fn too_large() {
    let mut store = ParamStore::new(Ram::new());
    assert_eq!(store.capacity(), 480);
    assert_eq!(store.save(&[0; 481], LAYOUT), Err(StoreError::TooLarge));
    assert_eq!(store.flash().ops(), 0, "nothing touched");
    store.save(&[0x11; 480], LAYOUT).unwrap();
    let mut small = [0u8; 479];
    assert_eq!(store.load(LAYOUT, &mut small), Err(StoreError::TooLarge));
}

#[test]
fn both_slots_corrupt_is_no_data() {
    let mut store = ParamStore::new(Ram::new());
    store.save(&set(1, 30), LAYOUT).unwrap();
    store.save(&set(2, 30), LAYOUT).unwrap();
    for off in [24 + 5, 512 + 24 + 5] {
        *store.flash_mut().bytes_mut().nth(off).unwrap() ^= 0x80;
    }
    assert_eq!(load(&mut store), Err(StoreError::NoData));
    // A save then starts afresh.
    store.save(&set(3, 30), LAYOUT).unwrap();
    assert_eq!(load(&mut store).unwrap(), set(3, 30));
}

#[test]
fn sequence_wraps() {
    assert!(newer(0, u32::MAX));
    assert!(newer(1, 0));
    assert!(!newer(u32::MAX, 0));
}

#[test]
fn flash_errors_propagate() {
    let mut flash = Ram::new();
    flash.cut_after(0);
    let mut store = ParamStore::new(flash);
    assert_eq!(
        store.save(&[1; 8], LAYOUT),
        Err(StoreError::Flash(FlashError::Device))
    );
    assert_eq!(load(&mut store), Err(StoreError::Flash(FlashError::Device)));
    let mut ram = Ram::new();
    assert_eq!(ram.write(3, &[0; 8]), Err(FlashError::Misaligned));
    assert_eq!(ram.erase(4), Err(FlashError::OutOfRange));
}

/// The power-cut switch E-020's tests cut saves and downloads with: the
/// operations after its budget fail, the flash keeps what the last one left.
#[test]
fn e020_power_cut_switch_fails_every_operation_after_its_budget_and_keeps_reads() {
    let mut f = PowerCut::after(Ram::new(), 2);
    assert_eq!(f.erase(0), Ok(()));
    assert_eq!(f.write(0, &[0x5A; 8]), Ok(()));
    assert_eq!(f.write(8, &[0x5A; 8]), Err(FlashError::Device));
    assert_eq!(f.erase(1), Err(FlashError::Device));
    let mut b = [0u8; 16];
    assert_eq!(f.read(0, &mut b), Ok(()));
    assert_eq!(b[..8], [0x5A; 8]);
    assert_eq!(b[8..], [0xFF; 8]);
    f.power_on();
    assert_eq!(f.write(8, &[0x5A; 8]), Ok(()));
    f.cut_after(0);
    assert_eq!(f.erase(0), Err(FlashError::Device));
    let mut plain = PowerCut::new(f.into_inner());
    assert_eq!(plain.erase(0), Ok(()));
    assert_eq!(plain.inner_mut().ops(), 4);
}
