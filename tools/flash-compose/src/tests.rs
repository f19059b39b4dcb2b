use crate::*;
use boot::SlotState;
use bootloader::ImageFault;

/// The development key pair's secret seed (keys/dev-ed25519.key).
fn dev_seed() -> [u8; 32] {
    boot::parse_key_hex(include_str!("../../../keys/dev-ed25519.key")).unwrap()
}

fn info(at: u32, version: u32) -> foe_image::ImageInfo {
    foe_image::ImageInfo {
        version,
        load_address: at,
        security_counter: 0,
    }
}

/// An update file of a body linked for `slot` (vector table: stack at the end
/// of RAM, reset handler 0x41 into the body).
fn image(slot: Slot, len: usize, version: u32) -> Vec<u8> {
    image_signed(slot, len, version, &dev_seed())
}

/// [`image`] signed with `seed`.
fn image_signed(slot: Slot, len: usize, version: u32, seed: &[u8; 32]) -> Vec<u8> {
    let at = mps2::LAYOUT
        .body_address::<mps2::SlotFlash<'static, NoMirror>>(slot)
        .unwrap();
    let mut body = vec![0x5A; len];
    body[..4].copy_from_slice(&mps2::LAYOUT.ram_end.to_le_bytes());
    body[4..8].copy_from_slice(&(at + 0x41).to_le_bytes());
    foe_image::update_file(&body, info(at, version), seed).unwrap()
}

fn run(steps: &[Step]) -> (Vec<u8>, Vec<String>) {
    let mut log = Vec::new();
    let f = compose(&[0xAB; 100], steps, &mut |l| log.push(l)).unwrap();
    (f, log)
}

/// The states of the file's slot region and the slot the boot loader starts.
fn boot(file: &[u8]) -> ([SlotState; 2], Option<Slot>) {
    let mut region = file[mps2::SLOTS_BASE as usize..].to_vec();
    let (states, start) = boot_start(&mut region);
    (states, start.map(|st| st.slot))
}

fn boot_start(region: &mut [u8]) -> ([SlotState; 2], Option<bootloader::Start>) {
    let mut s = BootSlots::with_base(mps2::SlotFlash::new(region, NoMirror), mps2::SLOTS_BASE);
    let states = s.states().unwrap();
    match select(&mut s, &mps2::LAYOUT, &PUBLIC_KEY) {
        Outcome::Start(st) => (states, Some(st)),
        Outcome::Halt { .. } => (states, None),
    }
}

#[test]
fn an_image_signed_with_another_key_is_installed_but_never_started() {
    let mut steps = factory();
    steps.push(Step::Install(image_signed(Slot::B, 5000, 2, &[0x33; 32])));
    let (f, log) = run(&steps);
    // valid CRC: the slot is pending as crates/boot's marks and CRC see it
    assert_eq!(log.last().unwrap(), "flash: slot A confirmed, slot B pending");
    let mut region = f[mps2::SLOTS_BASE as usize..].to_vec();
    let (_, st) = boot_start(&mut region);
    let st = st.unwrap();
    assert_eq!(st.slot, Slot::A);
    assert_eq!(st.fallback, Some(ImageFault::Signature));
}

fn factory() -> Vec<Step> {
    vec![Step::Install(image(Slot::A, 3000, 1)), Step::Reset, Step::Confirm]
}

#[test]
fn the_file_is_the_boot_loader_then_the_slot_region() {
    let (f, log) = run(&factory());
    assert_eq!(f.len(), mps2::FILE_LEN);
    assert!(f[..100].iter().all(|&b| b == 0xAB));
    assert!(f[100..mps2::SLOTS_BASE as usize].iter().all(|&b| b == 0xFF));
    // slot A's header at the region's start, its body 1 KiB later
    assert_eq!(&f[0x8000..0x8004], b"SC6F");
    assert_eq!(&f[0x8400..0x8404], &mps2::LAYOUT.ram_end.to_le_bytes());
    assert_eq!(log.last().unwrap(), "flash: slot A confirmed, slot B empty");
    assert_eq!(boot(&f).1, Some(Slot::A));
}

#[test]
fn a_new_image_is_pending_and_a_flipped_byte_makes_it_unbootable() {
    let mut steps = factory();
    steps.push(Step::Install(image(Slot::B, 5000, 2)));
    let (f, _) = run(&steps);
    assert_eq!(
        boot(&f),
        (
            [SlotState::Confirmed { seq: 1 }, SlotState::Pending { seq: 2 }],
            Some(Slot::B)
        )
    );
    steps.push(Step::Flip(1000));
    let (f, log) = run(&steps);
    assert_eq!(log[4], "flip: slot B body byte 1000");
    assert_eq!(
        boot(&f),
        ([SlotState::Confirmed { seq: 1 }, SlotState::Empty], Some(Slot::A))
    );
}

#[test]
fn a_cut_download_leaves_the_old_image() {
    let mut steps = factory();
    steps.push(Step::Cut(image(Slot::B, 5000, 2), 7));
    let (f, log) = run(&steps);
    assert!(log[3].starts_with("cut: power lost at flash operation 7 of the download into slot B"));
    assert_eq!(
        boot(&f),
        ([SlotState::Confirmed { seq: 1 }, SlotState::Empty], Some(Slot::A))
    );
    // a cut after the download's last operation is an error of the scenario
    let mut steps = factory();
    steps.push(Step::Cut(image(Slot::B, 100, 2), 1000));
    assert!(compose(&[], &steps, &mut |_| {}).is_err());
}

#[test]
fn steps_parse_from_the_command_line() {
    let args: Vec<String> = ["install", "x", "reset", "confirm", "flip", "7", "cut", "y", "3"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let read = |p: &str| Ok(p.as_bytes().to_vec());
    assert_eq!(
        parse_steps(&args, &read),
        Ok(vec![
            Step::Install(b"x".to_vec()),
            Step::Reset,
            Step::Confirm,
            Step::Flip(7),
            Step::Cut(b"y".to_vec(), 3)
        ])
    );
    assert!(parse_steps(&["flip".to_string()], &read).is_err());
    assert!(parse_steps(&["boot".to_string()], &read).is_err());
}

#[test]
fn the_board_file_starts_at_the_boot_loader_and_ends_after_slot_b() {
    type Board = MemFlash<'static, NoMirror, { xmc4800::SECTOR }, { xmc4800::SECTORS }, { xmc4800::WRITE }>;
    let at = xmc4800::LAYOUT.body_address::<Board>(Slot::A).unwrap();
    assert_eq!(at, 0x0804_0400);
    let mut body = vec![0x5A; 4000];
    body[..4].copy_from_slice(&xmc4800::LAYOUT.ram_end.to_le_bytes());
    body[4..8].copy_from_slice(&(at + 0x41).to_le_bytes());
    let steps = [
        Step::Install(foe_image::update_file(&body, info(at, 9), &dev_seed()).unwrap()),
        Step::Reset,
        Step::Confirm,
    ];
    let mut log = Vec::new();
    let f = compose_for(Target::Xmc4800, &[0xAB; 64], &steps, &mut |l| log.push(l)).unwrap();
    assert_eq!(f.len(), 0x4_0000 + 4 * 256 * 1024);
    assert_eq!(&f[0x4_0000..0x4_0004], b"SC6F");
    assert_eq!(&f[0x4_0400..0x4_0404], &xmc4800::LAYOUT.ram_end.to_le_bytes());
    assert_eq!(log.last().unwrap(), "flash: slot A confirmed, slot B empty");
    // a boot loader larger than S0..S1 does not fit
    assert!(compose_for(Target::Xmc4800, &[0; 32 * 1024 + 1], &[], &mut |_| {}).is_err());
}
