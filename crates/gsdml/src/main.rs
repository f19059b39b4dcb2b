//! Writes the GSDML: `cargo run -p gsdml [-- DIR]` (default: the workspace's
//! `gsdml/`). The test `gsdml_is_current` does the same with `UPDATE_GSDML=1`
//! and fails when the checked-in file differs.

use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let default = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../gsdml"));
    desc_xml::write_all(default, &gsdml::files()?)?;
    Ok(())
}
