//! The provider of our input CR (drive → controller).

use super::{ConfigError, CrConfig, DataStatus, Ioxs, CLOCK_UNIT_NS, MAX_IO_OBJECTS};
use crate::wire::{emit_header, ethertype};
use nanos::Nanos;

/// Why [`Provider::poll`] could not build its frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TxError {
    /// The buffer is shorter than [`CrConfig::frame_len`].
    BufferTooShort,
}

/// Counters of the provider (wrapping).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ProviderStats {
    /// Frames built.
    pub sent: u32,
    /// Cycles that passed without a frame because `poll` came late.
    pub skipped: u32,
}

/// The RT_CLASS_1 provider of one CR: one frame per cycle, at
/// `origin + (Phase − 1) × send clock + k × cycle`.
#[derive(Clone, Debug)]
pub struct Provider {
    cfg: CrConfig,
    origin: Nanos,
    first: Nanos,
    next_k: u64,
    status: DataStatus,
    iops: heapless::Vec<Ioxs, MAX_IO_OBJECTS>,
    iocs: heapless::Vec<Ioxs, MAX_IO_OBJECTS>,
    stats: ProviderStats,
}

impl Provider {
    /// A provider for `cfg` (checked with [`CrConfig::validate`]) whose cycle
    /// starts at `now`. DataStatus starts as [`DataStatus::RUNNING`], every
    /// IOPS and IOCS as BAD until the application says otherwise.
    pub fn new(cfg: CrConfig, now: Nanos) -> Result<Provider, ConfigError> {
        cfg.validate()?;
        let phase_units = u64::from(cfg.phase.saturating_sub(1)) * u64::from(cfg.send_clock_factor);
        let mut iops = heapless::Vec::new();
        let mut iocs = heapless::Vec::new();
        for _ in &cfg.objects {
            let _ = iops.push(Ioxs::BAD);
        }
        for _ in &cfg.iocs {
            let _ = iocs.push(Ioxs::BAD);
        }
        Ok(Provider {
            origin: now,
            first: now.saturating_add(Nanos::from_ns(phase_units * CLOCK_UNIT_NS)),
            next_k: 0,
            status: DataStatus::RUNNING,
            iops,
            iocs,
            stats: ProviderStats::default(),
            cfg,
        })
    }

    /// Its configuration.
    pub fn config(&self) -> &CrConfig {
        &self.cfg
    }

    /// Its counters.
    pub fn stats(&self) -> &ProviderStats {
        &self.stats
    }

    /// The DataStatus the next frame carries.
    pub fn data_status(&self) -> DataStatus {
        self.status
    }

    /// ProviderState run (`true`) or stop.
    pub fn set_run(&mut self, run: bool) {
        self.set_bit(DataStatus::PROVIDER_RUN, run);
    }

    /// DataValid.
    pub fn set_data_valid(&mut self, valid: bool) {
        self.set_bit(DataStatus::DATA_VALID, valid);
    }

    /// StationProblemIndicator: `true` while diagnosis exists (the bit then
    /// reads 0, "problem detected").
    pub fn set_station_problem(&mut self, problem: bool) {
        self.set_bit(DataStatus::STATION_OK, !problem);
    }

    fn set_bit(&mut self, bit: u8, on: bool) {
        if on {
            self.status.0 |= bit;
        } else {
            self.status.0 &= !bit;
        }
    }

    /// The IOPS of a submodule's data from now on; `false` if the CR has no
    /// such object.
    pub fn set_iops(&mut self, slot: u16, subslot: u16, iops: Ioxs) -> bool {
        let addrs = self.cfg.objects.iter().map(|o| (o.slot, o.subslot));
        set_at(addrs, &mut self.iops, (slot, subslot), iops)
    }

    /// Every IOPS.
    pub fn set_all_iops(&mut self, iops: Ioxs) {
        self.iops.iter_mut().for_each(|v| *v = iops);
    }

    /// The IOCS we send for a submodule of the controller's outputs; `false`
    /// if the CR has no such entry.
    pub fn set_iocs(&mut self, slot: u16, subslot: u16, iocs: Ioxs) -> bool {
        let addrs = self.cfg.iocs.iter().map(|o| (o.slot, o.subslot));
        set_at(addrs, &mut self.iocs, (slot, subslot), iocs)
    }

    /// Every IOCS.
    pub fn set_all_iocs(&mut self, iocs: Ioxs) {
        self.iocs.iter_mut().for_each(|v| *v = iocs);
    }

    /// When the next frame is due.
    pub fn poll_at(&self) -> Nanos {
        self.send_time(self.next_k)
    }

    fn send_time(&self, k: u64) -> Nanos {
        let cycle = self.cfg.cycle().as_ns();
        self.first.saturating_add(Nanos::from_ns(cycle.saturating_mul(k)))
    }

    /// Builds the frame of the cycle that is due at `now` in `buf`, or
    /// nothing if none is due. A late call sends the latest due cycle and
    /// counts the ones it missed; the cycle counter is the time of the
    /// scheduled send in 31.25 µs units since the start (mod 2^16), so it
    /// advances by SendClockFactor × ReductionRatio per cycle. The C_SDU is
    /// zero, with the IOPS/IOCS set; the application writes its data through
    /// the returned [`TxFrame`].
    pub fn poll<'p, 'b>(
        &'p mut self,
        now: Nanos,
        buf: &'b mut [u8],
    ) -> Result<Option<TxFrame<'p, 'b>>, TxError> {
        if now < self.poll_at() {
            return Ok(None);
        }
        let len = self.cfg.frame_len();
        if buf.len() < len {
            return Err(TxError::BufferTooShort);
        }
        let cycle = self.cfg.cycle().as_ns().max(1);
        let k = now.saturating_sub(self.first).as_ns() / cycle;
        let missed = k.saturating_sub(self.next_k);
        self.stats.skipped = self.stats.skipped.wrapping_add(missed as u32);
        self.next_k = k.saturating_add(1);
        let units = self.send_time(k).saturating_sub(self.origin).as_ns() / CLOCK_UNIT_NS;
        let counter = units as u16;
        let buf = buf.get_mut(..len).ok_or(TxError::BufferTooShort)?;
        buf.fill(0);
        let at = emit_header(
            buf,
            self.cfg.remote,
            self.cfg.local,
            self.cfg.tag,
            ethertype::PROFINET,
        )
        .ok_or(TxError::BufferTooShort)?;
        let body = buf.get_mut(at..).ok_or(TxError::BufferTooShort)?;
        let (id, rest) = body.split_at_mut_checked(2).ok_or(TxError::BufferTooShort)?;
        put(id, &self.cfg.frame_id.to_be_bytes());
        let (csdu, trailer) = rest
            .split_at_mut_checked(self.cfg.data_length as usize)
            .ok_or(TxError::BufferTooShort)?;
        for (o, v) in self.cfg.objects.iter().zip(&self.iops) {
            if let Some(b) = csdu.get_mut(o.iops_offset()) {
                *b = v.0;
            }
        }
        for (c, v) in self.cfg.iocs.iter().zip(&self.iocs) {
            if let Some(b) = csdu.get_mut(c.offset as usize) {
                *b = v.0;
            }
        }
        if let [c0, c1, ds, ts] = trailer {
            [*c0, *c1] = counter.to_be_bytes();
            *ds = self.status.0;
            *ts = 0;
        }
        self.stats.sent = self.stats.sent.wrapping_add(1);
        Ok(Some(TxFrame {
            cfg: &self.cfg,
            frame: buf,
            csdu_at: at + 2,
            counter,
        }))
    }
}

/// A built cyclic frame, still open for the application's input data.
#[derive(Debug)]
pub struct TxFrame<'p, 'b> {
    cfg: &'p CrConfig,
    frame: &'b mut [u8],
    csdu_at: usize,
    counter: u16,
}

impl TxFrame<'_, '_> {
    /// The data bytes of a submodule, to fill in place.
    pub fn data_mut(&mut self, slot: u16, subslot: u16) -> Option<&mut [u8]> {
        let o = self.cfg.object(slot, subslot)?;
        let start = self.csdu_at + o.offset as usize;
        self.frame.get_mut(start..start + o.len as usize)
    }

    /// Copies a submodule's data (as much as fits; the rest stays zero);
    /// `false` if the CR has no such object or `data` has another length.
    pub fn set_data(&mut self, slot: u16, subslot: u16, data: &[u8]) -> bool {
        match self.data_mut(slot, subslot) {
            Some(d) => {
                let n = d.len().min(data.len());
                if let (Some(d), Some(s)) = (d.get_mut(..n), data.get(..n)) {
                    d.copy_from_slice(s);
                }
                n == data.len() && n == d.len()
            }
            None => false,
        }
    }

    /// Its cycle counter.
    pub fn cycle_counter(&self) -> u16 {
        self.counter
    }

    /// Its length in bytes.
    pub fn len(&self) -> usize {
        self.frame.len()
    }

    /// Never empty (a frame is at least 60 bytes).
    pub fn is_empty(&self) -> bool {
        self.frame.is_empty()
    }

    /// The frame's bytes.
    pub fn bytes(&self) -> &[u8] {
        self.frame
    }
}

/// Copies `src` into the start of `dst` (as far as both go): no length panic.
fn put(dst: &mut [u8], src: &[u8]) {
    for (d, s) in dst.iter_mut().zip(src) {
        *d = *s;
    }
}

/// Sets the status in `vals` at the position of `at` among `addrs` (slot,
/// subslot); `false` if `at` is not there.
fn set_at(mut addrs: impl Iterator<Item = (u16, u16)>, vals: &mut [Ioxs], at: (u16, u16), v: Ioxs) -> bool {
    match addrs.position(|a| a == at).and_then(|i| vals.get_mut(i)) {
        Some(x) => {
            *x = v;
            true
        }
        None => false,
    }
}
