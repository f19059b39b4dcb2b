//! Feedback: the encoder position in user coordinates, the coordinate shift
//! of a reference event, the touch probe.

use super::*;

impl Axis {
    /// Reads the encoder: user position and the filtered velocity.
    pub(super) fn feedback(&mut self, io: &AxisIo, polarity: u8, dt_ns: u32, now_ns: Nanos) -> i32 {
        let inverted = polarity & 0x80 != 0;
        // a faulty encoder's position is not used: the last valid one holds
        let raw = match (io.encoder_ok, self.last_raw) {
            (false, Some(last)) => last,
            _ => io.position_inc,
        };
        let dt_s = dt_ns as f32 * 1e-9;
        let v_raw = match self.last_raw {
            Some(last) if dt_ns > 0 => raw.wrapping_sub(last) as f32 / dt_s,
            _ => 0.0,
        };
        let v_user = if inverted { -v_raw } else { v_raw };
        let tau = self.params.cascade.velocity_filter_time_ns as f32;
        let alpha = dt_ns as f32 / (tau + dt_ns as f32);
        if self.last_raw.is_some() && alpha.is_finite() {
            self.velocity += alpha * (v_user - self.velocity);
        }
        if !self.velocity.is_finite() {
            self.velocity = 0.0;
        }
        self.last_raw = Some(raw);
        let actual = self.to_user(raw, polarity);
        if self.last_sample.is_none() {
            self.last_sample = Some(PositionSample {
                time: now_ns,
                position_inc: actual,
            });
            // power-on: the set-point state starts at the actual position
            self.disengage(actual);
            self.limits.restart_computing_limit(actual);
        }
        actual
    }

    /// Encoder position (motor coordinates) → user position.
    pub(super) fn to_user(&self, raw: i32, polarity: u8) -> i32 {
        let p = if polarity & 0x80 != 0 {
            raw.wrapping_neg()
        } else {
            raw
        };
        p.wrapping_add(self.offset)
    }

    /// Moves every stored position of the user coordinates by `shift`.
    pub(super) fn shift_coordinates(&mut self, shift: i32) {
        self.offset = self.offset.wrapping_add(shift);
        self.sp_pos = self.sp_pos.wrapping_add(shift);
        if let Some(s) = self.last_sample.as_mut() {
            s.position_inc = s.position_inc.wrapping_add(shift);
        }
        if let Some(i) = self.interp.as_mut() {
            i.start(self.sp_pos);
        }
        self.limits.reference_changed(self.sp_pos);
        self.profile.reset(self.sp_pos);
    }

    /// Touch probe (C-121 – C-129): 60B8h, the input edges and the index pulse.
    pub(super) fn touch_probe(&mut self, o: &Snapshot, io: &AxisIo, actual: i32, now_ns: Nanos) {
        self.probe.set_function(o.probe_function);
        let current = PositionSample {
            time: now_ns,
            position_inc: actual,
        };
        let previous = self.last_sample.replace(current).unwrap_or(current);
        if !self.probe.is_enabled() {
            return; // both probes off: no edge latches anything (C-126)
        }
        let [src1, src2] = o.probe_source;
        for edge in io.probe_edges.iter().flatten() {
            let position = match edge.position_inc {
                Some(p) => self.to_user(p, o.polarity),
                None => interpolate_position(previous, current, edge.time_ns),
            };
            let e = if edge.rising { Edge::Rising } else { Edge::Falling };
            let input = i16::from(edge.input);
            if input == src1 {
                self.latch_probe(TriggerSignal::Input1, e, position);
            }
            if input == src2 {
                self.latch_probe(TriggerSignal::Input2, e, position);
            }
        }
        if let Some(index) = io.index {
            let p = self.to_user(index.position_inc, o.polarity);
            self.latch_probe(TriggerSignal::IndexPulse, Edge::Rising, p);
        }
    }

    /// One edge to the touch probe; a stored value is written to the
    /// objects by the write-back of this cycle.
    fn latch_probe(&mut self, signal: TriggerSignal, edge: Edge, position: i32) {
        let (one, two) = self.probe.latch(signal, edge, position);
        if one || two {
            self.probe_shown = false;
        }
    }
}
