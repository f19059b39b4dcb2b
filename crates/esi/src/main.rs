//! Writes the ESI files: `cargo run -p esi [-- DIR]` (default: the
//! workspace's `esi/`). The test `esi_files_are_current` does the same with
//! `UPDATE_ESI=1` and fails when the checked-in files differ.

use std::path::PathBuf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args_os()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../esi")));
    std::fs::create_dir_all(&dir)?;
    for (name, text) in esi::files()? {
        let path = dir.join(&name);
        std::fs::write(&path, text)?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
