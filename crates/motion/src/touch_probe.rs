//! Touch probe: 60B8h function, 60B9h status, 60BAh – 60BDh edge positions
//! (spec §11; C-121 – C-129).
//!
//! Two probes; probe 1 uses bits 0–7 of 60B8h/60B9h, probe 2 the same layout
//! in bits 8–15. An edge is latched either with a position the hardware
//! latched itself ([`TouchProbe::latch`]) or with the position interpolated
//! between the two control-cycle samples around the edge's time stamp
//! ([`TouchProbe::latch_interpolated`], [`interpolate_position`]).
//!
//! 60B8h per probe (bit offset 0 / 8): bit 0 enable, bit 1 continuous (1) /
//! first event (0), bits 2–3 trigger selection (00 probe input, 01 encoder
//! zero pulse, 10 source from 60D0h, 11 reserved), bit 4 rising edge, bit 5
//! falling edge.
//!
//! 60B9h per probe: bit 0 enabled, bit 1 rising-edge position stored, bit 2
//! falling-edge position stored, bit 6 toggles on every rising-edge capture
//! and bit 7 on every falling-edge capture in continuous mode.
//!
//! Positions are increments; time stamps [`nanos::Nanos`].

use nanos::Nanos;

/// 60B8h/60B9h bit: probe enabled.
pub const ENABLE: u8 = 1 << 0;
/// 60B8h bit: continuous trigger (every event) instead of first event.
pub const CONTINUOUS: u8 = 1 << 1;
/// 60B8h bits 2–3: trigger selection mask.
pub const TRIGGER_SELECT_MASK: u8 = 0b11 << 2;
/// 60B8h bit: capture on the rising edge.
pub const RISING_EDGE: u8 = 1 << 4;
/// 60B8h bit: capture on the falling edge.
pub const FALLING_EDGE: u8 = 1 << 5;
/// 60B9h bit: a rising-edge position has been stored.
pub const RISING_STORED: u8 = 1 << 1;
/// 60B9h bit: a falling-edge position has been stored.
pub const FALLING_STORED: u8 = 1 << 2;
/// 60B9h bit: toggles on each rising-edge capture (continuous mode).
pub const RISING_TOGGLE: u8 = 1 << 6;
/// 60B9h bit: toggles on each falling-edge capture (continuous mode).
pub const FALLING_TOGGLE: u8 = 1 << 7;

/// One of the two probes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Probe {
    /// Probe 1: 60B8h/60B9h bits 0–7, values 60BAh/60BBh.
    One,
    /// Probe 2: bits 8–15, values 60BCh/60BDh.
    Two,
}

/// An edge of a trigger signal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Edge {
    /// 0 → 1.
    Rising,
    /// 1 → 0.
    Falling,
}

/// A signal that can trigger a probe.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TriggerSignal {
    /// The input selected for probe 1 by 60D0h:01 (I110, e.g. DI1).
    Input1,
    /// The input selected for probe 2 by 60D0h:02 (I126).
    Input2,
    /// The encoder zero (index) pulse.
    IndexPulse,
}

/// A position sample at a control-cycle boundary.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PositionSample {
    /// Time of the sample.
    pub time: Nanos,
    /// Actual position, increments.
    pub position_inc: i32,
}

/// The position at `edge_time`, linearly interpolated between
/// `previous` and `current` (wrap-around difference, rounded to the nearest
/// increment). Times outside the interval are clamped to it; an empty
/// interval gives `current`.
pub fn interpolate_position(previous: PositionSample, current: PositionSample, edge_time: Nanos) -> i32 {
    if current.time <= previous.time {
        return current.position_inc;
    }
    let t = edge_time.max(previous.time).min(current.time);
    let span = i128::from((current.time - previous.time).as_ns());
    let elapsed = i128::from((t - previous.time).as_ns());
    let delta = i128::from(current.position_inc.wrapping_sub(previous.position_inc));
    // Round half up: floor((2·δ·e + span) / (2·span)).
    let step = (2 * delta * elapsed + span).div_euclid(2 * span);
    // |step| ≤ |delta| < 2^32, so the truncation keeps the wrap-around value.
    previous.position_inc.wrapping_add(step as i64 as i32)
}

/// State of one probe.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Channel {
    /// 60B8h byte.
    function: u8,
    /// 60B9h byte.
    status: u8,
    /// Single shot not yet used, per edge.
    armed_rising: bool,
    armed_falling: bool,
    /// 60BAh/60BCh.
    rising_value: i32,
    /// 60BBh/60BDh.
    falling_value: i32,
}

impl Channel {
    const fn new() -> Self {
        Self {
            function: 0,
            status: 0,
            armed_rising: false,
            armed_falling: false,
            rising_value: 0,
            falling_value: 0,
        }
    }

    fn set_function(&mut self, function: u8) {
        let old = self.function;
        self.function = function;
        let enabled = function & ENABLE != 0;
        if !enabled {
            // Disabling clears every status bit; the values stay (C-126).
            self.status = 0;
            self.armed_rising = false;
            self.armed_falling = false;
            return;
        }
        if old & ENABLE == 0 {
            // Enable edge: (re-)arm both edges (C-127).
            self.status = ENABLE;
            self.armed_rising = true;
            self.armed_falling = true;
            return;
        }
        // Enabled: an edge-enable bit 0 → 1 re-arms that edge (`[std]`).
        if old & RISING_EDGE == 0 && function & RISING_EDGE != 0 {
            self.armed_rising = true;
            self.status &= !RISING_STORED;
        }
        if old & FALLING_EDGE == 0 && function & FALLING_EDGE != 0 {
            self.armed_falling = true;
            self.status &= !FALLING_STORED;
        }
    }

    /// Whether `signal` triggers this probe (`own_input` = the probe's
    /// 60D0h input).
    fn selects(&self, signal: TriggerSignal, own_input: TriggerSignal) -> bool {
        match (self.function & TRIGGER_SELECT_MASK) >> 2 {
            0b00 | 0b10 => signal == own_input,
            0b01 => signal == TriggerSignal::IndexPulse,
            _ => false,
        }
    }

    fn latch(
        &mut self,
        signal: TriggerSignal,
        own_input: TriggerSignal,
        edge: Edge,
        position_inc: i32,
    ) -> bool {
        if self.function & ENABLE == 0 || !self.selects(signal, own_input) {
            return false;
        }
        let continuous = self.function & CONTINUOUS != 0;
        let (edge_bit, armed, value, stored, toggle) = match edge {
            Edge::Rising => (
                RISING_EDGE,
                &mut self.armed_rising,
                &mut self.rising_value,
                RISING_STORED,
                RISING_TOGGLE,
            ),
            Edge::Falling => (
                FALLING_EDGE,
                &mut self.armed_falling,
                &mut self.falling_value,
                FALLING_STORED,
                FALLING_TOGGLE,
            ),
        };
        if self.function & edge_bit == 0 || !(*armed || continuous) {
            return false;
        }
        *value = position_inc;
        if continuous {
            self.status ^= toggle;
        } else {
            *armed = false;
        }
        self.status |= stored;
        true
    }
}

/// The two touch probes of one axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TouchProbe {
    one: Channel,
    two: Channel,
}

impl Default for TouchProbe {
    fn default() -> Self {
        Self::new()
    }
}

impl TouchProbe {
    /// Both probes off, values 0.
    pub const fn new() -> Self {
        Self {
            one: Channel::new(),
            two: Channel::new(),
        }
    }

    /// Writes 60B8h (A594) touch probe function (C-121, C-126 – C-128).
    pub fn set_function(&mut self, function_60b8: u16) {
        if function_60b8 == self.function() {
            return; // the same function again changes nothing
        }
        let [low, high] = function_60b8.to_le_bytes();
        self.one.set_function(low);
        self.two.set_function(high);
    }

    /// Whether either probe is switched on (60B8h bit 0 or 8): off, no
    /// edge latches anything.
    pub fn is_enabled(&self) -> bool {
        (self.one.function | self.two.function) & ENABLE != 0
    }

    /// 60B8h as last written.
    pub fn function(&self) -> u16 {
        u16::from_le_bytes([self.one.function, self.two.function])
    }

    /// 60B9h (A595) touch probe status.
    pub fn status(&self) -> u16 {
        u16::from_le_bytes([self.one.status, self.two.status])
    }

    /// The latched position of `probe` at `edge` (60BAh – 60BDh), increments.
    pub const fn value(&self, probe: Probe, edge: Edge) -> i32 {
        let c = match probe {
            Probe::One => &self.one,
            Probe::Two => &self.two,
        };
        match edge {
            Edge::Rising => c.rising_value,
            Edge::Falling => c.falling_value,
        }
    }

    /// 60BAh touch probe 1 positive (rising) edge value.
    pub const fn value_60ba(&self) -> i32 {
        self.one.rising_value
    }

    /// 60BBh touch probe 1 negative (falling) edge value.
    pub const fn value_60bb(&self) -> i32 {
        self.one.falling_value
    }

    /// 60BCh touch probe 2 positive (rising) edge value.
    pub const fn value_60bc(&self) -> i32 {
        self.two.rising_value
    }

    /// 60BDh touch probe 2 negative (falling) edge value.
    pub const fn value_60bd(&self) -> i32 {
        self.two.falling_value
    }

    /// An `edge` of `signal` with the position `position_inc` at the edge
    /// (latched by the encoder hardware or already interpolated). Offered to
    /// both probes; returns which ones stored it (probe 1, probe 2).
    pub fn latch(&mut self, signal: TriggerSignal, edge: Edge, position_inc: i32) -> (bool, bool) {
        let one = self.one.latch(signal, TriggerSignal::Input1, edge, position_inc);
        let two = self.two.latch(signal, TriggerSignal::Input2, edge, position_inc);
        (one, two)
    }

    /// An `edge` of `signal` time-stamped `edge_time`, with the position
    /// interpolated between the cycle samples `previous` and `current`
    /// ([`interpolate_position`]). Returns which probes stored it.
    pub fn latch_interpolated(
        &mut self,
        signal: TriggerSignal,
        edge: Edge,
        edge_time: Nanos,
        previous: PositionSample,
        current: PositionSample,
    ) -> (bool, bool) {
        self.latch(signal, edge, interpolate_position(previous, current, edge_time))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Probe 1: enable, input trigger, both edges, continuous.
    const P1_CONT_BOTH: u16 = (ENABLE | CONTINUOUS | RISING_EDGE | FALLING_EDGE) as u16;
    const P1_SINGLE_BOTH: u16 = (ENABLE | RISING_EDGE | FALLING_EDGE) as u16;

    fn edge(tp: &mut TouchProbe, e: Edge, pos: i32) -> bool {
        tp.latch(TriggerSignal::Input1, e, pos).0
    }

    #[test]
    fn c121_enable_bit_is_echoed_in_status() {
        let mut tp = TouchProbe::new();
        assert_eq!(tp.status(), 0);
        tp.set_function(ENABLE as u16);
        assert_eq!(tp.status() & 1, 1);
        assert_eq!(tp.function(), 1);
        tp.set_function(0);
        assert_eq!(tp.status(), 0);
    }

    /// The control cycle writes 60B8h every cycle: the same function again
    /// keeps the stored value, the status and the first-event lock; with
    /// both probes off nothing is enabled.
    #[test]
    fn c124_rewriting_the_same_function_changes_nothing() {
        let mut tp = TouchProbe::new();
        assert!(!tp.is_enabled());
        let f = (ENABLE | RISING_EDGE) as u16;
        tp.set_function(f);
        assert!(tp.is_enabled());
        assert!(edge(&mut tp, Edge::Rising, 10));
        let status = tp.status();
        tp.set_function(f);
        assert_eq!(tp.status(), status);
        assert!(!edge(&mut tp, Edge::Rising, 20), "first event: still locked");
        assert_eq!(tp.value_60ba(), 10);
        tp.set_function(0);
        assert!(!tp.is_enabled());
    }

    #[test]
    fn c122_rising_edge_latches_into_60ba() {
        let mut tp = TouchProbe::new();
        tp.set_function((ENABLE | RISING_EDGE) as u16);
        assert!(!edge(&mut tp, Edge::Falling, 5), "falling edge not enabled");
        assert_eq!(tp.status() & 0b110, 0);
        assert!(edge(&mut tp, Edge::Rising, 1234));
        assert_eq!(tp.value_60ba(), 1234);
        assert_eq!(tp.value(Probe::One, Edge::Rising), 1234);
        assert_eq!(tp.status() & 0b111, 0b011);
    }

    #[test]
    fn c123_falling_edge_latches_into_60bb() {
        let mut tp = TouchProbe::new();
        tp.set_function((ENABLE | FALLING_EDGE) as u16);
        assert!(!edge(&mut tp, Edge::Rising, 5));
        assert!(edge(&mut tp, Edge::Falling, -777));
        assert_eq!(tp.value_60bb(), -777);
        assert_eq!(tp.value_60ba(), 0);
        assert_eq!(tp.status() & 0b111, 0b101);
    }

    #[test]
    fn c125_touch_probe_example_1_continuous_both_edges() {
        // Example 1: continuous, both edges: every edge overwrites its value,
        // bits 1/2 come on with the first capture; disabling clears the
        // status bits and keeps the values.
        let mut tp = TouchProbe::new();
        tp.set_function(P1_CONT_BOTH);
        assert_eq!(tp.status(), 0x01);
        assert!(edge(&mut tp, Edge::Rising, 100)); // t1
        assert_eq!(tp.status() & 0b110, 0b010);
        assert!(edge(&mut tp, Edge::Falling, 200)); // t2
        assert_eq!(tp.status() & 0b110, 0b110);
        assert!(edge(&mut tp, Edge::Rising, 300)); // t3
        assert!(edge(&mut tp, Edge::Falling, 400)); // t4
        assert_eq!((tp.value_60ba(), tp.value_60bb()), (300, 400));
        assert!(edge(&mut tp, Edge::Rising, 500)); // t5
        assert_eq!((tp.value_60ba(), tp.value_60bb()), (500, 400));
        // Toggle bits: 3 rising captures → bit 6 set, 2 falling → bit 7 clear.
        assert_eq!(tp.status() & 0xC0, 0x40);
        // C-126: disable clears status, keeps values.
        tp.set_function(0);
        assert_eq!(tp.status(), 0);
        assert_eq!((tp.value_60ba(), tp.value_60bb()), (500, 400));
        assert!(!edge(&mut tp, Edge::Rising, 600), "disabled probe ignores edges");
        assert_eq!(tp.value_60ba(), 500);
    }

    #[test]
    fn c124_touch_probe_example_2_first_event_falling_only() {
        // Example 2: first event, falling edge only: only t2 is stored.
        let mut tp = TouchProbe::new();
        tp.set_function((ENABLE | FALLING_EDGE) as u16);
        assert!(!edge(&mut tp, Edge::Rising, 100)); // t1
        assert!(edge(&mut tp, Edge::Falling, 200)); // t2
        assert!(!edge(&mut tp, Edge::Rising, 300)); // t3
        assert!(!edge(&mut tp, Edge::Falling, 400)); // t4
        assert!(!edge(&mut tp, Edge::Falling, 500));
        assert_eq!(tp.value_60bb(), 200);
        assert_eq!(tp.value_60ba(), 0);
        assert_eq!(tp.status() & 0xFF, 0x05);
        // No toggling in single-shot mode.
        assert_eq!(tp.status() & 0xC0, 0);
    }

    #[test]
    fn c127_touch_probe_example_3_reenable_rearms() {
        // Example 3: first event, both edges, enabled twice in a row. The
        // signal is high at the first enable, so t2 (falling) is the first
        // event; after re-enabling, t3 (rising) is stored.
        let mut tp = TouchProbe::new();
        tp.set_function(P1_SINGLE_BOTH);
        assert!(edge(&mut tp, Edge::Falling, 200)); // t2
        assert_eq!(tp.value_60bb(), 200);
        assert_eq!(tp.status() & 0x07, 0x05);
        // A second falling edge before re-arming is ignored.
        assert!(!edge(&mut tp, Edge::Falling, 250));
        assert_eq!(tp.value_60bb(), 200);
        // Re-enable: bit 0 0 → 1 clears the status and re-arms both edges.
        tp.set_function(0);
        tp.set_function(P1_SINGLE_BOTH);
        assert_eq!(tp.status() & 0x07, 0x01);
        assert!(edge(&mut tp, Edge::Rising, 300)); // t3
        assert_eq!(tp.value_60ba(), 300);
        assert_eq!(tp.status() & 0x07, 0x03);
        assert!(!edge(&mut tp, Edge::Rising, 350), "single shot again");
        assert!(edge(&mut tp, Edge::Falling, 400), "falling re-armed too");
        assert_eq!((tp.value_60ba(), tp.value_60bb()), (300, 400));
        // Writing the same enabled value again does not re-arm.
        tp.set_function(P1_SINGLE_BOTH);
        assert!(!edge(&mut tp, Edge::Rising, 500));
    }

    #[test]
    fn c127_edge_enable_bit_rearms_while_enabled() {
        let mut tp = TouchProbe::new();
        tp.set_function((ENABLE | RISING_EDGE) as u16);
        assert!(edge(&mut tp, Edge::Rising, 10));
        assert!(!edge(&mut tp, Edge::Rising, 20));
        tp.set_function(ENABLE as u16);
        tp.set_function((ENABLE | RISING_EDGE) as u16);
        assert_eq!(tp.status() & 0x02, 0, "stored bit cleared on re-arm");
        assert!(edge(&mut tp, Edge::Rising, 30));
        assert_eq!(tp.value_60ba(), 30);
    }

    #[test]
    fn c128_probe_2_uses_the_high_byte() {
        let mut tp = TouchProbe::new();
        let p2 = u16::from(ENABLE | RISING_EDGE | FALLING_EDGE) << 8;
        tp.set_function(p2);
        assert_eq!(tp.status(), 0x0100);
        // Probe 1's input does not trigger probe 2.
        assert_eq!(tp.latch(TriggerSignal::Input1, Edge::Rising, 1), (false, false));
        assert_eq!(tp.latch(TriggerSignal::Input2, Edge::Rising, 11), (false, true));
        assert_eq!(tp.latch(TriggerSignal::Input2, Edge::Falling, 22), (false, true));
        assert_eq!((tp.value_60bc(), tp.value_60bd()), (11, 22));
        assert_eq!(tp.value(Probe::Two, Edge::Falling), 22);
        assert_eq!(tp.status(), 0x0700);
        assert_eq!((tp.value_60ba(), tp.value_60bb()), (0, 0));
        tp.set_function(0);
        assert_eq!(tp.status(), 0);
        assert_eq!(tp.value_60bc(), 11);
    }

    #[test]
    fn c129_trigger_selection_input_60d0_or_index_pulse() {
        let mut tp = TouchProbe::new();
        // Probe 1 on the zero pulse (bits 2–3 = 01), probe 2 on its 60D0h
        // source (bits 10–11 = 10).
        let p1 = ENABLE | CONTINUOUS | (0b01 << 2) | RISING_EDGE;
        let p2 = ENABLE | CONTINUOUS | (0b10 << 2) | RISING_EDGE;
        tp.set_function(u16::from_le_bytes([p1, p2]));
        assert_eq!(tp.latch(TriggerSignal::Input1, Edge::Rising, 1), (false, false));
        assert_eq!(
            tp.latch(TriggerSignal::IndexPulse, Edge::Rising, 2),
            (true, false)
        );
        assert_eq!(tp.latch(TriggerSignal::Input2, Edge::Rising, 3), (false, true));
        assert_eq!((tp.value_60ba(), tp.value_60bc()), (2, 3));
        // Reserved selection 11: nothing triggers.
        tp.set_function(u16::from(ENABLE | (0b11 << 2) | RISING_EDGE));
        for s in [
            TriggerSignal::Input1,
            TriggerSignal::Input2,
            TriggerSignal::IndexPulse,
        ] {
            assert_eq!(tp.latch(s, Edge::Rising, 9), (false, false));
        }
    }

    #[test]
    fn c122_timestamped_edge_interpolates_between_cycle_samples() {
        let prev = PositionSample {
            time: Nanos::from_ns(1_000_000),
            position_inc: 10_000,
        };
        let cur = PositionSample {
            time: Nanos::from_ns(1_250_000),
            position_inc: 11_000,
        };
        assert_eq!(interpolate_position(prev, cur, Nanos::from_ns(1_000_000)), 10_000);
        assert_eq!(interpolate_position(prev, cur, Nanos::from_ns(1_100_000)), 10_400);
        assert_eq!(interpolate_position(prev, cur, Nanos::from_ns(1_250_000)), 11_000);
        // 1/64 µs resolution: 15.625 ns → 0.0625 inc, rounds to 0.
        assert_eq!(interpolate_position(prev, cur, Nanos::from_ns(1_000_016)), 10_000);
        assert_eq!(interpolate_position(prev, cur, Nanos::from_ns(1_000_125)), 10_001);
        // Clamped outside the interval, empty interval gives current.
        assert_eq!(interpolate_position(prev, cur, Nanos::from_ns(2_000_000)), 11_000);
        assert_eq!(interpolate_position(cur, cur, Nanos::from_ns(0)), 11_000);
        // Moving backwards across the i32 wrap.
        let prev = PositionSample {
            time: Nanos::from_ns(0),
            position_inc: i32::MIN + 100,
        };
        let cur = PositionSample {
            time: Nanos::from_ns(250_000),
            position_inc: i32::MAX - 99,
        };
        assert_eq!(interpolate_position(prev, cur, Nanos::from_ns(125_000)), i32::MIN);
        let mut tp = TouchProbe::new();
        tp.set_function(u16::from(ENABLE | RISING_EDGE));
        let r = tp.latch_interpolated(
            TriggerSignal::Input1,
            Edge::Rising,
            Nanos::from_ns(187_500),
            prev,
            cur,
        );
        assert_eq!(r, (true, false));
        assert_eq!(tp.value_60ba(), i32::MAX - 49);
    }
}
