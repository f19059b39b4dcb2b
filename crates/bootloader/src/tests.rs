extern crate std;
use std::vec;
use std::vec::Vec;

use crate::*;
use boot::PowerCut;

/// The QEMU geometry (4 KiB sectors, 256-byte units, 64 KiB per slot).
type Mem<'a> = mps2::SlotFlash<'a, NoMirror>;
const L: Layout = mps2::LAYOUT;

/// An image body linked for `slot`: a vector table (stack at the end of RAM,
/// reset handler 0x40 into the body), then filler.
fn body_for(slot: Slot, len: usize, fill: u8) -> Vec<u8> {
    let at = L.body_address::<Mem>(slot).unwrap();
    let mut b = vec![fill; len];
    b[..4].copy_from_slice(&L.ram_end.to_le_bytes());
    b[4..8].copy_from_slice(&(at + 0x40 + 1).to_le_bytes());
    b
}

/// The development key pair's secret seed (keys/dev-ed25519.key).
fn dev_seed() -> [u8; 32] {
    boot::parse_key_hex(include_str!("../../../keys/dev-ed25519.key")).unwrap()
}

/// Another key pair's seed: not the boot loader's.
const OTHER_SEED: [u8; 32] = [0x5A; 32];

/// The update file of `body` whose header names `slot`'s load address,
/// signed with `seed`.
fn signed(slot: Slot, body: &[u8], version: u32, seed: &[u8; 32]) -> Vec<u8> {
    let load = L.body_address::<Mem>(slot).unwrap();
    let mut h = ImageHeader::for_body(body, version, load, 0);
    h.sign(body, seed);
    let mut f = h.to_bytes().to_vec();
    f.extend_from_slice(body);
    f
}

/// The update file for `slot`, signed with the development key.
fn file(slot: Slot, body: &[u8], version: u32) -> Vec<u8> {
    signed(slot, body, version, &dev_seed())
}

/// The slots of the QEMU layout over `f`, mapped where the images run.
fn slots<F: Flash>(f: F) -> BootSlots<F> {
    BootSlots::with_base(f, L.region_xip)
}

/// The running image's view of the slots (it was started from `slot`).
fn resume<F: Flash>(f: F, slot: Slot) -> BootSlots<F> {
    BootSlots::resume_with_base(f, L.region_xip, slot).unwrap()
}

fn install<F: Flash>(s: &mut BootSlots<F>, f: &[u8]) -> Result<Slot, boot::UpdateError> {
    s.begin()?;
    for c in f.chunks(100) {
        s.write(c)?;
    }
    s.finish()
}

fn start_of(o: Outcome) -> Start {
    match o {
        Outcome::Start(s) => s,
        other => panic!("expected a start, got {other:?}"),
    }
}

/// Slot A holds a confirmed image (version 1).
fn factory(mem: &mut [u8]) {
    let mut s = slots(Mem::new(mem, NoMirror));
    assert_eq!(
        install(&mut s, &file(Slot::A, &body_for(Slot::A, 3000, 0xA1), 1)),
        Ok(Slot::A)
    );
    let mut s = slots(s.into_inner());
    let st = start_of(select(&mut s, &L, &PUBLIC_KEY));
    assert_eq!((st.slot, st.decision.trial), (Slot::A, true));
    let mut app = resume(s.into_inner(), Slot::A);
    app.confirm().unwrap();
}

/// The running image in `slot` installs `f` into the other slot.
fn update(mem: &mut [u8], running: Slot, f: &[u8]) -> Result<Slot, boot::UpdateError> {
    let mut app = resume(Mem::new(mem, NoMirror), running);
    install(&mut app, f)
}

/// The running A downloads version 2 into B (5000 bytes of 0xB2).
fn update_to_b(mem: &mut [u8]) -> Result<Slot, boot::UpdateError> {
    update(mem, Slot::A, &file(Slot::B, &body_for(Slot::B, 5000, 0xB2), 2))
}

fn boot(mem: &mut [u8]) -> Outcome {
    select(&mut slots(Mem::new(mem, NoMirror)), &L, &PUBLIC_KEY)
}

/// [`check_image`] of slot B in `mem`, as the boot loader would judge it.
fn check_slot_b(mem: &mut [u8]) -> Result<Entry, ImageFault> {
    check_image(&mut slots(Mem::new(mem, NoMirror)), Slot::B, &L, &PUBLIC_KEY)
}

fn region() -> Vec<u8> {
    vec![0xFF; mps2::REGION_LEN]
}

#[test]
fn an_empty_flash_halts() {
    let mut mem = region();
    assert_eq!(
        boot(&mut mem),
        Outcome::Halt {
            error: None,
            fault: None
        }
    );
}

#[test]
fn the_layout_puts_each_body_after_its_header_and_marks() {
    assert_eq!(BootSlots::<Mem>::body_offset(), 1024);
    assert_eq!(L.body_address::<Mem>(Slot::A), Some(0x8400));
    assert_eq!(L.body_address::<Mem>(Slot::B), Some(0x1_8400));
    assert_eq!(L.slot_at::<Mem>(0x1_8400), Some(Slot::B));
    assert_eq!(L.slot_at::<Mem>(0x1_8000), None);
    // the board: bodies at 1 KiB into 512 KiB slots, cached alias
    type Board = MemFlash<'static, NoMirror, { xmc4800::SECTOR }, { xmc4800::SECTORS }, { xmc4800::WRITE }>;
    let b = xmc4800::LAYOUT;
    assert_eq!(b.body_address::<Board>(Slot::A), Some(0x0804_0400));
    assert_eq!(b.body_address::<Board>(Slot::B), Some(0x080C_0400));
}

#[test]
fn a_confirmed_image_starts_with_its_vector_table() {
    let mut mem = region();
    factory(&mut mem);
    let st = start_of(boot(&mut mem));
    assert_eq!(st.slot, Slot::A);
    assert!(!st.decision.trial);
    assert_eq!((st.version, st.fallback, st.marks_failed), (1, None, None));
    assert_eq!(
        st.entry,
        Entry {
            vtor: 0x8400,
            msp: 0x2002_0000,
            reset: 0x8441
        }
    );
}

#[test]
fn a_new_image_starts_on_trial_and_stays_once_confirmed() {
    let mut mem = region();
    factory(&mut mem);
    assert_eq!(update_to_b(&mut mem), Ok(Slot::B));
    let st = start_of(boot(&mut mem));
    assert_eq!((st.slot, st.decision.trial, st.version), (Slot::B, true, 2));
    assert_eq!(st.entry.vtor, 0x1_8400);
    let mut app = resume(Mem::new(&mut mem, NoMirror), Slot::B);
    assert!(app.on_trial());
    app.confirm().unwrap();
    for _ in 0..2 {
        let st = start_of(boot(&mut mem));
        assert_eq!((st.slot, st.decision.trial), (Slot::B, false));
    }
}

#[test]
fn an_unconfirmed_image_is_rolled_back_at_the_next_reset() {
    let mut mem = region();
    factory(&mut mem);
    update_to_b(&mut mem).unwrap();
    assert_eq!(start_of(boot(&mut mem)).slot, Slot::B);
    // B never confirms
    let st = start_of(boot(&mut mem));
    assert_eq!((st.slot, st.decision.rolled_back), (Slot::A, Some(Slot::B)));
    assert_eq!(start_of(boot(&mut mem)).slot, Slot::A);
}

#[test]
fn a_body_byte_flipped_after_the_download_is_never_started() {
    let mut mem = region();
    factory(&mut mem);
    update_to_b(&mut mem).unwrap();
    let at = BootSlots::<Mem>::slot_len() + BootSlots::<Mem>::body_offset() + 1234;
    mem[at] ^= 0x10;
    for _ in 0..2 {
        let st = start_of(boot(&mut mem));
        assert_eq!((st.slot, st.decision.trial, st.version), (Slot::A, false, 1));
    }
    assert_eq!(check_slot_b(&mut mem), Err(ImageFault::NotBootable));
}

#[test]
fn a_power_cut_at_any_point_of_a_download_leaves_the_old_image_running() {
    let f = file(Slot::B, &body_for(Slot::B, 9000, 0xB3), 2);
    let mut cuts = 0;
    for left in 0.. {
        let mut mem = region();
        factory(&mut mem);
        let flash = PowerCut::after(Mem::new(&mut mem, NoMirror), left);
        let mut app = resume(flash, Slot::A);
        if install(&mut app, &f).is_ok() {
            break;
        }
        cuts += 1;
        let st = start_of(boot(&mut mem));
        assert_eq!(
            (st.slot, st.decision.trial, st.version),
            (Slot::A, false, 1),
            "cut after {left} operations"
        );
    }
    // 3 sectors erased, 1 header unit, 36 body units (9000 bytes), the VALID mark
    assert_eq!(cuts, 3 + 1 + 36 + 1);
}

#[test]
fn an_image_linked_for_the_other_slot_is_not_started() {
    let mut mem = region();
    factory(&mut mem);
    // linked for A, downloaded into B
    // (signed, its header naming B's load address: a build mistake)
    update(
        &mut mem,
        Slot::A,
        &file(Slot::B, &body_for(Slot::A, 2000, 0xB4), 2),
    )
    .unwrap();
    let st = start_of(boot(&mut mem));
    assert_eq!(st.slot, Slot::A);
    assert_eq!(st.decision.slot, Slot::B);
    assert_eq!(st.fallback, Some(ImageFault::BadReset(0x8441)));
    // it was marked TRIED: the next boot rolls it back without trying it
    let st = start_of(boot(&mut mem));
    assert_eq!(
        (st.slot, st.decision.rolled_back, st.fallback),
        (Slot::A, Some(Slot::B), None)
    );
}

#[test]
fn a_wrongly_signed_image_is_never_started() {
    let mut mem = region();
    factory(&mut mem);
    // valid CRC, load address and vector table; signed with another key
    let f = signed(Slot::B, &body_for(Slot::B, 5000, 0xB6), 2, &OTHER_SEED);
    update(&mut mem, Slot::A, &f).unwrap();
    let st = start_of(boot(&mut mem));
    assert_eq!((st.slot, st.version), (Slot::A, 1));
    assert_eq!(
        (st.decision.slot, st.fallback),
        (Slot::B, Some(ImageFault::Signature))
    );
    // marked TRIED when it was chosen: rolled back from now on, never started
    for _ in 0..2 {
        let st = start_of(boot(&mut mem));
        assert_eq!(
            (st.slot, st.decision.rolled_back, st.fallback),
            (Slot::A, Some(Slot::B), None)
        );
    }
    assert_eq!(check_slot_b(&mut mem), Err(ImageFault::Signature));
}

#[test]
fn a_lone_wrongly_signed_image_halts() {
    let mut mem = region();
    let mut s = slots(Mem::new(&mut mem, NoMirror));
    install(
        &mut s,
        &signed(Slot::A, &body_for(Slot::A, 600, 0xC6), 1, &OTHER_SEED),
    )
    .unwrap();
    assert_eq!(
        boot(&mut mem),
        Outcome::Halt {
            error: None,
            fault: Some((Slot::A, ImageFault::Signature))
        }
    );
}

#[test]
fn an_image_whose_header_names_another_slot_is_not_started() {
    let mut mem = region();
    factory(&mut mem);
    // the header of slot B's image rewritten to name A's load address and
    // signed again (the download itself refuses it at the header)
    let body = body_for(Slot::B, 3000, 0xB7);
    let mut h = ImageHeader::for_body(&body, 2, L.body_address::<Mem>(Slot::A).unwrap(), 0);
    h.sign(&body, &dev_seed());
    update(&mut mem, Slot::A, &file(Slot::B, &body, 2)).unwrap();
    let b = BootSlots::<Mem>::slot_len();
    mem[b..b + boot::IMAGE_HEADER_LEN].copy_from_slice(&h.to_bytes());
    let st = start_of(boot(&mut mem));
    assert_eq!((st.slot, st.fallback), (Slot::A, Some(ImageFault::LoadAddress)));
}

#[test]
fn a_lone_image_with_a_bad_stack_pointer_halts() {
    let mut mem = region();
    let mut body = body_for(Slot::A, 600, 0xC5);
    body[..4].copy_from_slice(&0x1000u32.to_le_bytes());
    let mut s = slots(Mem::new(&mut mem, NoMirror));
    install(&mut s, &file(Slot::A, &body, 7)).unwrap();
    assert_eq!(
        boot(&mut mem),
        Outcome::Halt {
            error: None,
            fault: Some((Slot::A, ImageFault::BadStack(0x1000)))
        }
    );
}

/// Reads only: every erase/write fails (a flash whose marks cannot be written).
struct ReadOnly<F>(F);

impl<F: Flash> Flash for ReadOnly<F> {
    const SECTOR: usize = F::SECTOR;
    const SECTORS: usize = F::SECTORS;
    const WRITE: usize = F::WRITE;
    fn read(&mut self, addr: u32, buf: &mut [u8]) -> Result<(), FlashError> {
        self.0.read(addr, buf)
    }
    fn erase(&mut self, _sector: u32) -> Result<(), FlashError> {
        Err(FlashError::Device)
    }
    fn write(&mut self, _addr: u32, _data: &[u8]) -> Result<(), FlashError> {
        Err(FlashError::Device)
    }
}

#[test]
fn without_marks_a_pending_image_is_not_started() {
    let mut mem = region();
    factory(&mut mem);
    update_to_b(&mut mem).unwrap();
    let mut s = slots(ReadOnly(Mem::new(&mut mem, NoMirror)));
    let st = start_of(select(&mut s, &L, &PUBLIC_KEY));
    assert_eq!((st.slot, st.decision.trial), (Slot::A, false));
    assert_eq!(st.marks_failed, Some(FlashError::Device));
    // a pending image alone: nothing starts
    let mut mem = region();
    let mut s = slots(Mem::new(&mut mem, NoMirror));
    install(&mut s, &file(Slot::A, &body_for(Slot::A, 500, 1), 1)).unwrap();
    let mut s = slots(ReadOnly(Mem::new(&mut mem, NoMirror)));
    assert_eq!(
        select(&mut s, &L, &PUBLIC_KEY),
        Outcome::Halt {
            error: None,
            fault: None
        }
    );
}

/// Records every change.
#[derive(Default)]
struct Log(Vec<(u32, usize, u8)>);

impl Mirror for Log {
    fn changed(&mut self, addr: u32, bytes: &[u8]) -> Result<(), FlashError> {
        self.0.push((addr, bytes.len(), bytes[0]));
        Ok(())
    }
}

#[test]
fn every_change_reaches_the_mirror_as_it_now_reads() {
    let mut mem = region();
    factory(&mut mem);
    let mut s = slots(mps2::SlotFlash::new(&mut mem, Log::default()));
    let st = start_of(select(&mut s, &L, &PUBLIC_KEY));
    assert_eq!(st.slot, Slot::A);
    // confirmed: the boot writes nothing
    assert!(s.flash_mut().mirror_mut().0.is_empty());
    let mut app = resume(s.into_inner(), Slot::A);
    app.begin().unwrap();
    app.write(&file(Slot::B, &body_for(Slot::B, 100, 9), 2)[..boot::IMAGE_HEADER_LEN])
        .unwrap();
    let log = &app.flash_mut().mirror_mut().0;
    // erase of B's first sector, then its header unit ("SC6F" starts with 'S')
    assert_eq!(log.as_slice(), &[(0x1_0000, 4096, 0xFF), (0x1_0000, 256, b'S')]);
}

#[test]
fn misaligned_or_out_of_range_accesses_fail() {
    let mut mem = vec![0xFF; 100];
    let mut f = mps2::SlotFlash::new(&mut mem, NoMirror);
    let mut b = [0u8; 8];
    assert_eq!(f.read(96, &mut b), Err(FlashError::OutOfRange));
    assert_eq!(f.write(8, &[0; 256]), Err(FlashError::Misaligned));
    assert_eq!(f.erase(0), Err(FlashError::OutOfRange));
    assert!(f.bytes().is_empty());
}
