//! Time traces of a simulated run and their SVG plot: set and actual
//! position, velocity, torque and following error over time.

use nanos::Nanos;
use plotters::prelude::*;
use std::io::Write;

/// One axis' signals sampled once per master cycle.
#[derive(Debug, Default, Clone)]
pub struct Trace {
    /// Simulated time, ms.
    pub t_ms: Vec<f64>,
    /// Position set-point (607Ah), revolutions.
    pub set_rev: Vec<f64>,
    /// Position actual value (6064h), revolutions.
    pub act_rev: Vec<f64>,
    /// Velocity actual value (606Ch), rpm.
    pub vel_rpm: Vec<f64>,
    /// Torque actual value (6077h), % of rated torque.
    pub torque_pct: Vec<f64>,
    /// Following error (60F4h), increments.
    pub ferr_inc: Vec<f64>,
    /// The set position's legend (empty: "set 607Ah").
    pub set_name: String,
    /// Optional: a state per sample (e.g. a status word's state as a
    /// number), drawn as a fifth panel when not empty.
    pub state: Vec<f64>,
    /// The fifth panel's axis label.
    pub state_name: String,
    /// Optional: phases (start time in ms, name), marked in every panel.
    pub phases: Vec<(f64, String)>,
    /// Optional ([`Trace::push_currents`]): measured d current, A; with it two
    /// more panels (dq currents, phase currents).
    pub id_a: Vec<f64>,
    /// Measured q current, A.
    pub iq_a: Vec<f64>,
    /// q current reference, A.
    pub iq_ref_a: Vec<f64>,
    /// Phase currents a, b, c, A.
    pub phase_a: [Vec<f64>; 3],
}

/// One line of a panel: values, colour, legend.
pub type Line<'a> = (&'a [f64], RGBColor, &'a str);

/// Increments per revolution (2^20).
const INC_PER_REV: f64 = 1_048_576.0;

/// The plot's size as shown, pixels.
const SIZE: (u32, u32) = (1100, 1000);
/// It is drawn this many times finer and shown at [`SIZE`] (the root's
/// width and height; its viewBox stays the drawing's): plotters places every
/// point on whole drawing pixels, so at 1:1 a slow creep (1 rev in 4 s over
/// a panel of 9 rev) becomes a staircase of 1 px steps ~200 ms apart.
const FINE: u32 = 4;

/// `v` in drawing units (pixels as shown × [`FINE`]).
const fn fine(v: u32) -> u32 {
    v * FINE
}

impl Trace {
    /// Appends one sample: positions and following error in increments,
    /// velocity in increments per second, torque in 0.1 % of rated torque.
    pub fn push(
        &mut self,
        t: Nanos,
        set_inc: i32,
        act_inc: i32,
        vel_inc_s: i32,
        torque_permille: i16,
        ferr_inc: i32,
    ) {
        self.t_ms.push(t.as_ns() as f64 / 1e6);
        self.set_rev.push(f64::from(set_inc) / INC_PER_REV);
        self.act_rev.push(f64::from(act_inc) / INC_PER_REV);
        self.vel_rpm.push(f64::from(vel_inc_s) / INC_PER_REV * 60.0);
        self.torque_pct.push(f64::from(torque_permille) / 10.0);
        self.ferr_inc.push(f64::from(ferr_inc));
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t_ms.len()
    }

    /// No samples yet.
    pub fn is_empty(&self) -> bool {
        self.t_ms.is_empty()
    }

    /// Maximum and RMS of |following error| in increments.
    pub fn following_error_stats(&self) -> (f64, f64) {
        let n = self.ferr_inc.len().max(1) as f64;
        let max = self.ferr_inc.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let rms = (self.ferr_inc.iter().map(|v| v * v).sum::<f64>() / n).sqrt();
        (max, rms)
    }

    /// Appends one sample's state (the fifth panel).
    pub fn push_state(&mut self, state: f64) {
        self.state.push(state);
    }

    /// Appends one sample's currents (the electrical plant): measured id and
    /// iq, the iq reference, the phase currents a, b, c, A.
    pub fn push_currents(&mut self, id: f64, iq: f64, iq_ref: f64, phases: [f64; 3]) {
        self.id_a.push(id);
        self.iq_a.push(iq);
        self.iq_ref_a.push(iq_ref);
        for (v, x) in self.phase_a.iter_mut().zip(phases) {
            v.push(x);
        }
    }

    /// Marks the start of a phase at `t`.
    pub fn mark_phase(&mut self, t: Nanos, name: &str) {
        self.phases.push((t.as_ns() as f64 / 1e6, name.to_string()));
    }

    /// Writes a four-panel (five with a state) SVG plot to `out` (the caller opened the file
    /// before the run, so an unwritable path fails before the work is done).
    pub fn write_svg<W: Write>(&self, out: &mut W, title: &str) -> Result<(), String> {
        let svg = self.svg(title)?;
        out.write_all(svg.as_bytes()).map_err(|e| e.to_string())?;
        out.flush().map_err(|e| e.to_string())
    }

    /// The four-panel SVG plot.
    pub fn svg(&self, title: &str) -> Result<String, String> {
        // the two current panels add their height
        let size = if self.iq_a.is_empty() {
            SIZE
        } else {
            (SIZE.0, SIZE.1 + SIZE.1 / 2)
        };
        shown_at(size, |backend| self.draw(backend, title))
    }

    fn draw(&self, backend: SVGBackend<'_>, title: &str) -> Result<(), String> {
        let with_state = !self.state.is_empty();
        let with_currents = !self.iq_a.is_empty();
        let set_name = if self.set_name.is_empty() {
            "set 607Ah"
        } else {
            self.set_name.as_str()
        };
        let mut series: Vec<(&str, Vec<Line>)> = vec![
            (
                "position [rev]",
                vec![
                    (&self.set_rev, BLUE, set_name),
                    (&self.act_rev, RED, "actual 6064h"),
                ],
            ),
            ("velocity [rpm]", vec![(&self.vel_rpm, GREEN, "actual 606Ch")]),
            (
                "torque [% rated]",
                vec![(&self.torque_pct, MAGENTA, "actual 6077h")],
            ),
            ("following error [inc]", vec![(&self.ferr_inc, BLACK, "60F4h")]),
        ];
        if with_state {
            series.push((self.state_name.as_str(), vec![(&self.state, CYAN, "state")]));
        }
        if with_currents {
            series.push((
                "current dq [A]",
                vec![
                    (&self.iq_ref_a, BLUE, "iq reference"),
                    (&self.iq_a, RED, "iq measured"),
                    (&self.id_a, GREEN, "id measured"),
                ],
            ));
            let [a, b, c] = &self.phase_a;
            series.push((
                "phase currents [A]",
                vec![(a, RED, "a"), (b, GREEN, "b"), (c, BLUE, "c")],
            ));
        }
        draw_panels(backend, title, &self.t_ms, &series, &self.phases)
    }
}

/// The SVG `draw` makes, drawn `FINE` times finer and shown at `size`
/// (pixels).
pub fn shown_at(
    size: (u32, u32),
    draw: impl FnOnce(SVGBackend<'_>) -> Result<(), String>,
) -> Result<String, String> {
    let mut svg = String::new();
    draw(SVGBackend::with_string(&mut svg, (fine(size.0), fine(size.1))))?;
    // shown at its size: the root's width and height (its first attributes)
    let drawn = format!("width=\"{}\" height=\"{}\"", fine(size.0), fine(size.1));
    let shown = format!("width=\"{}\" height=\"{}\"", size.0, size.1);
    if !svg.contains(&drawn) {
        return Err("the SVG root has no width and height to set".into());
    }
    Ok(svg.replacen(&drawn, &shown, 1))
}

/// Panels one above the other over the time axis `t_ms` (ms), each with its
/// label and lines, the `phases` (start ms, name) marked in every panel and
/// named in the first: the demo's plot and the scope's (`scope_plot`).
pub fn draw_panels(
    backend: SVGBackend<'_>,
    title: &str,
    t_ms: &[f64],
    series: &[(&str, Vec<Line>)],
    phases: &[(f64, String)],
) -> Result<(), String> {
    let root = backend.into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let root = root
        .titled(title, ("sans-serif", fine(22)))
        .map_err(|e| e.to_string())?;
    let panels = root.split_evenly((series.len().max(1), 1));
    let t_end = t_ms.last().copied().unwrap_or(1.0).max(1e-3);
    let t0 = t_ms.first().copied().unwrap_or(0.0);
    for (k, (area, (label, lines))) in panels.iter().zip(series.iter()).enumerate() {
        let (lo, hi) = lines
            .iter()
            .flat_map(|(v, _, _)| v.iter())
            .fold((f64::MAX, f64::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        let (lo, hi) = if lo > hi { (-1.0, 1.0) } else { (lo, hi) };
        let pad = ((hi - lo) * 0.08).max(1e-9);
        let mut chart = ChartBuilder::on(area)
            .margin(fine(8))
            .x_label_area_size(fine(30))
            .y_label_area_size(fine(70))
            .build_cartesian_2d(t0..t_end, (lo - pad)..(hi + pad))
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("time [ms]")
            .y_desc(*label)
            .label_style(("sans-serif", fine(12)))
            .axis_desc_style(("sans-serif", fine(12)))
            .axis_style(BLACK.stroke_width(FINE))
            .bold_line_style(BLACK.mix(0.2).stroke_width(FINE))
            .light_line_style(BLACK.mix(0.08).stroke_width(FINE))
            .draw()
            .map_err(|e| e.to_string())?;
        for (n, (at, name)) in phases.iter().enumerate() {
            let (lo, hi) = (lo - pad, hi + pad);
            // alternate rows: names of phases close together stay apart
            let y = hi - (hi - lo) * 0.08 * (n % 2) as f64;
            chart
                .draw_series(LineSeries::new(
                    [(*at, lo), (*at, hi)],
                    BLACK.mix(0.3).stroke_width(FINE),
                ))
                .map_err(|e| e.to_string())?;
            if k == 0 {
                chart
                    .draw_series([Text::new(name.clone(), (*at, y), ("sans-serif", fine(12)))])
                    .map_err(|e| e.to_string())?;
            }
        }
        for (values, color, name) in lines {
            let color = *color;
            chart
                .draw_series(LineSeries::new(
                    t_ms.iter().copied().zip(values.iter().copied()),
                    color.stroke_width(FINE),
                ))
                .map_err(|e| e.to_string())?
                .label(*name)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + fine(18) as i32, y)], color.stroke_width(FINE))
                });
        }
        chart
            .configure_series_labels()
            .label_font(("sans-serif", fine(12)))
            .legend_area_size(fine(30))
            .margin(fine(10))
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK.stroke_width(FINE))
            .draw()
            .map_err(|e| e.to_string())?;
    }
    root.present().map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The y coordinates of the first polyline drawn in `stroke`, in
    /// displayed pixels (the root's width over its viewBox width).
    fn polyline_y(svg: &str, stroke: &str) -> Vec<f64> {
        let attr = |tag: &str, name: &str| -> Option<f64> {
            let at = tag.find(&format!("{name}=\""))? + name.len() + 2;
            tag[at..].split('"').next()?.parse().ok()
        };
        let root = &svg[svg.find("<svg").unwrap()..];
        let root = &root[..root.find('>').unwrap()];
        let view_w: f64 = root
            .split("viewBox=\"")
            .nth(1)
            .and_then(|v| v.split(' ').nth(2))
            .unwrap()
            .parse()
            .unwrap();
        let k = attr(root, "width").unwrap() / view_w;
        let line = svg
            .split("<polyline")
            .find(|p| p.contains(&format!("stroke=\"{stroke}\"")))
            .expect("the polyline");
        let points = line.split("points=\"").nth(1).unwrap().split('"').next().unwrap();
        points
            .split_whitespace()
            .map(|p| p.split(',').nth(1).unwrap().parse::<f64>().unwrap() * k)
            .collect()
    }

    /// A slow creep (the demo's homing: 1 rev in 4 s, in a panel spanning
    /// 9 rev) is drawn as a slope, not as a staircase of whole pixels
    /// (plotters' backends place points on integer coordinates): the plot
    /// is drawn at a finer internal resolution and shown at its size.
    #[test]
    fn a_slow_creep_is_no_staircase_of_whole_pixels() {
        let mut t = Trace::default();
        for k in 0..4000u32 {
            let act = (f64::from(k) / 4000.0 * INC_PER_REV) as i32;
            t.push(Nanos::from_ms(u64::from(k)), 9 << 20, act, 0, 0, 0);
        }
        let svg = t.svg("creep").unwrap();
        assert!(
            svg.contains("width=\"1100\" height=\"1000\""),
            "shown at its size"
        );
        let y = polyline_y(&svg, "#FF0000");
        assert_eq!(y.len(), 4000);
        let step = y.windows(2).map(|w| (w[1] - w[0]).abs()).fold(0.0, f64::max);
        assert!(step <= 0.3, "the creep moves in steps of {step} px");
    }
}
