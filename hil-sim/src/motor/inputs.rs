//! Position-defined digital inputs: hardware limit switches, reference switch
//! and touch-probe inputs, and the edges they produce while the rotor moves.
//!
//! Every input is described by a small set of *marks* (absolute, unwrapped
//! positions in increments, 2^20 per revolution) and the state below all of
//! them. The input is physically actuated when the number of marks at or
//! below the rotor position is odd, XOR the base state. So a mark `m` is
//! crossed exactly when the encoder count (the floor of the continuous
//! position) goes from `< m` to `>= m` or back; the crossing is at the
//! continuous position `m`, whichever the direction. The electrical level is
//! the actuation, inverted for an active-low (normally closed) contact.

use nanos::Nanos;

/// Most marks (toggle positions) one input can hold.
pub const MAX_MARKS: usize = 16;

/// Most edges one [`Motor::step`](super::Motor::step) reports; further edges
/// are counted in [`EdgeList::lost`].
pub const MAX_EDGES_PER_STEP: usize = 32;

/// A position-defined input had no room for another mark.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CapacityError;

/// One digital input whose physical state depends only on the rotor position.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PositionInput {
    /// Mark positions, increments (absolute, unwrapped); `marks[..len]` are used.
    marks: [i64; MAX_MARKS],
    len: usize,
    /// Actuated below every mark.
    actuated_below: bool,
    /// Electrical level is low while actuated (normally closed contact).
    active_low: bool,
}

impl PositionInput {
    /// Not fitted: never actuated, electrical level always low.
    pub const fn never() -> Self {
        Self {
            marks: [0; MAX_MARKS],
            len: 0,
            actuated_below: false,
            active_low: false,
        }
    }

    /// Actuated at `position_inc` and above (e.g. a positive limit switch or a
    /// reference switch on the positive side).
    pub const fn above(position_inc: i64) -> Self {
        let mut marks = [0; MAX_MARKS];
        marks[0] = position_inc;
        Self {
            marks,
            len: 1,
            actuated_below: false,
            active_low: false,
        }
    }

    /// Actuated below `position_inc` (e.g. a negative limit switch or a
    /// reference switch on the negative side).
    pub const fn below(position_inc: i64) -> Self {
        let mut marks = [0; MAX_MARKS];
        marks[0] = position_inc;
        Self {
            marks,
            len: 1,
            actuated_below: true,
            active_low: false,
        }
    }

    /// Actuated in `low_inc <= position < high_inc` (a cam, e.g. a reference
    /// switch in the middle of the travel).
    pub const fn window(low_inc: i64, high_inc: i64) -> Self {
        let mut marks = [0; MAX_MARKS];
        marks[0] = low_inc;
        marks[1] = high_inc;
        Self {
            marks,
            len: 2,
            actuated_below: false,
            active_low: false,
        }
    }

    /// An input that toggles at each of `positions_inc` (any order);
    /// `actuated_below` is its state below all of them. Used for touch-probe
    /// inputs. Fails if there are more than [`MAX_MARKS`] positions.
    pub fn toggles(actuated_below: bool, positions_inc: &[i64]) -> Result<Self, CapacityError> {
        let mut input = Self::never();
        input.actuated_below = actuated_below;
        for &p in positions_inc {
            input.push_mark(p)?;
        }
        Ok(input)
    }

    /// Adds one toggle position (increments).
    pub fn push_mark(&mut self, position_inc: i64) -> Result<(), CapacityError> {
        let slot = self.marks.get_mut(self.len).ok_or(CapacityError)?;
        *slot = position_inc;
        self.len += 1;
        Ok(())
    }

    /// The same input with an active-low (normally closed) contact: the
    /// electrical level is high while not actuated and drops to low when
    /// actuated (spec §8.1: hardware limit switches are low-active).
    pub const fn active_low(mut self) -> Self {
        self.active_low = true;
        self
    }

    /// Whether the electrical level is low while actuated.
    pub const fn is_active_low(&self) -> bool {
        self.active_low
    }

    /// The toggle positions (increments, absolute).
    pub fn marks(&self) -> &[i64] {
        self.marks.get(..self.len).unwrap_or(&[])
    }

    /// Physical state with the encoder count at `position_inc` (absolute).
    pub fn is_actuated_at(&self, position_inc: i64) -> bool {
        let at_or_below = self.marks().iter().filter(|&&m| position_inc >= m).count();
        self.actuated_below ^ (at_or_below % 2 == 1)
    }

    /// Electrical level with the encoder count at `position_inc` (absolute).
    pub fn level_at(&self, position_inc: i64) -> bool {
        self.is_actuated_at(position_inc) ^ self.active_low
    }
}

impl Default for PositionInput {
    fn default() -> Self {
        Self::never()
    }
}

/// Which input an [`Edge`] belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Input {
    /// Positive hardware limit switch.
    PositiveLimit,
    /// Negative hardware limit switch.
    NegativeLimit,
    /// Reference (home) switch.
    Reference,
    /// Touch-probe input 1.
    Probe1,
    /// Touch-probe input 2.
    Probe2,
}

impl Input {
    /// All inputs, in the order of [`Switches`]' fields.
    pub const ALL: [Input; 5] = [
        Input::PositiveLimit,
        Input::NegativeLimit,
        Input::Reference,
        Input::Probe1,
        Input::Probe2,
    ];
}

/// The position-defined inputs of one axis. `Default` is nothing fitted
/// (all levels low, no edges).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Switches {
    /// Positive hardware limit switch (spec §8.1, I441).
    pub positive_limit: PositionInput,
    /// Negative hardware limit switch (spec §8.1, I442).
    pub negative_limit: PositionInput,
    /// Reference switch for homing (spec §9).
    pub reference: PositionInput,
    /// Touch-probe input 1 (spec §11, 60D0h:01 source).
    pub probe1: PositionInput,
    /// Touch-probe input 2 (spec §11, 60D0h:02 source).
    pub probe2: PositionInput,
}

impl Switches {
    /// A limited linear axis as the spec recommends: normally closed
    /// (active-low) limit switches, actuated below `negative_limit_inc` and at
    /// or above `positive_limit_inc`, and the given reference switch.
    pub const fn linear_axis(
        negative_limit_inc: i64,
        positive_limit_inc: i64,
        reference: PositionInput,
    ) -> Self {
        Self {
            positive_limit: PositionInput::above(positive_limit_inc).active_low(),
            negative_limit: PositionInput::below(negative_limit_inc).active_low(),
            reference,
            probe1: PositionInput::never(),
            probe2: PositionInput::never(),
        }
    }

    /// The input for `which`.
    pub const fn get(&self, which: Input) -> &PositionInput {
        match which {
            Input::PositiveLimit => &self.positive_limit,
            Input::NegativeLimit => &self.negative_limit,
            Input::Reference => &self.reference,
            Input::Probe1 => &self.probe1,
            Input::Probe2 => &self.probe2,
        }
    }

    /// Electrical levels of all inputs with the encoder count at `position_inc`.
    pub fn levels_at(&self, position_inc: i64) -> InputLevels {
        InputLevels {
            positive_limit: self.positive_limit.level_at(position_inc),
            negative_limit: self.negative_limit.level_at(position_inc),
            reference: self.reference.level_at(position_inc),
            probe1: self.probe1.level_at(position_inc),
            probe2: self.probe2.level_at(position_inc),
        }
    }

    /// Appends the edges of all inputs for one sub-step (see [`Crossing`]).
    pub(super) fn detect(&self, c: &Crossing, edges: &mut EdgeList) {
        for which in Input::ALL {
            detect_input(which, self.get(which), c, edges);
        }
    }
}

/// Electrical input levels (true = high) at the end of a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct InputLevels {
    /// Positive hardware limit switch.
    pub positive_limit: bool,
    /// Negative hardware limit switch.
    pub negative_limit: bool,
    /// Reference switch.
    pub reference: bool,
    /// Touch-probe input 1.
    pub probe1: bool,
    /// Touch-probe input 2.
    pub probe2: bool,
}

impl InputLevels {
    /// The level of `which`.
    pub const fn get(&self, which: Input) -> bool {
        match which {
            Input::PositiveLimit => self.positive_limit,
            Input::NegativeLimit => self.negative_limit,
            Input::Reference => self.reference,
            Input::Probe1 => self.probe1,
            Input::Probe2 => self.probe2,
        }
    }
}

/// One level change of an input, at the exact (interpolated) crossing time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Edge {
    /// The input that changed.
    pub input: Input,
    /// The electrical level after the edge is high (a rising edge).
    pub rising: bool,
    /// Encoder position at the edge: the mark, increments, wrapped to `i32`.
    pub position_inc: i32,
    /// Time of the edge after the start of the step.
    pub time_offset: Nanos,
}

/// The edges of one step, sorted by time (edges at the same time keep the
/// input order of [`Input::ALL`] and, per input, the order of motion).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EdgeList {
    edges: [Edge; MAX_EDGES_PER_STEP],
    len: usize,
    lost: u32,
}

impl EdgeList {
    pub(super) const fn new() -> Self {
        const NONE: Edge = Edge {
            input: Input::Probe1,
            rising: false,
            position_inc: 0,
            time_offset: Nanos::ZERO,
        };
        Self {
            edges: [NONE; MAX_EDGES_PER_STEP],
            len: 0,
            lost: 0,
        }
    }

    /// The edges, earliest first.
    pub fn as_slice(&self) -> &[Edge] {
        self.edges.get(..self.len).unwrap_or(&[])
    }

    /// The edges, earliest first.
    pub fn iter(&self) -> core::slice::Iter<'_, Edge> {
        self.as_slice().iter()
    }

    /// The edges of one input, earliest first.
    pub fn of(&self, which: Input) -> impl Iterator<Item = &Edge> + '_ {
        self.iter().filter(move |e| e.input == which)
    }

    /// Number of edges.
    pub fn len(&self) -> usize {
        self.len
    }

    /// No edges this step.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Edges that did not fit (more than [`MAX_EDGES_PER_STEP`] in one step).
    pub fn lost(&self) -> u32 {
        self.lost
    }

    fn push(&mut self, edge: Edge) {
        if let Some(slot) = self.edges.get_mut(self.len) {
            *slot = edge;
            self.len += 1;
        } else {
            self.lost = self.lost.saturating_add(1);
        }
    }

    /// Appends `other`'s edges `offset` later (the steps of a control cycle
    /// split into sub-steps, merged into one list; sorted if `other` is and
    /// `offset` is past every edge already here).
    pub(crate) fn append_shifted(&mut self, other: &EdgeList, offset: Nanos) {
        for e in other {
            self.push(Edge {
                time_offset: e.time_offset.saturating_add(offset),
                ..*e
            });
        }
        self.lost = self.lost.saturating_add(other.lost);
    }

    /// Stable insertion sort by time (the list is short and nearly sorted).
    pub(super) fn sort_by_time(&mut self) {
        let n = self.len.min(MAX_EDGES_PER_STEP);
        let edges = &mut self.edges;
        for i in 1..n {
            let mut j = i;
            while j > 0 {
                let (Some(a), Some(b)) = (edges.get(j - 1), edges.get(j)) else {
                    break;
                };
                if a.time_offset <= b.time_offset {
                    break;
                }
                edges.swap(j - 1, j);
                j -= 1;
            }
        }
    }
}

impl<'a> IntoIterator for &'a EdgeList {
    type Item = &'a Edge;
    type IntoIter = core::slice::Iter<'a, Edge>;
    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

/// The motion of one sub-step, for interpolating crossing times: the rotor
/// went linearly from `p0_int + p0_frac` to `p0 + delta` (increments) between
/// `t0_ns` and `t0_ns + h_ns` (offsets within the step).
pub(super) struct Crossing {
    /// Encoder count at the start of the sub-step.
    pub p0_int: i64,
    /// Fraction of an increment at the start, `[0, 1)`.
    pub p0_frac: f64,
    /// Encoder count at the end of the sub-step.
    pub p1_int: i64,
    /// Continuous displacement over the sub-step, increments.
    pub delta: f64,
    /// Start of the sub-step after the start of the step, ns.
    pub t0_ns: u64,
    /// Length of the sub-step, ns.
    pub h_ns: u64,
}

impl Crossing {
    /// Whether mark `m` changes side in this sub-step.
    pub fn crosses(&self, m: i64) -> bool {
        (self.p0_int >= m) != (self.p1_int >= m)
    }

    /// Fraction `[0, 1]` of the sub-step at which the continuous position is `m`.
    pub fn fraction(&self, m: i64) -> f64 {
        if self.delta == 0.0 {
            return 0.0;
        }
        let s = ((m - self.p0_int) as f64 - self.p0_frac) / self.delta;
        s.clamp(0.0, 1.0)
    }

    /// Time offset within the step at which the position is `m`, ns (rounded).
    pub fn time_of(&self, m: i64) -> u64 {
        let dt = self.fraction(m) * self.h_ns as f64 + 0.5;
        // `as` saturates; dt is within [0.5, h_ns + 0.5].
        self.t0_ns + (dt as u64).min(self.h_ns)
    }
}

fn detect_input(which: Input, input: &PositionInput, c: &Crossing, edges: &mut EdgeList) {
    // Crossed marks of this input, with the fraction of the sub-step.
    let mut crossed = [(0.0f64, 0i64); MAX_MARKS];
    let mut n = 0;
    for &m in input.marks() {
        if c.crosses(m) {
            if let Some(slot) = crossed.get_mut(n) {
                *slot = (c.fraction(m), m);
                n += 1;
            }
        }
    }
    if n == 0 {
        return;
    }
    let crossed = crossed.get_mut(..n).unwrap_or(&mut []);
    // Order of motion: by fraction, ties by position in the direction of travel.
    let up = c.delta >= 0.0;
    crossed.sort_unstable_by(|a, b| {
        a.0.total_cmp(&b.0)
            .then_with(|| if up { a.1.cmp(&b.1) } else { b.1.cmp(&a.1) })
    });
    let mut level = input.level_at(c.p0_int);
    for &(_, m) in crossed.iter() {
        level = !level;
        edges.push(Edge {
            input: which,
            rising: level,
            position_inc: m as i32,
            time_offset: Nanos::from_ns(c.time_of(m)),
        });
    }
}
