extern crate std;
use std::vec::Vec;

use crate::*;
use store::RamFlash;

/// 64 sectors of 256 bytes: 8 KiB per slot, the body at 1 KiB.
pub(crate) type Ram = RamFlash<256, 64>;

/// The development key pair's secret seed (keys/dev-ed25519.key).
pub(crate) fn dev_seed() -> [u8; 32] {
    parse_key_hex(include_str!("../../../keys/dev-ed25519.key")).unwrap()
}

/// The load address of `slot` of a [`Ram`] (mapped at 0).
pub(crate) fn load(slot: Slot) -> u32 {
    (slot.index() * 32 * 256 + BootSlots::<Ram>::body_offset()) as u32
}

pub(crate) fn body(n: u8, len: usize) -> Vec<u8> {
    (0..len)
        .map(|i| n.wrapping_mul(31).wrapping_add(i as u8))
        .collect()
}

/// The update file of `body` for `slot`, security counter 0, signed with the
/// development key.
pub(crate) fn file_for(slot: Slot, body: &[u8], version: u32) -> Vec<u8> {
    signed(slot, body, version, 0, &dev_seed())
}

/// The update file of `body` for `slot` with `counter`, signed with `seed`.
pub(crate) fn signed(slot: Slot, body: &[u8], version: u32, counter: u32, seed: &[u8; 32]) -> Vec<u8> {
    let mut h = ImageHeader::for_body(body, version, load(slot), counter);
    h.sign(body, seed);
    let mut f = h.to_bytes().to_vec();
    f.extend_from_slice(body);
    f
}

/// An update file for slot B (where the tests' downloads go after the factory image).
fn file(body: &[u8], version: u32) -> Vec<u8> {
    file_for(Slot::B, body, version)
}

/// Downloads `f` in chunks of `chunk` bytes.
pub(crate) fn download(s: &mut BootSlots<Ram>, f: &[u8], chunk: usize) -> Result<Slot, UpdateError> {
    s.begin()?;
    for c in f.chunks(chunk) {
        s.write(c)?;
    }
    s.finish()
}

pub(crate) fn power_cycle(s: BootSlots<Ram>) -> (BootSlots<Ram>, Option<Decision>) {
    let mut s = BootSlots::new(s.into_inner());
    let d = s.boot().unwrap();
    (s, d)
}

/// A device with a confirmed image (version 1) in slot A.
pub(crate) fn factory() -> BootSlots<Ram> {
    let mut s = BootSlots::new(Ram::new());
    assert_eq!(s.boot().unwrap(), None, "empty flash: nothing to start");
    assert_eq!(
        download(&mut s, &file_for(Slot::A, &body(1, 1000), 1), 100),
        Ok(Slot::A)
    );
    let (mut s, d) = power_cycle(s);
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::A, true)));
    s.confirm().unwrap();
    s
}

#[test]
fn decide_is_a_pure_function_of_the_states() {
    use SlotState::*;
    let run = |slot, trial, rolled_back| {
        Some(Decision {
            slot,
            trial,
            rolled_back,
        })
    };
    assert_eq!(decide([Empty, Empty]), None);
    assert_eq!(decide([Confirmed { seq: 1 }, Empty]), run(Slot::A, false, None));
    assert_eq!(
        decide([Confirmed { seq: 1 }, Pending { seq: 2 }]),
        run(Slot::B, true, None)
    );
    // the pending image started once and never confirmed: back to A
    assert_eq!(
        decide([Confirmed { seq: 1 }, Trial { seq: 2 }]),
        run(Slot::A, false, Some(Slot::B))
    );
    assert_eq!(
        decide([Confirmed { seq: 1 }, Confirmed { seq: 2 }]),
        run(Slot::B, false, None)
    );
    assert_eq!(
        decide([Confirmed { seq: 3 }, Confirmed { seq: 2 }]),
        run(Slot::A, false, None)
    );
    // sequence numbers wrap
    assert_eq!(
        decide([Confirmed { seq: u32::MAX }, Confirmed { seq: 0 }]),
        run(Slot::B, false, None)
    );
    // nothing to roll back to: the trial image runs again
    assert_eq!(decide([Trial { seq: 1 }, Empty]), run(Slot::A, false, None));
    assert_eq!(decide([Empty, Pending { seq: 7 }]), run(Slot::B, true, None));
}

#[test]
fn update_switches_on_next_boot_and_stays_after_confirm() {
    let mut s = factory();
    assert_eq!(s.inactive(), Slot::B);
    let new = file(&body(2, 1500), 2);
    assert_eq!(download(&mut s, &new, 244), Ok(Slot::B));
    assert_eq!(s.active(), Some(Slot::A), "the running image does not change");
    assert_eq!(s.state(Slot::B).unwrap(), SlotState::Pending { seq: 2 });
    let (mut s, d) = power_cycle(s);
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::B, true)));
    assert!(s.on_trial());
    s.confirm().unwrap();
    assert_eq!(s.state(Slot::B).unwrap(), SlotState::Confirmed { seq: 2 });
    let (s, d) = power_cycle(s);
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::B, false)));
    assert_eq!(s.inactive(), Slot::A);
}

#[test]
fn unconfirmed_image_rolls_back() {
    let mut s = factory();
    download(&mut s, &file(&body(2, 700), 2), 64).unwrap();
    let (s, d) = power_cycle(s);
    assert_eq!(d.map(|d| d.slot), Some(Slot::B));
    // no confirm: the next boot goes back to A
    let (mut s, d) = power_cycle(s);
    assert_eq!(
        d,
        Some(Decision {
            slot: Slot::A,
            trial: false,
            rolled_back: Some(Slot::B)
        })
    );
    assert!(!s.on_trial());
    // and a new download may overwrite the failed image
    assert_eq!(download(&mut s, &file(&body(3, 10), 3), 7), Ok(Slot::B));
}

#[test]
fn corrupt_image_is_refused_and_old_slot_stays() {
    let mut s = factory();
    let mut bad = file(&body(2, 900), 2);
    bad[500] ^= 0x40;
    assert_eq!(download(&mut s, &bad, 128), Err(UpdateError::Crc));
    assert_eq!(s.state(Slot::B).unwrap(), SlotState::Empty);
    let (_, d) = power_cycle(s);
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::A, false)));
}

#[test]
fn cut_download_leaves_the_slot_empty() {
    let mut s = factory();
    let f = file(&body(2, 900), 2);
    s.begin().unwrap();
    s.write(&f[..400]).unwrap();
    s.abort();
    assert_eq!(s.finish(), Err(UpdateError::NotStarted));
    assert_eq!(s.state(Slot::B).unwrap(), SlotState::Empty);
    // a short file is incomplete
    s.begin().unwrap();
    s.write(&f[..400]).unwrap();
    assert_eq!(s.finish(), Err(UpdateError::Incomplete));
    let (_, d) = power_cycle(s);
    assert_eq!(d.map(|d| d.slot), Some(Slot::A));
}

/// A power cut while the VALID unit is written (the flash programs the tag,
/// not the sequence number) commits nothing: the slot stays empty, the
/// running image starts, and the next download is taken and starts on
/// trial (the fault matrix found it through FoE: the torn unit read as the
/// newest image, sequence FFFFFFFFh).
#[test]
fn e020_a_valid_unit_cut_after_its_tag_commits_nothing() {
    let f = file(&body(2, 900), 2);
    let written = || {
        let mut s = factory();
        s.begin().unwrap();
        s.write(&f).unwrap();
        s
    };
    // the flash operations finish makes: the VALID unit is the last
    let mut s = written();
    let before = s.flash_mut().ops();
    assert_eq!(s.finish(), Ok(Slot::B));
    let last = s.flash_mut().ops() - before - 1;
    let mut s = written();
    s.flash_mut().cut_after(last);
    assert!(s.finish().is_err(), "the cut fails the finish");
    s.flash_mut().power_on();
    let (mut s, d) = power_cycle(s);
    assert_eq!(s.state(Slot::B).unwrap(), SlotState::Empty, "torn VALID unit");
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::A, false)));
    assert_eq!(download(&mut s, &f, 100), Ok(Slot::B));
    let (_, d) = power_cycle(s);
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::B, true)));
}

#[test]
fn header_length_and_size_checks() {
    let mut s = factory();
    s.begin().unwrap();
    assert_eq!(s.write(&[0u8; 100]), Err(UpdateError::BadHeader));
    let cap = s.capacity();
    let big = ImageHeader {
        length: cap as u32 + 1,
        ..ImageHeader::for_body(&[], 9, load(Slot::B), 0)
    };
    s.begin().unwrap();
    assert_eq!(s.write(&big.to_bytes()), Err(UpdateError::TooLarge));
    // more bytes than announced
    let mut f = file(&body(4, 100), 4);
    f.push(0);
    assert_eq!(download(&mut s, &f, 50), Err(UpdateError::TooLarge));
    // exactly the capacity fits
    assert_eq!(download(&mut s, &file(&body(5, cap), 5), 244), Ok(Slot::B));
    assert!(s.write(&[1]).is_err(), "no download after finish");
}

#[test]
fn no_download_over_the_rollback_target_while_on_trial() {
    let mut s = factory();
    download(&mut s, &file(&body(2, 300), 2), 300).unwrap();
    let (mut s, _) = power_cycle(s);
    assert!(s.on_trial());
    assert_eq!(s.begin(), Err(UpdateError::Unconfirmed));
    s.confirm().unwrap();
    assert_eq!(s.begin(), Ok(Slot::A));
    // and an image for A now goes there
    assert_eq!(
        download(&mut s, &file_for(Slot::A, &body(3, 50), 3), 50),
        Ok(Slot::A)
    );
}

#[test]
fn a_flipped_bit_in_flash_makes_the_slot_unbootable() {
    let mut s = factory();
    download(&mut s, &file(&body(2, 300), 2), 300).unwrap();
    // corrupt one body byte of slot B in flash (bits can only be cleared)
    let at = 32 * 256 + 1024 + 10;
    let b = s.flash_mut().bytes_mut().nth(at).unwrap();
    *b &= 0x0F;
    let (_, d) = power_cycle(s);
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::A, false)));
}

#[test]
fn resume_sees_the_running_slot_as_the_boot_loader_left_it() {
    // a separate boot loader ran boot() and started B on trial
    let mut s = factory();
    assert_eq!(download(&mut s, &file(&body(2, 700), 2), 64), Ok(Slot::B));
    let (s, d) = power_cycle(s);
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::B, true)));
    // the image in B: on trial, confirms itself
    let mut app = BootSlots::resume(s.into_inner(), Slot::B).unwrap();
    assert_eq!((app.active(), app.on_trial()), (Some(Slot::B), true));
    app.confirm().unwrap();
    // the next start of B: confirmed, nothing to do
    let app = BootSlots::resume(app.into_inner(), Slot::B).unwrap();
    assert!(!app.on_trial());
    let (_, d) = power_cycle(app);
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::B, false)));
    assert_eq!(BootSlots::<Ram>::body_offset(), 1024);
    assert_eq!(BootSlots::<Ram>::slot_len(), 32 * 256);
}

#[test]
fn resume_takes_the_running_images_security_counter_as_the_floor() {
    let mut s = factory();
    let f = signed(Slot::B, &body(2, 700), 2, 7, &dev_seed());
    assert_eq!(download(&mut s, &f, 64), Ok(Slot::B));
    let (s, _) = power_cycle(s);
    let mut app = BootSlots::resume(s.into_inner(), Slot::B).unwrap();
    assert_eq!(app.security_floor(), 7);
    app.confirm().unwrap();
    // a download below the running image's counter is refused at the header
    let older = signed(Slot::A, &body(3, 700), 3, 6, &dev_seed());
    assert_eq!(download(&mut app, &older, 64), Err(UpdateError::Downgrade));
}
