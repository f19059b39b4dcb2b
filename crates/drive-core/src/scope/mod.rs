//! The drive's scope (group T, issue 35): a trace recorder sampling up to
//! [`MAX_CHANNELS`] channels every `divider` control cycles into a buffer
//! the shell hands over ([`Recorder::new`]: a `Box<[u32]>` in the simulator,
//! a `&'static mut [u32]` in a RAM bank of its own on a board), with a
//! trigger (level or edge on a channel, or a statusword bit), a pre-trigger
//! share and a single or normal mode.
//!
//! A channel is a PDO-mappable integer entry (read through the dictionary's
//! prepared access where it has one, [`DriveObjects::prepare`], else
//! [`DriveObjects::get`]) or an internal signal of the cascade and the current
//! loop ([`Signal`]). Every sample is stored as 32 bits (the entry's value,
//! sign-extended; a signal in the integer unit [`Signal`] names).
//!
//! States ([`State`]): idle → (arm) armed → (trigger, once the pre-trigger
//! share is recorded) triggered → (the rest recorded) complete. Single mode
//! stays complete until armed again; normal mode arms itself again once the
//! trace has been read out to its last block. Only a complete trace is read
//! ([`Recorder::read_block`]); before that the read answers 0800 0022h, never
//! the last trace's samples as new ones.
//!
//! Cost: [`Recorder::sample`] is one compare and branch while idle or
//! complete; the recording is out of line.
//!
//! The objects (T00…T11 at 4600h + line) are answered by the recorder as a
//! [`crate::LiveValues`] provider (`objects.rs`): their values live here, not
//! in the dictionary's RAM image.

use crate::axis::{Axis, AxisIo};
use crate::dictionary::{scope_mappable, DriveObjects, Prepared};
use od::{CommState, SdoAbort};

mod objects;
#[cfg(test)]
mod tests;

/// Channels a trace holds at most.
pub const MAX_CHANNELS: usize = 8;
/// Bytes of one element of the trace data object (T11): one SDO upload.
pub const BLOCK_BYTES: usize = 4096;
/// Elements of T11: the longest trace readable is `BLOCKS × BLOCK_BYTES`.
pub const BLOCKS: u8 = 16;
/// The highest sample divider (T03).
pub const MAX_DIVIDER: u16 = 1000;

/// An internal signal of one axis. Channel code: index 0, sub = axis · 10h +
/// signal number, 32 bits (`0x0000_0120` is axis A's speed set-point).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Signal {
    /// 1: the speed controller's set-point (the cascade's velocity command), inc/s.
    SpeedSetpoint,
    /// 2: the speed controller's actual value (filtered), inc/s.
    SpeedActual,
    /// 3: the following error (set-point − actual position), inc.
    FollowingError,
    /// 4: the measured torque-forming current iq, mA.
    Iq,
    /// 5: the measured d current id (mean over the cycle), mA.
    Id,
    /// 6: the applied d voltage ud (mean over the cycle), mV.
    Ud,
}

impl Signal {
    /// The signal of number `n` (1…6).
    pub const fn from_number(n: u8) -> Option<Self> {
        Some(match n {
            1 => Self::SpeedSetpoint,
            2 => Self::SpeedActual,
            3 => Self::FollowingError,
            4 => Self::Iq,
            5 => Self::Id,
            6 => Self::Ud,
            _ => return None,
        })
    }

    /// The channel code of this signal of `axis` (0 = A, 1 = B).
    pub const fn code(self, axis: u8) -> u32 {
        let n = match self {
            Self::SpeedSetpoint => 1,
            Self::SpeedActual => 2,
            Self::FollowingError => 3,
            Self::Iq => 4,
            Self::Id => 5,
            Self::Ud => 6,
        };
        ((axis as u32 * 0x10 + n) << 8) | 32
    }
}

/// The internal signals of one axis in one control cycle, integer units (a
/// quantity the loop does not report reads 0).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Signals {
    /// The speed controller's set-point, inc/s.
    pub speed_setpoint: i32,
    /// The speed controller's actual value, inc/s.
    pub speed_actual: i32,
    /// The following error, inc.
    pub following_error: i32,
    /// iq, mA.
    pub iq: i32,
    /// id, mA.
    pub id: i32,
    /// ud, mV.
    pub ud: i32,
}

impl Signals {
    /// The signals of `axis` after its control cycle with the inputs `io`
    /// (the current loop's measurement as it reported it to the axis; uq is
    /// not reported, so it is no signal).
    pub fn of(axis: &Axis, io: &AxisIo) -> Self {
        // `as` saturates: a float beyond i32 reads as its bound
        let c = axis.cascade_output();
        let d = io.current.and_then(|m| m.d_axis);
        Self {
            speed_setpoint: c.map_or(0, |c| c.velocity_command_inc_per_s as i32),
            speed_actual: axis.actual_velocity() as i32,
            following_error: c.map_or(0, |c| c.following_error_inc),
            iq: io.current.map_or(0, |m| (m.current_a * 1000.0) as i32),
            id: d.map_or(0, |d| (d.current_a * 1000.0) as i32),
            ud: d.map_or(0, |d| (d.voltage_v * 1000.0) as i32),
        }
    }

    fn get(&self, s: Signal) -> i32 {
        match s {
            Signal::SpeedSetpoint => self.speed_setpoint,
            Signal::SpeedActual => self.speed_actual,
            Signal::FollowingError => self.following_error,
            Signal::Iq => self.iq,
            Signal::Id => self.id,
            Signal::Ud => self.ud,
        }
    }
}

/// The recorder's state (T00).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum State {
    /// 0: not recording.
    Idle,
    /// 1: recording, waiting for the trigger.
    Armed,
    /// 2: triggered, recording the rest.
    Triggered,
    /// 3: a trace is complete and readable.
    Complete,
}

impl State {
    /// T00's value.
    pub const fn code(self) -> u8 {
        match self {
            Self::Idle => 0,
            Self::Armed => 1,
            Self::Triggered => 2,
            Self::Complete => 3,
        }
    }
}

/// The trigger condition (T06) on the source's value `v` against the level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Condition {
    /// 0: v ≥ level.
    Above,
    /// 1: v < level.
    Below,
    /// 2: v went from below the level to at or above it.
    Rising,
    /// 3: v went from at or above the level to below it.
    Falling,
    /// 4: either edge.
    Either,
}

impl Condition {
    /// The condition of T06 value `n`.
    pub const fn from_code(n: u8) -> Option<Self> {
        Some(match n {
            0 => Self::Above,
            1 => Self::Below,
            2 => Self::Rising,
            3 => Self::Falling,
            4 => Self::Either,
            _ => return None,
        })
    }

    fn met(self, last: Option<i32>, v: i32, level: i32) -> bool {
        let now = v >= level;
        let before = last.map(|l| l >= level);
        match self {
            Self::Above => now,
            Self::Below => !now,
            Self::Rising => before == Some(false) && now,
            Self::Falling => before == Some(true) && !now,
            Self::Either => before.is_some_and(|b| b != now),
        }
    }
}

/// What a trace starts on (T05).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// 0: at once, once the pre-trigger share is recorded.
    Immediate,
    /// 1…8: channel k − 1's value.
    Channel(u8),
    /// 10h + n / 20h + n: statusword (6041h / 6841h) bit n of axis 0 / 1,
    /// as the value 0 or 1 (the level is 1).
    StatusBit {
        /// 0 = A, 1 = B.
        axis: u8,
        /// Bit 0…15.
        bit: u8,
    },
}

impl Source {
    /// The source of T05 value `n`.
    pub const fn from_code(n: u16) -> Option<Self> {
        Some(match n {
            0 => Self::Immediate,
            1..=8 => Self::Channel(n as u8 - 1),
            0x10..=0x2F => Self::StatusBit {
                axis: (n >> 4) as u8 - 1,
                bit: (n & 0xF) as u8,
            },
            _ => return None,
        })
    }
}

/// A channel as the recorder reads it.
#[derive(Debug, Clone, Copy)]
enum Channel {
    Off,
    /// An entry (SDO Info numbering) and its prepared access, if it has one.
    Entry {
        index: u16,
        sub: u8,
        prepared: Option<Prepared>,
    },
    Signal {
        axis: u8,
        signal: Signal,
    },
}

/// Why a channel code is refused (its SDO abort, [`Recorder::check_channel`]).
fn decode_channel(code: u32) -> Result<Channel, SdoAbort> {
    let (index, sub, bits) = ((code >> 16) as u16, (code >> 8) as u8, code as u8);
    if code == 0 {
        return Ok(Channel::Off);
    }
    if index == 0 {
        let signal = Signal::from_number(sub & 0x0F).ok_or(SdoAbort::NOT_MAPPABLE)?;
        let axis = sub >> 4;
        if axis > 1 || bits != 32 {
            return Err(SdoAbort::NOT_MAPPABLE);
        }
        return Ok(Channel::Signal { axis, signal });
    }
    let t = scope_mappable(index, sub)?;
    if u16::from(bits) != t.bits() {
        return Err(SdoAbort::PARAMETER_INCOMPATIBLE);
    }
    Ok(Channel::Entry {
        index,
        sub,
        prepared: None,
    })
}

/// The configuration (T01…T09).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Config {
    /// T01: channel codes.
    pub channels: [u32; MAX_CHANNELS],
    /// T02: channels in use.
    pub count: u8,
    /// T03: control cycles per sample (1…[`MAX_DIVIDER`]).
    pub divider: u16,
    /// T04: samples per channel (0 = the whole buffer).
    pub length: u32,
    /// T05: trigger source code.
    pub source: u16,
    /// T06: trigger condition code.
    pub condition: u8,
    /// T07: trigger level.
    pub level: i32,
    /// T08: pre-trigger share, %.
    pub pre_percent: u8,
    /// T09: 0 single, 1 normal.
    pub normal: bool,
}

impl Default for Config {
    fn default() -> Self {
        Self {
            channels: [0; MAX_CHANNELS],
            count: 0,
            divider: 1,
            length: 0,
            source: 0,
            condition: 0,
            level: 0,
            pre_percent: 0,
            normal: false,
        }
    }
}

/// The trace recorder over the buffer `S` (words).
#[derive(Debug, Clone)]
pub struct Recorder<S> {
    storage: S,
    config: Config,
    state: State,
    /// Decoded channels of the armed trace.
    chans: [Channel; MAX_CHANNELS],
    n: usize,
    source: Source,
    condition: Condition,
    /// Samples per channel of the armed trace.
    frames: u32,
    pre: u32,
    /// Control cycles since the last sample.
    tick: u16,
    /// Ring position of the next sample.
    write: u32,
    /// Samples recorded since arming (up to `frames`).
    filled: u32,
    /// Samples still to record after the trigger.
    post: u32,
    /// The trigger source's value at the previous sample.
    last: Option<i32>,
    /// Ring position of the trigger sample.
    trigger_at: u32,
    /// Ring position of the oldest sample of the complete trace.
    start: u32,
    /// Completed traces.
    traces: u32,
    /// Armed, its channels' accesses not prepared yet
    /// ([`prepare`](Self::prepare)).
    unprepared: bool,
}

impl<S: AsRef<[u32]> + AsMut<[u32]>> Recorder<S> {
    /// A recorder over `storage` (its words hold channels × samples), idle.
    pub fn new(storage: S) -> Self {
        Self {
            storage,
            config: Config::default(),
            state: State::Idle,
            chans: [Channel::Off; MAX_CHANNELS],
            n: 0,
            source: Source::Immediate,
            condition: Condition::Above,
            frames: 0,
            pre: 0,
            tick: 0,
            write: 0,
            filled: 0,
            post: 0,
            last: None,
            trigger_at: 0,
            start: 0,
            traces: 0,
            unprepared: false,
        }
    }

    /// The buffer back (the recorder ends: a drive restarted in the
    /// simulator hands its buffer to the next one).
    pub fn into_storage(self) -> S {
        self.storage
    }

    /// The state (T00).
    pub fn state(&self) -> State {
        self.state
    }

    /// The configuration (T01…T09).
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// Words in the buffer.
    pub fn capacity(&self) -> usize {
        self.storage.as_ref().len()
    }

    /// Completed traces since construction.
    pub fn traces(&self) -> u32 {
        self.traces
    }

    /// Samples per channel of the trace (armed or complete; 0 before).
    pub fn frames(&self) -> u32 {
        self.frames
    }

    /// Index of the trigger sample in the complete trace (0 before).
    pub fn trigger_index(&self) -> u32 {
        match self.state {
            State::Complete => ring_sub(self.trigger_at, self.start, self.frames),
            _ => 0,
        }
    }

    /// Sets the configuration, checked as the objects' writes are
    /// (channels mappable, count and length within the buffer); refused
    /// with 0800 0022h while a trace is recording.
    pub fn configure(&mut self, config: Config) -> Result<(), SdoAbort> {
        self.check_idle()?;
        for &c in &config.channels {
            decode_channel(c)?;
        }
        if usize::from(config.count) > MAX_CHANNELS {
            return Err(SdoAbort::VALUE_TOO_HIGH);
        }
        if config.divider == 0 {
            return Err(SdoAbort::VALUE_TOO_LOW);
        }
        if config.divider > MAX_DIVIDER || config.pre_percent > 100 {
            return Err(SdoAbort::VALUE_TOO_HIGH);
        }
        Source::from_code(config.source).ok_or(SdoAbort::INVALID_VALUE)?;
        Condition::from_code(config.condition).ok_or(SdoAbort::INVALID_VALUE)?;
        self.check_length(config.length, config.count)?;
        self.config = config;
        Ok(())
    }

    fn check_idle(&self) -> Result<(), SdoAbort> {
        match self.state {
            State::Armed | State::Triggered => Err(SdoAbort::DEVICE_STATE),
            State::Idle | State::Complete => Ok(()),
        }
    }

    /// A length of `length` samples of `count` channels fits the buffer
    /// and T11 (0609 0031h otherwise).
    fn check_length(&self, length: u32, count: u8) -> Result<(), SdoAbort> {
        let words = u64::from(length) * u64::from(count.max(1));
        let limit = (self.capacity() as u64).min((usize::from(BLOCKS) * BLOCK_BYTES / 4) as u64);
        if words > limit {
            Err(SdoAbort::VALUE_TOO_HIGH)
        } else {
            Ok(())
        }
    }

    /// Arms a trace with the configuration: channels 1…T02 must be set
    /// (0609 0030h otherwise, and for no channel at all), at least two
    /// samples must fit.
    pub fn arm(&mut self) -> Result<(), SdoAbort> {
        let c = self.config;
        let n = usize::from(c.count);
        if n == 0 {
            return Err(SdoAbort::INVALID_VALUE);
        }
        let mut chans = [Channel::Off; MAX_CHANNELS];
        for (slot, &code) in chans.iter_mut().zip(&c.channels).take(n) {
            *slot = decode_channel(code)?;
            if matches!(slot, Channel::Off) {
                return Err(SdoAbort::INVALID_VALUE);
            }
        }
        let source = Source::from_code(c.source).ok_or(SdoAbort::INVALID_VALUE)?;
        if matches!(source, Source::Channel(k) if usize::from(k) >= n) {
            return Err(SdoAbort::INVALID_VALUE);
        }
        let limit = (self.capacity() / n).min(usize::from(BLOCKS) * BLOCK_BYTES / 4 / n);
        let frames = match c.length {
            0 => u32::try_from(limit).unwrap_or(u32::MAX),
            l => l,
        };
        if frames < 2 || frames as usize > limit {
            return Err(SdoAbort::VALUE_TOO_HIGH);
        }
        self.chans = chans;
        self.n = n;
        self.source = source;
        self.condition = Condition::from_code(c.condition).ok_or(SdoAbort::INVALID_VALUE)?;
        self.frames = frames;
        // the trigger sample is the first after the pre-trigger share
        self.pre = ((u64::from(frames) * u64::from(c.pre_percent)) / 100).min(u64::from(frames - 1)) as u32;
        self.restart();
        self.unprepared = true;
        Ok(())
    }

    /// Prepares the armed trace's object channels (their accesses to the
    /// dictionary), in the context that armed it (the mailbox or record
    /// task after the write of T00 = 1): the control cycle's first sample
    /// then reads them as every later one does (without this, the first
    /// sample prepares them: ≈ 3,300 instructions more in the control
    /// task). One compare when nothing is to do. A channel whose access a
    /// configuration change made stale is prepared again by the sample.
    pub fn prepare(&mut self, od: &DriveObjects) {
        if !core::mem::take(&mut self.unprepared) {
            return;
        }
        for ch in self.chans.iter_mut().take(self.n) {
            if let Channel::Entry { index, sub, prepared } = ch {
                *prepared = od.prepare(*index, *sub, CommState::Op);
            }
        }
    }

    fn restart(&mut self) {
        self.tick = 0;
        self.write = 0;
        self.filled = 0;
        self.post = 0;
        self.last = None;
        self.trigger_at = 0;
        self.start = 0;
        self.state = State::Armed;
    }

    /// Stops: idle, the trace (complete or not) is gone.
    pub fn stop(&mut self) {
        self.state = State::Idle;
    }

    /// One control cycle: records a sample every T03 cycles while armed or
    /// triggered. `signals` gives both axes' internal signals of this cycle
    /// (asked only while recording: idle costs the one branch).
    #[inline(always)]
    pub fn sample(&mut self, od: &DriveObjects, signals: impl FnOnce() -> [Signals; 2]) {
        if matches!(self.state, State::Armed | State::Triggered) {
            self.record(od, &signals());
        }
    }

    #[inline(never)]
    fn record(&mut self, od: &DriveObjects, signals: &[Signals; 2]) {
        self.tick += 1;
        if self.tick < self.config.divider {
            return;
        }
        self.tick = 0;
        let mut frame = [0i32; MAX_CHANNELS];
        for (v, ch) in frame.iter_mut().zip(self.chans.iter_mut()).take(self.n) {
            *v = read_channel(ch, od, signals);
        }
        let n = self.n;
        let at = self.write as usize * n;
        if let Some(dst) = self.storage.as_mut().get_mut(at..at + n) {
            for (d, v) in dst.iter_mut().zip(&frame) {
                *d = *v as u32;
            }
        }
        let this = self.write;
        self.write = if self.write + 1 >= self.frames {
            0
        } else {
            self.write + 1
        };
        self.filled = (self.filled + 1).min(self.frames);
        match self.state {
            State::Armed => {
                let v = match self.source {
                    Source::Immediate => None,
                    Source::Channel(k) => frame.get(usize::from(k)).copied(),
                    Source::StatusBit { axis, bit } => {
                        let sw = od
                            .get(0x6041 + u16::from(axis) * crate::AXIS_B_CIA402, 0)
                            .unwrap_or(0);
                        Some(((sw >> bit) & 1) as i32)
                    }
                };
                let level = match self.source {
                    Source::StatusBit { .. } => 1,
                    _ => self.config.level,
                };
                // the pre-trigger share must be recorded before this sample
                let ready = self.filled > self.pre;
                let fired = match v {
                    None => ready,
                    Some(v) => ready && self.condition.met(self.last, v, level),
                };
                self.last = v;
                if fired {
                    self.trigger_at = this;
                    self.post = self.frames - self.pre - 1;
                    self.state = State::Triggered;
                    self.complete_if_done();
                }
            }
            State::Triggered => {
                self.post = self.post.saturating_sub(1);
                self.complete_if_done();
            }
            State::Idle | State::Complete => {}
        }
    }

    fn complete_if_done(&mut self) {
        if self.post == 0 {
            // the ring is full (pre + 1 + post = frames samples since the
            // pre-trigger share): the oldest sample is the next to write
            self.start = self.write;
            self.state = State::Complete;
            self.traces = self.traces.wrapping_add(1);
        }
    }

    /// Sample `i` of channel `k` of the complete trace.
    pub fn value(&self, i: u32, k: usize) -> Option<i32> {
        if self.state != State::Complete || i >= self.frames || k >= self.n {
            return None;
        }
        let ring = (self.start + i) % self.frames;
        self.storage
            .as_ref()
            .get(ring as usize * self.n + k)
            .map(|&w| w as i32)
    }

    /// Bytes of the complete trace (samples × channels × 4, sample by sample).
    pub fn trace_bytes(&self) -> usize {
        self.frames as usize * self.n * 4
    }

    /// Block `k` (0-based) of the complete trace into `buf` (at least
    /// [`BLOCK_BYTES`]): sample by sample, channel by channel, 32 bits
    /// little-endian each. 0800 0022h unless complete; 0800 0024h ("no data
    /// available") beyond the trace's end. In normal mode, reading the last
    /// block arms the next trace.
    pub fn read_block(&mut self, k: u8, buf: &mut [u8]) -> Result<usize, SdoAbort> {
        self.read_piece(usize::from(k), BLOCK_BYTES, buf)
    }

    /// Piece `k` of `piece` bytes (a multiple of 4) of the complete trace
    /// into `buf` (at least `piece` bytes), as [`read_block`](Self::read_block)
    /// does for pieces of [`BLOCK_BYTES`]: the trace in the pieces a
    /// fieldbus carries (a PROFINET record, `drive_pn::scope_record`).
    pub fn read_piece(&mut self, k: usize, piece: usize, buf: &mut [u8]) -> Result<usize, SdoAbort> {
        if self.state != State::Complete {
            return Err(SdoAbort::DEVICE_STATE);
        }
        let total = self.trace_bytes();
        let from = k.saturating_mul(piece & !3);
        if from >= total {
            return Err(SdoAbort::NO_DATA);
        }
        let len = (total - from).min(piece & !3);
        let out = buf.get_mut(..len).ok_or(SdoAbort::OUT_OF_MEMORY)?;
        let n = self.n.max(1) as u32;
        for (w, chunk) in (from / 4..).zip(out.chunks_exact_mut(4)) {
            let w = w as u32;
            let v = self.value(w / n, (w % n) as usize).unwrap_or(0);
            chunk.copy_from_slice(&v.to_le_bytes());
        }
        if from + len == total && self.config.normal {
            self.restart();
        }
        Ok(len)
    }
}

/// `a − b` on a ring of `m` positions.
fn ring_sub(a: u32, b: u32, m: u32) -> u32 {
    if a >= b {
        a - b
    } else {
        a + m - b
    }
}

/// A channel's value now: an entry through its prepared access (prepared
/// again when the configuration moved), else the dictionary's cached path.
fn read_channel(ch: &mut Channel, od: &DriveObjects, signals: &[Signals; 2]) -> i32 {
    match ch {
        Channel::Off => 0,
        Channel::Signal { axis, signal } => signals.get(usize::from(*axis)).map_or(0, |s| s.get(*signal)),
        Channel::Entry { index, sub, prepared } => {
            if let Some(v) = prepared.as_ref().and_then(|p| od.read_prepared(p)) {
                return v as i32;
            }
            *prepared = od.prepare(*index, *sub, CommState::Op);
            prepared
                .as_ref()
                .and_then(|p| od.read_prepared(p))
                .or_else(|| od.get(*index, *sub).ok())
                .map_or(0, |v| v as i32)
        }
    }
}
