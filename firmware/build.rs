//! Puts the memory layout of the selected board where cortex-m-rt's `link.x`
//! finds it (`INCLUDE memory.x`): the reference board's `../memory.x`, or
//! `qemu/memory.x` for the QEMU build.
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let qemu = env::var_os("CARGO_FEATURE_QEMU").is_some();
    let board = env::var_os("CARGO_FEATURE_BOARD").is_some();
    if qemu && board {
        panic!("features `board` and `qemu` select different chips: build QEMU with --no-default-features --features qemu");
    }
    let src = if qemu { "qemu/memory.x" } else { "../memory.x" };
    fs::copy(src, out.join("memory.x")).expect("copy memory layout");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={src}");
    println!("cargo:rerun-if-changed=build.rs");
}
