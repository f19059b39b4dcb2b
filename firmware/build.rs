//! Puts the memory layout of the selected board where cortex-m-rt's `link.x`
//! finds it (`INCLUDE memory.x`): the reference board's `../memory.x`, or
//! `qemu/memory.x` for the QEMU builds (`qemu`, `qemu-pn`), or
//! `qemu-mps2/memory.x` and its interrupt names (`device.x`) for the
//! MPS2-AN386 QEMU build (`mps2-pn`). The boot loaders (`boot-board`,
//! `boot-mps2`) and the images linked for a firmware slot (`FIRMWARE_SLOT=a|b`:
//! the board images, the `mps2-slot` test image) get the same file with its
//! FLASH region replaced by theirs (docs/flashing.md, "Flash layout").
use std::{env, fs, path::PathBuf};

/// The FLASH line of the reference board's `../memory.x` (a standalone image
/// over the whole flash) and of `qemu-mps2/memory.x`.
const BOARD_FLASH: &str = "FLASH : ORIGIN = 0x08000000, LENGTH = 2048K";
const MPS2_FLASH: &str = "FLASH : ORIGIN = 0x00000000, LENGTH = 256K";

/// The FLASH region of a linked-for-a-slot or boot-loader image (the layout of
/// docs/flashing.md and crates/bootloader: a slot's body starts 1 KiB after its
/// header, so the region is the slot minus 1 KiB).
fn flash_region(image: &str) -> &'static str {
    match image {
        // boot loader budget: 24 KiB of S0..S1, read by the boot ROM at 0x0C00_0000
        "board-boot" => "FLASH : ORIGIN = 0x0C000000, LENGTH = 24K",
        // slot A = S9..S10 (512 KiB at 0x0C04_0000), run through the cached alias
        "board-a" => "FLASH : ORIGIN = 0x08040400, LENGTH = 523264",
        // slot B = S11..S12 (512 KiB at 0x0C0C_0000)
        "board-b" => "FLASH : ORIGIN = 0x080C0400, LENGTH = 523264",
        "mps2-boot" => "FLASH : ORIGIN = 0x00000000, LENGTH = 24K",
        // slots of 64 KiB at 0x8000 and 0x1_8000 (bootloader::mps2)
        "mps2-a" => "FLASH : ORIGIN = 0x00008400, LENGTH = 64512",
        "mps2-b" => "FLASH : ORIGIN = 0x00018400, LENGTH = 64512",
        _ => unreachable!("unknown image {image}"),
    }
}

/// `FIRMWARE_SLOT`: `a` or `b` links the image for that slot, unset for the
/// standalone link.
fn slot() -> Option<&'static str> {
    match env::var("FIRMWARE_SLOT").ok().as_deref() {
        None | Some("") => None,
        Some("a" | "A") => Some("a"),
        Some("b" | "B") => Some("b"),
        Some(other) => panic!("FIRMWARE_SLOT={other}: expected a or b"),
    }
}

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let on = |f: &str| env::var_os(f).is_some();
    let qemu = on("CARGO_FEATURE_QEMU") || on("CARGO_FEATURE_QEMU_PN");
    let board = on("CARGO_FEATURE_BOARD") || on("CARGO_FEATURE_BOARD_PN");
    let mps2_foc = on("CARGO_FEATURE_MPS2_FOC");
    let mps2 = on("CARGO_FEATURE_MPS2_PN");
    let boot_board = on("CARGO_FEATURE_BOOT_BOARD");
    let boot_mps2 = on("CARGO_FEATURE_BOOT_MPS2");
    let mps2_slot = on("CARGO_FEATURE_MPS2_SLOT");
    println!("cargo:rerun-if-env-changed=FIRMWARE_SLOT");
    let boot_images = [boot_board, boot_mps2, mps2_slot].iter().filter(|&&b| b).count();
    if boot_images > 0 && (boot_images > 1 || qemu || board || mps2) {
        panic!("features `boot-board`, `boot-mps2` and `mps2-slot` each build one image: build it alone with --no-default-features");
    }
    if mps2_foc && (qemu || board || mps2 || boot_images > 0) {
        panic!("feature `mps2-foc` builds one image: build it alone with --no-default-features --features mps2-foc");
    }
    if mps2 && (qemu || board) {
        panic!("feature `mps2-pn` selects QEMU's MPS2-AN386: build it alone with --no-default-features --features mps2-pn");
    }
    if qemu && board {
        panic!("features `board`/`board-pn` and `qemu`/`qemu-pn` select different chips: build QEMU with --no-default-features --features qemu (or qemu-pn)");
    }
    if mps2 {
        // cortex-m-rt's `device` feature includes device.x: the handlers of
        // the image's own vector table (src/bin/mps2_pn.rs), DefaultHandler
        // unless bound
        fs::write(
            out.join("device.x"),
            "PROVIDE(ETHERNET = DefaultHandler);\nPROVIDE(CONTROL = DefaultHandler);\n",
        )
        .expect("write device.x");
    }
    let slot = slot();
    // (memory layout file, the FLASH line to replace in it)
    let (src, image) = if boot_board {
        ("../memory.x", Some("board-boot".to_string()))
    } else if boot_mps2 {
        ("qemu-mps2/memory.x", Some("mps2-boot".to_string()))
    } else if mps2_slot {
        let s = slot.expect("the mps2-slot image is linked for a slot: set FIRMWARE_SLOT=a or b");
        ("qemu-mps2/memory.x", Some(format!("mps2-{s}")))
    } else if mps2 || mps2_foc {
        ("qemu-mps2/memory.x", None)
    } else if qemu {
        ("qemu/memory.x", None)
    } else {
        // the board images: standalone (whole flash) unless FIRMWARE_SLOT is set
        ("../memory.x", slot.map(|s| format!("board-{s}")))
    };
    let mut layout = fs::read_to_string(src).expect("read memory layout");
    if mps2 {
        // the PROFINET image on the MPS2 (4 MiB of code memory): the board's
        // PROFINET image's budget (288 KiB, size-budget.toml) fits, 256K no
        // longer does since the motor actions joined the PROFINET drive
        assert!(layout.contains(MPS2_FLASH), "{src} has no line `{MPS2_FLASH}`");
        layout = layout.replace(MPS2_FLASH, "FLASH : ORIGIN = 0x00000000, LENGTH = 320K");
    }
    if let Some(image) = image {
        let from = if src.contains("mps2") {
            MPS2_FLASH
        } else {
            BOARD_FLASH
        };
        assert!(layout.contains(from), "{src} has no line `{from}`");
        layout = layout.replace(from, flash_region(&image));
    }
    if boot_board || boot_mps2 {
        // the boot loader's service table (boot::BootApi, src/bootapi.rs) at a
        // fixed address: BOOT_API_OFFSET (0x400) after the start, right after
        // the vector table; the code follows it
        layout.push_str(
            "\n/* the boot loader's service table (boot::BootApi) at ORIGIN(FLASH) + 0x400 (build.rs) */\n\
             SECTIONS\n{\n  .boot_api ORIGIN(FLASH) + 0x400 :\n  {\n    KEEP(*(.boot_api));\n  } > FLASH\n}\n\
             INSERT AFTER .vector_table;\n_stext = ORIGIN(FLASH) + 0x440;\n",
        );
    }
    fs::write(out.join("memory.x"), layout).expect("write memory layout");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={src}");
    println!("cargo:rerun-if-changed=build.rs");
}
