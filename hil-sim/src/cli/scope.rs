//! `hil-sim scope-plot`: a scope trace (CSV) as SVG and PNG.

use super::args::ScopePlotArgs;
use hil_sim::scope_plot::{svg_to_png, ScopeTrace};

/// Reads the CSV, writes the SVG and, where a converter runs, the PNG.
pub fn plot(a: &ScopePlotArgs) -> Result<(), String> {
    let text = std::fs::read_to_string(&a.csv).map_err(|e| format!("{}: {e}", a.csv.display()))?;
    let trace = ScopeTrace::from_csv(&text).map_err(|e| format!("{}: {e}", a.csv.display()))?;
    let svg_path = a.svg.clone().unwrap_or_else(|| a.csv.with_extension("svg"));
    let png_path = a.png.clone().unwrap_or_else(|| a.csv.with_extension("png"));
    std::fs::write(&svg_path, trace.svg(&a.title)?).map_err(|e| format!("{}: {e}", svg_path.display()))?;
    println!(
        "{} samples of {} channels: {}",
        trace.t_ms.len(),
        trace.channels.len(),
        svg_path.display()
    );
    match svg_to_png(&svg_path, &png_path) {
        Ok(()) => println!("{}", png_path.display()),
        Err(e) => println!("no PNG: {e}"),
    }
    Ok(())
}
