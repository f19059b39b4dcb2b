//! Copies of a line in its present state ([`Simulation::try_clone`]): the
//! fuzz targets start each input from one instead of building the line again.

use super::{SimDrive, Simulation};

impl SimDrive {
    /// A copy of this drive in its present state; `None` with an IP stack
    /// bound ([`SimDrive::bind_net`]: smoltcp's interface cannot be copied).
    pub fn try_clone(&self) -> Option<Self> {
        if self.net.is_some() {
            return None;
        }
        Some(Self {
            esc: self.esc.clone(),
            drive: self.drive.clone(),
            state_log: self.state_log.clone(),
            motors: self.motors.clone(),
            conditions: self.conditions,
            cycle: self.cycle,
            sync0_log: self.sync0_log.clone(),
            cycle_log: self.cycle_log.clone(),
            pll_lock: self.pll_lock,
            feedback: self.feedback,
            electrical: self.electrical.clone(),
            next_cycle: self.next_cycle,
            next_tick: self.next_tick,
            sm2_event: self.sm2_event,
            net: None,
            scope: self.scope.clone(),
        })
    }
}

impl Simulation<SimDrive> {
    /// A copy of the whole line in its present state (drives, ESCs, motors,
    /// clock): a snapshot to start many runs from (the fuzz targets start
    /// each input from a line already in Pre-Op or Op instead of building
    /// it again). `None` while a drive has an IP stack bound or a capture
    /// is being recorded, which cannot be copied.
    pub fn try_clone(&self) -> Option<Self> {
        if self.pcap.is_some() {
            return None;
        }
        let drives = self
            .drives
            .iter()
            .map(SimDrive::try_clone)
            .collect::<Option<Vec<_>>>()?;
        Some(Self {
            drives,
            now: self.now,
            last_poll: self.last_poll,
            frames: self.frames,
            pcap: None,
            jitter: self.jitter,
            next_events: Vec::new(),
        })
    }
}
