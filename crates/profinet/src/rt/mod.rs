//! RT_CLASS_1 cyclic data (P-042): the consumer of the controller's output CR
//! ([`Consumer`]) and the provider of our input CR ([`Provider`]).
//!
//! A cyclic frame is `FrameID (2) | C_SDU (DataLength) | CycleCounter (2) |
//! DataStatus (1) | TransferStatus (1)` after the Ethernet header (with the
//! 802.1Q tag of the CR's IOCRTagHeader). The C_SDU holds the IO data objects,
//! each followed by its IOPS, and the IOCS bytes of the other direction, at
//! the offsets the controller chose in its IOCRBlockReq ([`CrConfig`]).
//!
//! Time: the cycle is SendClockFactor × ReductionRatio × 31.25 µs
//! ([`CrConfig::cycle`]); the cycle counter counts 31.25 µs units. Both
//! sides take `now` as an argument and say when they next need it
//! ([`Consumer::poll_at`], [`Provider::poll_at`]); nothing reads a clock.
//!
//! Reaction to AR loss (Q-07, P-036): [`ConsumerEvent::WatchdogExpired`] is
//! the AR loss: the connection management aborts the AR (RTA ERR with
//! [`crate::alarm::AbortCode::CONSUMER_DHT_EXPIRED`]) and the drive
//! personality raises its communication fault (quick stop, then fault, like
//! EtherCAT's event 52 cause 6). [`ConsumerEvent::DataHoldExpired`] means the
//! outputs take their substitute values; what that is, the caller decides.

mod consumer;
mod provider;

pub use consumer::{
    Consumer, ConsumerEvent, ConsumerState, ConsumerStats, CyclicData, Invalid, Received, RxError,
};
pub use provider::{Provider, ProviderStats, TxError, TxFrame};

use crate::wire::{FrameKind, MacAddr};
use nanos::Nanos;

/// The send clock unit: 31.25 µs, in ns.
pub const CLOCK_UNIT_NS: u64 = 31_250;
/// Most IO data objects (and most IOCS entries) one CR holds.
pub const MAX_IO_OBJECTS: usize = 16;
/// Smallest C_SDU of an RT_CLASS_1 frame (makes every frame ≥ 60 bytes).
pub const MIN_DATA_LENGTH: u16 = 40;
/// Largest C_SDU.
pub const MAX_DATA_LENGTH: u16 = 1440;
/// Largest SendClockFactor × ReductionRatio (512 ms) for RT_CLASS_1.
pub const MAX_CYCLE_UNITS: u32 = 16_384;
/// Largest WatchdogFactor / DataHoldFactor.
pub const MAX_FACTOR: u16 = 0x1E00;
/// FrameID (2) + APDU status (4) around the C_SDU.
pub const RT_OVERHEAD: usize = 6;

/// An IOPS or IOCS byte (IOxS).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Ioxs(pub u8);

impl Ioxs {
    /// DataState good, detected by the subslot.
    pub const GOOD: Ioxs = Ioxs(0x80);
    /// DataState bad, detected by the subslot.
    pub const BAD: Ioxs = Ioxs(0x00);
    /// DataState bad, detected by the IO device (instance 2).
    pub const BAD_BY_DEVICE: Ioxs = Ioxs(0x40);

    /// DataState (bit 7) good.
    pub const fn is_good(self) -> bool {
        self.0 & 0x80 != 0
    }
}

/// The DataStatus byte of a cyclic frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DataStatus(pub u8);

impl DataStatus {
    /// Bit 0, State: 1 primary, 0 backup.
    pub const PRIMARY: u8 = 0x01;
    /// Bit 1, Redundancy.
    pub const REDUNDANCY: u8 = 0x02;
    /// Bit 2, DataValid.
    pub const DATA_VALID: u8 = 0x04;
    /// Bit 4, ProviderState: 1 run, 0 stop.
    pub const PROVIDER_RUN: u8 = 0x10;
    /// Bit 5, StationProblemIndicator: 1 normal, 0 problem detected.
    pub const STATION_OK: u8 = 0x20;
    /// Bit 7, Ignore: 1 the consumer ignores the frame.
    pub const IGNORE: u8 = 0x80;

    /// Primary, valid, run, no station problem (0x35): what a healthy
    /// provider sends.
    pub const RUNNING: DataStatus =
        DataStatus(Self::PRIMARY | Self::DATA_VALID | Self::PROVIDER_RUN | Self::STATION_OK);

    /// State primary.
    pub const fn primary(self) -> bool {
        self.0 & Self::PRIMARY != 0
    }
    /// Redundancy bit.
    pub const fn redundancy(self) -> bool {
        self.0 & Self::REDUNDANCY != 0
    }
    /// DataValid.
    pub const fn data_valid(self) -> bool {
        self.0 & Self::DATA_VALID != 0
    }
    /// ProviderState run.
    pub const fn provider_run(self) -> bool {
        self.0 & Self::PROVIDER_RUN != 0
    }
    /// StationProblemIndicator says "normal" (no diagnosis at the provider).
    pub const fn station_ok(self) -> bool {
        self.0 & Self::STATION_OK != 0
    }
    /// Ignore bit.
    pub const fn ignore(self) -> bool {
        self.0 & Self::IGNORE != 0
    }
}

/// One IO data object of a CR: `len` data bytes at `offset` in the C_SDU,
/// its IOPS right after them (at `offset + len`). A submodule without IO
/// data in this direction (the DAP's subslots) has `len` 0: an IOPS only.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct IoDataObject {
    /// Slot number.
    pub slot: u16,
    /// Subslot number.
    pub subslot: u16,
    /// FrameOffset of the data in the C_SDU.
    pub offset: u16,
    /// Data length in bytes (0 for an IOPS-only object).
    pub len: u16,
}

impl IoDataObject {
    /// The offset of its IOPS.
    pub const fn iops_offset(&self) -> usize {
        self.offset as usize + self.len as usize
    }
}

/// One IOCS of a CR: the consumer status, for a submodule of the other
/// direction, at `offset` in the C_SDU.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct IocsEntry {
    /// Slot number.
    pub slot: u16,
    /// Subslot number.
    pub subslot: u16,
    /// FrameOffset of the IOCS byte in the C_SDU.
    pub offset: u16,
}

/// The configuration of one RT_CLASS_1 CR, the way the connection management
/// fills it from an IOCRBlockReq (and its IOCRBlockRes): plain values, no
/// behaviour. [`CrConfig::validate`] checks it; [`Consumer::new`] and
/// [`Provider::new`] refuse what it refuses.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CrConfig {
    /// FrameID of the CR (0x8000…0xFBFF; for the output CR the one our
    /// IOCRBlockRes assigned).
    pub frame_id: u16,
    /// DataLength: the C_SDU length in bytes (40…1440).
    pub data_length: u16,
    /// SendClockFactor (1…128): the send clock is this × 31.25 µs.
    pub send_clock_factor: u16,
    /// ReductionRatio (1, 2, 4 … 512): one frame every this many send clocks.
    pub reduction_ratio: u16,
    /// Phase (1…ReductionRatio): which send clock of the reduction the frame
    /// goes in (provider only).
    pub phase: u16,
    /// WatchdogFactor (1…0x1E00): consumer AR loss after this many cycles
    /// without an accepted frame.
    pub watchdog_factor: u16,
    /// DataHoldFactor (1…0x1E00): outputs to substitute values after this
    /// many cycles without a valid frame.
    pub data_hold_factor: u16,
    /// Our MAC: the provider's source, the consumer's expected destination.
    pub local: MacAddr,
    /// The controller's MAC: the provider's destination, the consumer's
    /// expected source.
    pub remote: MacAddr,
    /// IOCRTagHeader as the 802.1Q TCI our provider frames carry (priority
    /// in bits 15…13, VLAN ID in bits 11…0; 0xC000 = priority 6, VID 0);
    /// `None` sends untagged. The consumer accepts tagged and untagged.
    pub tag: Option<u16>,
    /// The IO data objects (data + IOPS) of this CR's provider side.
    pub objects: heapless::Vec<IoDataObject, MAX_IO_OBJECTS>,
    /// The IOCS bytes this CR carries for the other direction.
    pub iocs: heapless::Vec<IocsEntry, MAX_IO_OBJECTS>,
}

/// What [`CrConfig::validate`] refuses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConfigError {
    /// FrameID outside the RT_CLASS_1 range.
    FrameId,
    /// DataLength outside 40…1440.
    DataLength,
    /// SendClockFactor outside 1…128.
    SendClockFactor,
    /// ReductionRatio not a power of two in 1…512, or the cycle over 512 ms.
    ReductionRatio,
    /// Phase outside 1…ReductionRatio.
    Phase,
    /// WatchdogFactor outside 1…0x1E00.
    WatchdogFactor,
    /// DataHoldFactor outside 1…0x1E00.
    DataHoldFactor,
    /// An IO data object, IOPS or IOCS outside the C_SDU, or two overlapping.
    Layout,
}

impl CrConfig {
    /// The cycle: SendClockFactor × ReductionRatio × 31.25 µs.
    pub const fn cycle(&self) -> Nanos {
        Nanos::from_ns(self.cycle_units() as u64 * CLOCK_UNIT_NS)
    }

    /// The cycle in 31.25 µs units (the cycle counter's step per frame).
    pub const fn cycle_units(&self) -> u32 {
        self.send_clock_factor as u32 * self.reduction_ratio as u32
    }

    /// The length of a frame of this CR (Ethernet header, tag if any,
    /// FrameID, C_SDU, APDU status); never below 60.
    pub fn frame_len(&self) -> usize {
        let header = crate::wire::HEADER_LEN
            + if self.tag.is_some() {
                crate::wire::VLAN_TAG_LEN
            } else {
                0
            };
        header + RT_OVERHEAD + self.data_length as usize
    }

    /// The IO data object of a submodule.
    pub fn object(&self, slot: u16, subslot: u16) -> Option<&IoDataObject> {
        self.objects
            .iter()
            .find(|o| o.slot == slot && o.subslot == subslot)
    }

    /// The IOCS entry of a submodule.
    pub fn iocs_entry(&self, slot: u16, subslot: u16) -> Option<&IocsEntry> {
        self.iocs.iter().find(|o| o.slot == slot && o.subslot == subslot)
    }

    /// Checks the ranges of IEC 61158-6-10 for RT_CLASS_1 and the layout
    /// (every byte inside the C_SDU, no two overlapping).
    pub fn validate(&self) -> Result<(), ConfigError> {
        if !matches!(FrameKind::of(self.frame_id), FrameKind::Cyclic(_)) {
            return Err(ConfigError::FrameId);
        }
        if !(MIN_DATA_LENGTH..=MAX_DATA_LENGTH).contains(&self.data_length) {
            return Err(ConfigError::DataLength);
        }
        if !(1..=128).contains(&self.send_clock_factor) {
            return Err(ConfigError::SendClockFactor);
        }
        let rr = self.reduction_ratio;
        if !rr.is_power_of_two() || rr > 512 || self.cycle_units() > MAX_CYCLE_UNITS {
            return Err(ConfigError::ReductionRatio);
        }
        if !(1..=rr).contains(&self.phase) {
            return Err(ConfigError::Phase);
        }
        if !(1..=MAX_FACTOR).contains(&self.watchdog_factor) {
            return Err(ConfigError::WatchdogFactor);
        }
        if !(1..=MAX_FACTOR).contains(&self.data_hold_factor) {
            return Err(ConfigError::DataHoldFactor);
        }
        self.check_layout()
    }

    /// Every byte range (data + IOPS, IOCS) as `(start, end)`.
    fn ranges(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        let data = self
            .objects
            .iter()
            .map(|o| (o.offset as usize, o.iops_offset() + 1));
        let iocs = self
            .iocs
            .iter()
            .map(|c| (c.offset as usize, c.offset as usize + 1));
        data.chain(iocs)
    }

    fn check_layout(&self) -> Result<(), ConfigError> {
        let end = self.data_length as usize;
        for (i, (a0, a1)) in self.ranges().enumerate() {
            if a1 > end {
                return Err(ConfigError::Layout);
            }
            let overlaps = self.ranges().skip(i + 1).any(|(b0, b1)| a0 < b1 && b0 < a1);
            if overlaps {
                return Err(ConfigError::Layout);
            }
        }
        Ok(())
    }
}

/// `counter` is newer than `last` (16-bit wrap): IEC 61158-6-10 takes a
/// difference of 1…61440 units as newer, 0 and the 4096 units behind as old.
pub const fn counter_is_newer(counter: u16, last: u16) -> bool {
    let diff = counter.wrapping_sub(last);
    diff >= 1 && diff <= 61_440
}

#[cfg(test)]
pub(crate) mod tests;
#[cfg(test)]
pub(crate) mod tests_vectors;
