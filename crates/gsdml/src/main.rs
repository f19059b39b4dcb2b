//! Writes the GSDML: `cargo run -p gsdml [-- DIR]` (default: the workspace's
//! `gsdml/`). The test `gsdml_is_current` does the same with `UPDATE_GSDML=1`
//! and fails when the checked-in file differs.

use std::path::PathBuf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args_os()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../gsdml")));
    std::fs::create_dir_all(&dir)?;
    for (name, text) in gsdml::files()? {
        let path = dir.join(&name);
        std::fs::write(&path, text)?;
        println!("wrote {}", path.display());
    }
    let path = dir.join(gsdml::bitmap_file_name());
    std::fs::write(&path, gsdml::device_bitmap())?;
    println!("wrote {}", path.display());
    Ok(())
}
