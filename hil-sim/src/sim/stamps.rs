//! What a simulated drive records of its timing: the control-cycle starts
//! under the PLL, the SYNC0 pulses it saw, and its SYNC0 lock (`hil-sim
//! serve` prints it).

use nanos::Nanos;

/// One control-cycle start under the PLL.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CycleStamp {
    /// Simulation time of the start.
    pub now: Nanos,
    /// The MCU's local time of the start (the drive's clock).
    pub local: Nanos,
    /// The ESC's DC system time at the start, ns.
    pub system_ns: u64,
    /// Position in the SYNC0 cycle (0 = the aligned cycle).
    pub index: u32,
    /// The PLL was phase locked after this start.
    pub locked: bool,
    /// The cycle read the RxPDO (the aligned cycle).
    pub rx: bool,
    /// The cycle wrote the TxPDO (the aligned cycle).
    pub tx: bool,
}

/// The PLL's phase lock (the SYNC0 lock, A298 bit 10) as the control cycles
/// saw it: followed at every control cycle, so a loss between two looks of
/// a caller is counted too (`hil-sim serve` prints it).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PllLock {
    /// Phase locked after the last control cycle.
    pub locked: bool,
    /// Times the lock was gained.
    pub gained: u32,
    /// Times it was lost (the PLL lost it, or went: SYNC0 stopped or changed).
    pub lost: u32,
    /// Simulation time of the last gain or loss.
    pub changed: Nanos,
    /// The last loss.
    pub last_loss: Option<LockLoss>,
    /// Simulation time of the last frame that passed the drive's ESC.
    pub last_frame: Option<Nanos>,
}

/// One loss of the PLL's phase lock.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LockLoss {
    /// Simulation time of the control cycle that found the lock lost.
    pub at: Nanos,
    /// The drive's AL state then.
    pub state: ::esc::AlState,
    /// Time since the last frame had passed the drive's ESC (`None`: no frame yet).
    pub since_frame: Option<Nanos>,
}

impl PllLock {
    /// Follows the lock after the control cycle at `now`.
    pub(super) fn follow(&mut self, locked: bool, now: Nanos, state: ::esc::AlState) {
        if locked == self.locked {
            return;
        }
        self.locked = locked;
        self.changed = now;
        if locked {
            self.gained = self.gained.saturating_add(1);
        } else {
            self.lost = self.lost.saturating_add(1);
            self.last_loss = Some(LockLoss {
                at: now,
                state,
                since_frame: self.last_frame.map(|f| now.saturating_sub(f)),
            });
        }
    }
}

/// One SYNC0 pulse as the drive saw it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sync0Stamp {
    /// Simulation time of the pulse.
    pub now: Nanos,
    /// The ESC's local time at the pulse, ns.
    pub local_ns: u64,
    /// The ESC's DC system time of the pulse (start time + k · cycle), ns.
    pub system_ns: u64,
    /// Pulses since the previous stamp (1 unless pulses were missed).
    pub pulses: u32,
}
