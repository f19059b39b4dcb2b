//! The consumer of the controller's output CR (controller → drive).

use super::{counter_is_newer, ConfigError, CrConfig, DataStatus, IoDataObject, Ioxs};
use crate::alarm::AbortCode;
use crate::wire::{ethertype, split_frame_id, EthFrame, FrameKind};
use nanos::Nanos;

/// Where a consumer is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConsumerState {
    /// No frame accepted yet; no timer runs (the connection management's
    /// own connect-phase timeout applies until the first frame).
    Waiting,
    /// Frames arrive; watchdog and data hold timer run.
    Running,
    /// The watchdog expired: the AR is lost; every frame is refused.
    Expired,
}

/// What the consumer reports from [`Consumer::poll`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConsumerEvent {
    /// No valid (DataValid, primary) frame for DataHoldFactor cycles: the
    /// outputs take their substitute values until valid data returns.
    DataHoldExpired,
    /// No accepted frame for WatchdogFactor cycles: AR loss. The
    /// connection management aborts the AR
    /// ([`crate::alarm::AbortCode::CONSUMER_DHT_EXPIRED`]); the drive
    /// personality raises its communication fault.
    WatchdogExpired,
}

impl ConsumerEvent {
    /// The AR abort this event calls for: the watchdog's is
    /// [`AbortCode::CONSUMER_DHT_EXPIRED`] (for [`crate::alarm::AlarmCr::abort`]);
    /// a data hold expiry aborts nothing.
    pub const fn abort_code(self) -> Option<AbortCode> {
        match self {
            ConsumerEvent::WatchdogExpired => Some(AbortCode::CONSUMER_DHT_EXPIRED),
            ConsumerEvent::DataHoldExpired => None,
        }
    }
}

/// Why a received frame was dropped. Every drop is counted
/// ([`ConsumerStats`]) and changes no other state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RxError {
    /// Not a PROFINET frame, or shorter than a FrameID.
    NotRt,
    /// A frame with another FrameID (another CR, DCP, alarms).
    WrongFrameId,
    /// This CR's FrameID but not 2 + DataLength + 4 bytes.
    WrongLength,
    /// Source is not the controller, or destination not us.
    WrongAddress,
    /// TransferStatus ≠ 0.
    TransferStatus,
    /// DataStatus.Ignore set.
    Ignored,
    /// CycleCounter not newer than the last accepted one.
    Stale,
    /// The watchdog has expired; the AR is gone.
    Expired,
}

/// Why accepted outputs are not handed to the application.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Invalid {
    /// DataValid = 0.
    DataInvalid,
    /// State = backup (another AR of the set is primary).
    Backup,
    /// ProviderState = stop (the controller is in STOP).
    ProviderStop,
}

/// A frame the consumer accepted: it restarted the watchdog.
#[derive(Clone, Copy, Debug)]
pub struct Received<'c, 'f> {
    /// Its CycleCounter.
    pub cycle_counter: u16,
    /// Its DataStatus.
    pub status: DataStatus,
    /// DataStatus bits that changed against the last accepted frame (all
    /// bits that are set, for the first frame).
    pub changed: u8,
    /// This is the first accepted frame of the CR (cyclic exchange started).
    pub first: bool,
    /// The outputs, when the frame is valid, primary and the controller runs.
    pub outputs: Result<CyclicData<'c, 'f>, Invalid>,
}

/// The C_SDU of a valid frame, read through the CR's layout.
#[derive(Clone, Copy, Debug)]
pub struct CyclicData<'c, 'f> {
    cfg: &'c CrConfig,
    csdu: &'f [u8],
}

impl<'c, 'f> CyclicData<'c, 'f> {
    /// The IOPS the controller sent for a submodule's outputs.
    pub fn iops(&self, slot: u16, subslot: u16) -> Option<Ioxs> {
        let o = self.cfg.object(slot, subslot)?;
        self.csdu.get(o.iops_offset()).map(|b| Ioxs(*b))
    }

    /// A submodule's output data, only while its IOPS is GOOD.
    pub fn data(&self, slot: u16, subslot: u16) -> Option<&'f [u8]> {
        let o = self.cfg.object(slot, subslot)?;
        self.object_data(o)
    }

    /// The IOCS the controller sent for one of our input submodules.
    pub fn iocs(&self, slot: u16, subslot: u16) -> Option<Ioxs> {
        let c = self.cfg.iocs_entry(slot, subslot)?;
        self.csdu.get(c.offset as usize).map(|b| Ioxs(*b))
    }

    /// Every IO data object with its IOPS and its data (`None` while BAD).
    pub fn objects(&self) -> impl Iterator<Item = (&'c IoDataObject, Ioxs, Option<&'f [u8]>)> + '_ {
        self.cfg.objects.iter().map(move |o| {
            let iops = self.csdu.get(o.iops_offset()).map_or(Ioxs::BAD, |b| Ioxs(*b));
            (o, iops, self.object_data(o))
        })
    }

    /// The whole C_SDU.
    pub fn csdu(&self) -> &'f [u8] {
        self.csdu
    }

    fn object_data(&self, o: &IoDataObject) -> Option<&'f [u8]> {
        let iops = Ioxs(*self.csdu.get(o.iops_offset())?);
        if !iops.is_good() {
            return None;
        }
        self.csdu.get(o.offset as usize..o.iops_offset())
    }
}

/// Counters of the consumer (wrapping).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ConsumerStats {
    /// Frames accepted (watchdog restarted).
    pub accepted: u32,
    /// Accepted frames with valid outputs.
    pub valid: u32,
    /// Dropped: another FrameID (or not RT).
    pub wrong_frame_id: u32,
    /// Dropped: wrong length.
    pub wrong_length: u32,
    /// Dropped: wrong source or destination.
    pub wrong_address: u32,
    /// Dropped: TransferStatus ≠ 0.
    pub transfer_status: u32,
    /// Dropped: Ignore bit.
    pub ignored: u32,
    /// Dropped: cycle counter not newer.
    pub stale: u32,
    /// Dropped after the watchdog expired.
    pub after_expiry: u32,
    /// Data hold expiries.
    pub data_hold_expired: u32,
}

/// The RT_CLASS_1 consumer of one CR.
#[derive(Clone, Debug)]
pub struct Consumer {
    cfg: CrConfig,
    state: ConsumerState,
    last_counter: u16,
    last_status: DataStatus,
    watchdog_at: Nanos,
    hold_at: Nanos,
    hold_expired: bool,
    stats: ConsumerStats,
}

impl Consumer {
    /// A consumer for `cfg` (checked with [`CrConfig::validate`]), waiting
    /// for its first frame.
    pub fn new(cfg: CrConfig) -> Result<Consumer, ConfigError> {
        cfg.validate()?;
        Ok(Consumer {
            cfg,
            state: ConsumerState::Waiting,
            last_counter: 0,
            last_status: DataStatus(0),
            watchdog_at: Nanos::MAX,
            hold_at: Nanos::MAX,
            hold_expired: false,
            stats: ConsumerStats::default(),
        })
    }

    /// Its configuration.
    pub fn config(&self) -> &CrConfig {
        &self.cfg
    }

    /// Where it is.
    pub fn state(&self) -> ConsumerState {
        self.state
    }

    /// Its counters.
    pub fn stats(&self) -> &ConsumerStats {
        &self.stats
    }

    /// The DataStatus of the last accepted frame.
    pub fn last_status(&self) -> DataStatus {
        self.last_status
    }

    /// The outputs are current: running, data hold not expired, and the last
    /// accepted frame was valid, primary, run.
    pub fn outputs_valid(&self) -> bool {
        self.state == ConsumerState::Running && !self.hold_expired && usable(self.last_status).is_ok()
    }

    /// Frames arrived recently: running and the data hold timer has not
    /// expired (the "cyclic data exchanged" input of the BF LED).
    pub fn exchanging(&self) -> bool {
        self.state == ConsumerState::Running && !self.hold_expired
    }

    /// Checks a received frame against this CR and takes it if it belongs:
    /// FrameID, length, addresses, TransferStatus, Ignore, a newer cycle
    /// counter. A taken frame restarts the watchdog; a valid primary one also
    /// the data hold timer. A dropped frame changes nothing but a counter.
    pub fn receive<'c, 'f>(
        &'c mut self,
        now: Nanos,
        frame: &EthFrame<'f>,
    ) -> Result<Received<'c, 'f>, RxError> {
        let rest = match self.check(frame) {
            Ok(rest) => rest,
            Err(e) => {
                self.count(e);
                return Err(e);
            }
        };
        let n = rest.len();
        let (csdu, trailer) = rest.split_at(n.saturating_sub(4));
        let [c0, c1, ds, ts] = *trailer else {
            self.count(RxError::WrongLength);
            return Err(RxError::WrongLength);
        };
        let counter = u16::from_be_bytes([c0, c1]);
        let status = DataStatus(ds);
        let first = self.state == ConsumerState::Waiting;
        let verdict = if ts != 0 {
            Err(RxError::TransferStatus)
        } else if status.ignore() {
            Err(RxError::Ignored)
        } else if !first && !counter_is_newer(counter, self.last_counter) {
            Err(RxError::Stale)
        } else {
            Ok(())
        };
        if let Err(e) = verdict {
            self.count(e);
            return Err(e);
        }
        let cycle = self.cfg.cycle();
        let changed = if first { ds } else { ds ^ self.last_status.0 };
        self.state = ConsumerState::Running;
        self.last_counter = counter;
        self.last_status = status;
        self.watchdog_at = now.saturating_add(times(cycle, self.cfg.watchdog_factor));
        if first || (status.data_valid() && status.primary()) {
            // the first frame arms the data hold timer even when it is not
            // valid: a controller that never sends valid data trips it
            self.hold_at = now.saturating_add(times(cycle, self.cfg.data_hold_factor));
        }
        if status.data_valid() && status.primary() {
            self.hold_expired = false;
        }
        self.stats.accepted = self.stats.accepted.wrapping_add(1);
        let outputs = usable(status).map(|()| CyclicData { cfg: &self.cfg, csdu });
        if outputs.is_ok() {
            self.stats.valid = self.stats.valid.wrapping_add(1);
        }
        Ok(Received {
            cycle_counter: counter,
            status,
            changed,
            first,
            outputs,
        })
    }

    /// Runs the timers: the data hold expiry first, then the watchdog
    /// (call until `None`). Each is reported once.
    pub fn poll(&mut self, now: Nanos) -> Option<ConsumerEvent> {
        if self.state != ConsumerState::Running {
            return None;
        }
        if !self.hold_expired && now >= self.hold_at {
            self.hold_expired = true;
            self.stats.data_hold_expired = self.stats.data_hold_expired.wrapping_add(1);
            return Some(ConsumerEvent::DataHoldExpired);
        }
        if now >= self.watchdog_at {
            self.state = ConsumerState::Expired;
            return Some(ConsumerEvent::WatchdogExpired);
        }
        None
    }

    /// When [`Consumer::poll`] has something to do next ([`Nanos::MAX`]:
    /// nothing until a frame arrives).
    pub fn poll_at(&self) -> Nanos {
        match self.state {
            ConsumerState::Running if !self.hold_expired => self.hold_at.min(self.watchdog_at),
            ConsumerState::Running => self.watchdog_at,
            ConsumerState::Waiting | ConsumerState::Expired => Nanos::MAX,
        }
    }

    /// The bytes after the FrameID, if the frame is this CR's and well formed.
    fn check<'f>(&self, frame: &EthFrame<'f>) -> Result<&'f [u8], RxError> {
        if frame.ethertype != ethertype::PROFINET {
            return Err(RxError::NotRt);
        }
        let (kind, rest) = split_frame_id(frame.payload).ok_or(RxError::NotRt)?;
        if kind != FrameKind::Cyclic(self.cfg.frame_id) {
            return Err(RxError::WrongFrameId);
        }
        if rest.len() != self.cfg.data_length as usize + 4 {
            return Err(RxError::WrongLength);
        }
        if frame.src != self.cfg.remote || frame.dst != self.cfg.local {
            return Err(RxError::WrongAddress);
        }
        if self.state == ConsumerState::Expired {
            return Err(RxError::Expired);
        }
        Ok(rest)
    }

    fn count(&mut self, e: RxError) {
        let s = &mut self.stats;
        let c = match e {
            RxError::NotRt | RxError::WrongFrameId => &mut s.wrong_frame_id,
            RxError::WrongLength => &mut s.wrong_length,
            RxError::WrongAddress => &mut s.wrong_address,
            RxError::TransferStatus => &mut s.transfer_status,
            RxError::Ignored => &mut s.ignored,
            RxError::Stale => &mut s.stale,
            RxError::Expired => &mut s.after_expiry,
        };
        *c = c.wrapping_add(1);
    }
}

/// Outputs of a frame with this status may be used.
fn usable(status: DataStatus) -> Result<(), Invalid> {
    if !status.data_valid() {
        Err(Invalid::DataInvalid)
    } else if !status.primary() {
        Err(Invalid::Backup)
    } else if !status.provider_run() {
        Err(Invalid::ProviderStop)
    } else {
        Ok(())
    }
}

/// `factor` cycles.
fn times(cycle: Nanos, factor: u16) -> Nanos {
    Nanos::from_ns(cycle.as_ns().saturating_mul(u64::from(factor)))
}
