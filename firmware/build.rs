//! Puts the memory layout of the selected board where cortex-m-rt's `link.x`
//! finds it (`INCLUDE memory.x`): the reference board's `../memory.x`, or
//! `qemu/memory.x` for the QEMU builds (`qemu`, `qemu-pn`).
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let on = |f: &str| env::var_os(f).is_some();
    let qemu = on("CARGO_FEATURE_QEMU") || on("CARGO_FEATURE_QEMU_PN");
    let board = on("CARGO_FEATURE_BOARD") || on("CARGO_FEATURE_BOARD_PN");
    if qemu && board {
        panic!("features `board`/`board-pn` and `qemu`/`qemu-pn` select different chips: build QEMU with --no-default-features --features qemu (or qemu-pn)");
    }
    let src = if qemu { "qemu/memory.x" } else { "../memory.x" };
    fs::copy(src, out.join("memory.x")).expect("copy memory layout");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={src}");
    println!("cargo:rerun-if-changed=build.rs");
}
