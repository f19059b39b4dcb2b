//! A trace the drive's scope recorded (group T, issue 35), as the host
//! reads it back (`hil-sim/tests/soem/scope.py` writes it as CSV: the time
//! relative to the trigger in ms, then one column per channel), and its
//! plot: one panel per channel, the trigger marked (`hil-sim scope-plot`).

use crate::plot::{draw_panels, shown_at, Line};
use plotters::style::{RGBColor, BLACK, BLUE, CYAN, GREEN, MAGENTA, RED};
use std::path::Path;
use std::process::Command;

/// Colours of channels 1…8.
const COLOURS: [RGBColor; 8] = [
    BLUE,
    RED,
    GREEN,
    BLACK,
    MAGENTA,
    CYAN,
    RGBColor(200, 120, 0),
    RGBColor(120, 60, 160),
];

/// A trace: time and the channels' samples.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ScopeTrace {
    /// Time of each sample relative to the trigger sample, ms.
    pub t_ms: Vec<f64>,
    /// Each channel's name (its CSV header) and samples.
    pub channels: Vec<(String, Vec<f64>)>,
}

impl ScopeTrace {
    /// Parses the CSV `scope.py` writes: a header line (`time [ms]`, then
    /// the channels' names), then one line of numbers per sample.
    pub fn from_csv(text: &str) -> Result<Self, String> {
        let mut lines = text.lines();
        let header = lines.next().ok_or("an empty trace")?;
        let mut names = header.split(',').map(str::trim);
        names.next().ok_or("no time column")?;
        let mut trace = Self {
            t_ms: Vec::new(),
            channels: names.map(|n| (n.to_string(), Vec::new())).collect(),
        };
        for (k, line) in lines.enumerate().filter(|(_, l)| !l.trim().is_empty()) {
            let mut cells = line.split(',').map(|c| c.trim().parse::<f64>());
            let bad = |what: &str| format!("line {}: {what}", k + 2);
            trace.t_ms.push(
                cells
                    .next()
                    .ok_or_else(|| bad("no time"))?
                    .map_err(|e| bad(&e.to_string()))?,
            );
            for (_, values) in trace.channels.iter_mut() {
                values.push(
                    cells
                        .next()
                        .ok_or_else(|| bad("a column short"))?
                        .map_err(|e| bad(&e.to_string()))?,
                );
            }
            if cells.next().is_some() {
                return Err(bad("a column too many"));
            }
        }
        Ok(trace)
    }

    /// The channel named `name` (its CSV header).
    pub fn channel(&self, name: &str) -> Option<&[f64]> {
        self.channels
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }

    /// The plot: a panel per channel over time, the trigger (t = 0) marked.
    pub fn svg(&self, title: &str) -> Result<String, String> {
        let series: Vec<(&str, Vec<Line>)> = self
            .channels
            .iter()
            .zip(COLOURS.iter().cycle())
            .map(|((name, v), &c)| (name.as_str(), vec![(v.as_slice(), c, name.as_str())]))
            .collect();
        let phases = [(0.0, "trigger".to_string())];
        let height = 80 + 220 * u32::try_from(series.len()).unwrap_or(8);
        shown_at((1100, height), |backend| {
            draw_panels(backend, title, &self.t_ms, &series, &phases)
        })
    }
}

/// `svg` (a file) rendered to `png` with librsvg's `rsvg-convert`, else
/// ImageMagick's `convert`; `Err` when neither runs.
pub fn svg_to_png(svg: &Path, png: &Path) -> Result<(), String> {
    let tries = [
        (
            "rsvg-convert",
            vec!["-o".as_ref(), png.as_os_str(), svg.as_os_str()],
        ),
        ("convert", vec![svg.as_os_str(), png.as_os_str()]),
    ];
    let mut why = Vec::new();
    for (tool, args) in tries {
        match Command::new(tool).args(args).output() {
            Ok(out) if out.status.success() => return Ok(()),
            Ok(out) => why.push(format!("{tool}: {}", out.status)),
            Err(e) => why.push(format!("{tool}: {e}")),
        }
    }
    Err(why.join("; "))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 35, the scope's host side: the CSV reads back column by column;
    /// a short or long line is refused with its line number; the plot has a
    /// polyline per channel.
    #[test]
    fn issue35_scope_csv_reads_back_and_plots_a_panel_per_channel() {
        let csv = "time [ms],a [inc/s],b [inc]\n-1.000,1,10\n0.000,2,20\n1.000,3,30\n";
        let t = ScopeTrace::from_csv(csv).unwrap();
        assert_eq!(t.t_ms, [-1.0, 0.0, 1.0]);
        assert_eq!(t.channel("a [inc/s]").unwrap(), [1.0, 2.0, 3.0]);
        assert_eq!(t.channel("b [inc]").unwrap(), [10.0, 20.0, 30.0]);
        assert!(ScopeTrace::from_csv("time [ms],a\n1,2,3\n")
            .unwrap_err()
            .contains("line 2"));
        assert!(ScopeTrace::from_csv("time [ms],a,b\n1,2\n")
            .unwrap_err()
            .contains("line 2"));
        let svg = t.svg("test").unwrap();
        assert!(svg.matches("<polyline").count() >= 2);
        assert!(svg.contains("trigger"));
    }
}
