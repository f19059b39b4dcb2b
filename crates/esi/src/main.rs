//! Writes the ESI files: `cargo run -p esi [-- DIR]` (default: the
//! workspace's `esi/`). The test `esi_files_are_current` does the same with
//! `UPDATE_ESI=1` and fails when the checked-in files differ.

use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let default = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../esi"));
    desc_xml::write_all(default, &esi::files()?)?;
    Ok(())
}
