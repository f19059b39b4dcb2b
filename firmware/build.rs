//! Puts the memory layout of the selected board where cortex-m-rt's `link.x`
//! finds it (`INCLUDE memory.x`): the reference board's `../memory.x`, or
//! `qemu/memory.x` for the QEMU builds (`qemu`, `qemu-pn`), or
//! `qemu-mps2/memory.x` and its interrupt names (`device.x`) for the
//! MPS2-AN386 QEMU build (`mps2-pn`).
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let on = |f: &str| env::var_os(f).is_some();
    let qemu = on("CARGO_FEATURE_QEMU") || on("CARGO_FEATURE_QEMU_PN");
    let board = on("CARGO_FEATURE_BOARD") || on("CARGO_FEATURE_BOARD_PN");
    let mps2 = on("CARGO_FEATURE_MPS2_PN");
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
    let src = if mps2 {
        "qemu-mps2/memory.x"
    } else if qemu {
        "qemu/memory.x"
    } else {
        "../memory.x"
    };
    fs::copy(src, out.join("memory.x")).expect("copy memory layout");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={src}");
    println!("cargo:rerun-if-changed=build.rs");
}
