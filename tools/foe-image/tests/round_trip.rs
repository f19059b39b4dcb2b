//! The update file `foe-image` writes, through the simulated drive's FoE
//! (Bootstrap, the slots of issue 8): the file of an ELF goes into the
//! inactive slot and boots on the next power cycle; a truncated or
//! bit-flipped file is refused with the documented FoE error (800Ch) and
//! changes nothing. Signed images (issue 18): the tool signs with a key
//! file, makes key pairs and verifies with a public key; a file of another
//! key or linked for the other slot is refused by the drive.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use drive_ecat::boot::{Slot, SlotState};
use drive_ecat::params::E54;
use drive_tests::{fw_load_address, in_boot, FoeClient, FoeReply, FwNode};
use ecat::foe::FoeError;
use hil_sim::sim::Simulation;
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A minimal 32-bit little-endian ARM executable with `segments` as
/// `PT_LOAD` program headers: (physical address, virtual address, bytes,
/// memory size).
fn elf32(segments: &[(u32, u32, Vec<u8>, u32)]) -> Vec<u8> {
    let phoff = 52u32;
    let mut data_off = phoff + 32 * segments.len() as u32;
    let mut f = vec![0x7F, b'E', b'L', b'F', 1, 1, 1, 0];
    f.extend_from_slice(&[0; 8]);
    f.extend_from_slice(&2u16.to_le_bytes()); // ET_EXEC
    f.extend_from_slice(&40u16.to_le_bytes()); // EM_ARM
    f.extend_from_slice(&1u32.to_le_bytes());
    f.extend_from_slice(&segments[0].1.to_le_bytes()); // entry
    f.extend_from_slice(&phoff.to_le_bytes());
    f.extend_from_slice(&0u32.to_le_bytes()); // no section headers
    f.extend_from_slice(&0x0500_0400u32.to_le_bytes());
    for v in [52u16, 32, segments.len() as u16, 40, 0, 0] {
        f.extend_from_slice(&v.to_le_bytes());
    }
    for (paddr, vaddr, bytes, memsz) in segments {
        for v in [1u32, data_off, *vaddr, *paddr, bytes.len() as u32, *memsz, 5, 4] {
            f.extend_from_slice(&v.to_le_bytes());
        }
        data_off += bytes.len() as u32;
    }
    for (_, _, bytes, _) in segments {
        f.extend_from_slice(bytes);
    }
    f
}

fn pattern(len: usize, seed: u8) -> Vec<u8> {
    (0..len)
        .map(|i| (i as u8).wrapping_mul(31).wrapping_add(seed))
        .collect()
}

/// The development key files in the repository.
fn dev_key() -> String {
    concat!(env!("CARGO_MANIFEST_DIR"), "/../../keys/dev-ed25519.key").to_string()
}
fn dev_pub() -> String {
    concat!(env!("CARGO_MANIFEST_DIR"), "/../../keys/dev-ed25519.pub").to_string()
}

/// A board-like image linked for the simulated drive's slot B: code at the
/// start of the slot's body, the initial values of .data stored after it
/// (run in RAM), .bss without contents.
fn board_elf() -> (Vec<u8>, Vec<u8>) {
    board_elf_at(fw_load_address(Slot::B))
}

fn board_elf_at(base: u32) -> (Vec<u8>, Vec<u8>) {
    let text = pattern(6000, 1);
    let data = pattern(300, 2);
    let elf = elf32(&[
        (base, base, text.clone(), 6000),
        // .data: loaded 0x2000 bytes after the code's start, run at 0x2000_0000
        (base + 0x2000, 0x2000_0000, data.clone(), 300),
        // .bss: no bytes in the file
        (0x2000_0200, 0x2000_0200, Vec::new(), 4096),
    ]);
    let mut body = text;
    body.resize(0x2000, 0xFF);
    body.extend_from_slice(&data);
    (elf, body)
}

fn tool(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_foe-image"))
        .args(args)
        .output()
        .expect("run foe-image")
}

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("foe-image-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn make(dir: &Path, input: &[u8], version: u32) -> Vec<u8> {
    // the factory image of FwNode has security counter 1
    make_with(dir, input, version, &dev_key(), &["--security-counter", "1"])
}

fn make_with(dir: &Path, input: &[u8], version: u32, key: &str, extra: &[&str]) -> Vec<u8> {
    let elf = dir.join("board.elf");
    std::fs::write(&elf, input).unwrap();
    let v = version.to_string();
    let mut args = vec!["make", "--version", &v, "--key", key];
    args.extend_from_slice(extra);
    args.push(elf.to_str().unwrap());
    let out = tool(&args);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "foe-image make: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    // the default name beside the input, named for the slot of the load
    // address (issue 33): one the drive takes
    let written = stdout.split(": ").next().unwrap();
    let file = std::fs::read(written).unwrap();
    let load = u32::from_le_bytes(file[20..24].try_into().unwrap());
    assert_eq!(
        Path::new(written),
        dir.join(foe_image::default_file_name(load)),
        "{stdout}"
    );
    file
}

fn line() -> RefCell<Simulation<FwNode>> {
    RefCell::new(Simulation::with_nodes(vec![FwNode::factory(20_000)]))
}

fn download(sim: &RefCell<Simulation<FwNode>>, file: &[u8]) -> Result<u32, FoeReply> {
    in_boot(sim, async |_, sd| {
        FoeClient::new().write_file(&sd, "firmware.sc6f", file).await
    })
}

#[test]
fn foe_image_of_an_elf_boots_from_the_inactive_slot() {
    let dir = temp_dir("boot");
    let (elf, body) = board_elf();
    let file = make(&dir, &elf, 7);
    // header v2: magic, body length, CRC-32 of the body, version, format,
    // load address, security counter, reserved, signature; then the body
    assert_eq!(&file[..4], b"SC6F");
    assert_eq!(
        u32::from_le_bytes(file[4..8].try_into().unwrap()) as usize,
        body.len()
    );
    assert_eq!(
        u32::from_le_bytes(file[8..12].try_into().unwrap()),
        drive_ecat::boot::crc32(&body)
    );
    assert_eq!(u32::from_le_bytes(file[12..16].try_into().unwrap()), 7);
    assert_eq!(u32::from_le_bytes(file[16..20].try_into().unwrap()), 2);
    assert_eq!(
        u32::from_le_bytes(file[20..24].try_into().unwrap()),
        fw_load_address(Slot::B),
        "the ELF's lowest load address"
    );
    assert_eq!(u32::from_le_bytes(file[24..28].try_into().unwrap()), 1);
    assert!(drive_ecat::boot::verify_file(&file, &drive_ecat::boot::DEV_PUBLIC_KEY).is_ok());
    assert_eq!(
        &file[drive_ecat::boot::IMAGE_HEADER_LEN..],
        &body[..],
        "segments at their load addresses, gap FFh"
    );
    // the tool's own check agrees, with and without the public key
    let out = tool(&["check", dir.join("firmware-slot-b.sc6f").to_str().unwrap()]);
    assert!(out.status.success());
    let out = tool(&[
        "check",
        "--pub",
        &dev_pub(),
        dir.join("firmware-slot-b.sc6f").to_str().unwrap(),
    ]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("signature verified"));
    let sim = line();
    let s = &sim;
    let node = move || std::cell::RefMut::map(s.borrow_mut(), |s| &mut s.drives_mut()[0]);
    assert_eq!(node().boot.map(|d| d.slot), Some(Slot::A));
    download(&sim, &file).expect("the drive takes the file");
    assert_eq!(
        node().slots().state(Slot::B).unwrap(),
        SlotState::Pending { seq: 2 }
    );
    assert_eq!(
        node().slots().header(Slot::B).unwrap().map(|h| h.version),
        Some(7)
    );
    node().power_cycle();
    let d = node().boot.expect("a slot starts");
    assert_eq!(
        (d.slot, d.trial),
        (Slot::B, true),
        "the new image starts on trial"
    );
    assert!(node().drive.confirm_firmware());
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn foe_image_truncated_or_flipped_is_refused_and_changes_nothing() {
    let dir = temp_dir("bad");
    let (elf, _) = board_elf();
    let file = make(&dir, &elf, 7);
    let mut flipped = file.clone();
    flipped[drive_ecat::boot::IMAGE_HEADER_LEN + 4321] ^= 0x10;
    let truncated = &file[..file.len() - 100];
    for (what, bad) in [("flipped", &flipped[..]), ("truncated", truncated)] {
        // the tool says what the drive will say
        let p = dir.join(format!("firmware-{what}.sc6f"));
        std::fs::write(&p, bad).unwrap();
        let out = tool(&["check", p.to_str().unwrap()]);
        assert!(!out.status.success(), "{what}: check refuses it");
        assert!(String::from_utf8_lossy(&out.stderr).contains("800Ch"), "{what}");
        // the drive: FoE 800Ch on the last packet, slot B stays empty, A runs
        let sim = line();
        assert_eq!(
            download(&sim, bad),
            Err(FoeReply::Error(FoeError::CHECKSUM.0)),
            "{what}"
        );
        let mut n = std::cell::RefMut::map(sim.borrow_mut(), |s| &mut s.drives_mut()[0]);
        assert_eq!(n.slots().state(Slot::B).unwrap(), SlotState::Empty, "{what}");
        assert_eq!(
            n.slots().state(Slot::A).unwrap(),
            SlotState::Confirmed { seq: 1 },
            "{what}"
        );
        n.power_cycle();
        let d = n.boot.unwrap();
        assert_eq!((d.slot, d.trial, d.rolled_back), (Slot::A, false, None), "{what}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn foe_image_refuses_what_it_cannot_make() {
    let dir = temp_dir("refuse");
    let key = dev_key();
    // `make` of `input`, version 1, the development key, `extra` options
    let make = |extra: &[&str], input: &std::path::Path| {
        let mut args = vec!["make", "--version", "1", "--key", &key];
        args.extend_from_slice(extra);
        args.push(input.to_str().unwrap());
        tool(&args)
    };
    // `make` of `input` fails, says `why`, writes nothing
    let refused = |input: &std::path::Path, why: &str| {
        let out = make(&[], input);
        assert!(!out.status.success(), "{why}");
        assert!(String::from_utf8_lossy(&out.stderr).contains(why), "{why}");
        assert!(!dir.join("firmware.sc6f").exists(), "nothing written");
    };
    // an ELF without loadable contents
    let p = dir.join("empty.elf");
    std::fs::write(&p, elf32(&[(0x2000_0000, 0x2000_0000, Vec::new(), 64)])).unwrap();
    refused(&p, "no loadable segment");
    // overlapping segments: no sensible flash contents
    let p2 = dir.join("overlap.elf");
    let two = [
        (0x0800_0000, 0x0800_0000, pattern(100, 1), 100),
        (0x0800_0040, 0x0800_0040, pattern(100, 2), 100),
    ];
    std::fs::write(&p2, elf32(&two)).unwrap();
    refused(&p2, "overlap at 0x08000040");
    // an output that cannot be written
    let out = make(&["--out", "/nonexistent/firmware.sc6f"], &p);
    assert!(!out.status.success());
    // a missing version, a missing key
    let out = tool(&["make", "--key", &dev_key(), p.to_str().unwrap()]);
    assert!(!out.status.success());
    let out = tool(&["make", "--version", "1", p.to_str().unwrap()]);
    assert!(!out.status.success());
    // a flat binary without --load-addr: no address to put into the header
    let bin = dir.join("flat.bin");
    std::fs::write(&bin, pattern(100, 3)).unwrap();
    refused(&bin, "--load-addr");
    // a key file that is no key
    let out = tool(&[
        "make",
        "--version",
        "1",
        "--key",
        bin.to_str().unwrap(),
        p2.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("not a key file"));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn foe_signature_keygen_sign_check_and_the_drive_refuses_another_key() {
    let dir = temp_dir("keygen");
    let key = dir.join("prod.key");
    let out = tool(&["keygen", "--out", key.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let seed = drive_ecat::boot::parse_key_hex(&std::fs::read_to_string(&key).unwrap()).unwrap();
    let public =
        drive_ecat::boot::parse_key_hex(&std::fs::read_to_string(dir.join("prod.pub")).unwrap()).unwrap();
    assert_eq!(
        drive_ecat::boot::public_key(&seed),
        public,
        "the pair belongs together"
    );
    assert_ne!(public, drive_ecat::boot::DEV_PUBLIC_KEY);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&key).unwrap().permissions().mode();
        assert_eq!(mode & 0o077, 0, "the secret is its owner's only");
    }
    // no overwriting
    let out = tool(&["keygen", "--out", key.to_str().unwrap()]);
    assert!(!out.status.success());
    // sign with the new key: its public key verifies, the development key does not
    let (elf, _) = board_elf();
    let file = make_with(&dir, &elf, 8, key.to_str().unwrap(), &["--security-counter", "3"]);
    let f = dir.join("firmware-slot-b.sc6f");
    let pubfile = dir.join("prod.pub");
    let out = tool(&["check", "--pub", pubfile.to_str().unwrap(), f.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stdout).contains("security counter 3"));
    let out = tool(&["check", "--pub", &dev_pub(), f.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("800Ch"));
    // the simulated drive trusts the development key only: 800Ch at the end,
    // slot B stays empty, A runs on
    let sim = line();
    assert_eq!(download(&sim, &file), Err(FoeReply::Error(FoeError::CHECKSUM.0)));
    let mut n = std::cell::RefMut::map(sim.borrow_mut(), |s| &mut s.drives_mut()[0]);
    assert_eq!(n.slots().state(Slot::B).unwrap(), SlotState::Empty);
    n.power_cycle();
    assert_eq!(n.boot.map(|d| (d.slot, d.trial)), Some((Slot::A, false)));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn foe_signature_load_address_and_security_counter_from_the_tool() {
    let dir = temp_dir("addr");
    // linked for slot A while A runs: refused at the header with 8004h
    let (elf, _) = board_elf_at(fw_load_address(Slot::A));
    let file = make(&dir, &elf, 7);
    let sim = line();
    assert_eq!(download(&sim, &file), Err(FoeReply::Error(FoeError::ILLEGAL.0)));
    // --load-addr puts another address into the header (the body is the same)
    let b = fw_load_address(Slot::B);
    let file = make_with(
        &dir,
        &elf,
        7,
        &dev_key(),
        &["--security-counter", "1", "--load-addr", &format!("{b:#x}")],
    );
    assert_eq!(u32::from_le_bytes(file[20..24].try_into().unwrap()), b);
    assert_eq!(download(&sim, &file).map(|_| ()), Ok(()));
    // a security counter below the running image's (1): 800Ah at the header
    let (elf, _) = board_elf();
    let file = make_with(&dir, &elf, 6, &dev_key(), &["--security-counter", "0"]);
    let sim = line();
    assert_eq!(download(&sim, &file), Err(FoeReply::Error(FoeError::NO_RIGHTS.0)));
    let mut n = std::cell::RefMut::map(sim.borrow_mut(), |s| &mut s.drives_mut()[0]);
    assert_eq!(n.slots().state(Slot::B).unwrap(), SlotState::Empty);
    std::fs::remove_dir_all(dir).unwrap();
}

/// The slot table of the tool (default file names, issue 33) is the
/// simulated drive's: each slot's body address is its `load_address`.
/// (The board's and mps2's are asserted in `crates/bootloader`'s tests.)
#[test]
fn e019_default_file_names_follow_the_slot_of_the_load_address() {
    let sim = hil_sim::sim::FirmwareSlots::new(hil_sim::sim::FirmwareFlash::new());
    let (_, bodies) = foe_image::KNOWN_SLOTS
        .iter()
        .find(|(layout, _)| *layout == "hil-sim")
        .unwrap();
    assert_eq!(bodies[0], sim.load_address(Slot::A));
    assert_eq!(bodies[1], sim.load_address(Slot::B));
    assert_eq!(
        foe_image::default_file_name(sim.load_address(Slot::A)),
        "firmware-slot-a.sc6f"
    );
    assert_eq!(
        foe_image::default_file_name(sim.load_address(Slot::B)),
        "firmware-slot-b.sc6f"
    );
    assert_eq!(foe_image::default_file_name(0x0804_0400), "firmware-slot-a.sc6f");
    assert_eq!(foe_image::default_file_name(0x080C_0400), "firmware-slot-b.sc6f");
    // the standalone board link (whole flash from 0x0800_0000): no slot
    assert_eq!(foe_image::default_file_name(0x0800_0000), "firmware.sc6f");
    // the tool writes one file per slot by its default name; a drive running
    // from A shows update slot 2 in E54, takes the slot-B file, refuses the
    // slot-A one with 8004h at the header, and reports the stored slot;
    // after the power cycle it runs B and shows update slot 1
    let dir = temp_dir("slots");
    let mut files = Vec::new();
    for slot in [Slot::A, Slot::B] {
        let (elf, _) = board_elf_at(fw_load_address(slot));
        let d = dir.join(format!("{slot:?}"));
        std::fs::create_dir_all(&d).unwrap();
        files.push(make(&d, &elf, 9));
        assert!(d.join(foe_image::slot_file_name(slot.index())).exists());
    }
    let e54 =
        |sim: &RefCell<Simulation<FwNode>>| sim.borrow().drives()[0].drive.objects().get(E54, 0).unwrap();
    let sim = line();
    assert_eq!(e54(&sim), 2, "running from A: the update slot is B");
    assert_eq!(
        download(&sim, &files[0]),
        Err(FoeReply::Error(FoeError::ILLEGAL.0))
    );
    assert_eq!(
        sim.borrow_mut().drives_mut()[0].drive.take_firmware_stored(),
        None
    );
    assert_eq!(download(&sim, &files[1]).map(|_| ()), Ok(()));
    let stored = sim.borrow_mut().drives_mut()[0].drive.take_firmware_stored();
    assert_eq!(stored.map(|s| (s.slot, s.version)), Some((Slot::B, 9)));
    sim.borrow_mut().drives_mut()[0].power_cycle();
    assert_eq!(sim.borrow().drives()[0].boot.map(|d| d.slot), Some(Slot::B));
    assert_eq!(e54(&sim), 1, "running from B: the update slot is A");
    std::fs::remove_dir_all(dir).unwrap();
}
