//! The drive as the application of the EtherCAT slave stack
//! ([`ecat::Application`]): A150 is its cycle, A258 chooses the RxPDO
//! monitoring, the DC-Sync rules of `dcsync` check a DC configuration, and
//! event 52 is the drive's answer when the slave leaves Op by itself.

use crate::dictionary::{LiveValues, WithLive};
use ecat::esm::OpLoss;
use ecat::{Application, DcRequest, PdoTimeout};
use esc::AlStatusCode;
use od::{CommState, Dictionary, ObjectInfo, SdoAbort};

pub use crate::params::{A150, A258};

/// A258 values with a special meaning (spec §13.1).
pub mod a258 {
    /// Monitoring off (as is 0).
    pub const OFF: u16 = 65535;
    /// Largest plain timeout, ms.
    pub const MAX_MS: u16 = 65531;
    /// A single lost packet is tolerated.
    pub const ONE_LOST: u16 = 65532;
    /// Up to 3 consecutive lost packets are tolerated.
    pub const THREE_LOST: u16 = 65533;
    /// SyncManager watchdog mode: the tolerance is the master's SM watchdog (A259).
    pub const SM_WATCHDOG: u16 = 65534;
}

/// The RxPDO monitoring A258 asks for: 0 / 65535 off, 1 … 65531 ms, 65532 /
/// 65533 one / three lost packets, 65534 the ESC's SM watchdog.
pub const fn pdo_timeout(a258: u16) -> PdoTimeout {
    match a258 {
        0 | a258::OFF => PdoTimeout::Off,
        1..=a258::MAX_MS => PdoTimeout::Ms(a258),
        a258::ONE_LOST => PdoTimeout::LostFrames(1),
        a258::THREE_LOST => PdoTimeout::LostFrames(3),
        _ => PdoTimeout::EscWatchdog,
    }
}

/// Event 52 "Communication" (spec §13.4): the causes (`E43`) the drive
/// raises for the bus. The EMCY is 7500h, error register 10h, `E82` = 52,
/// `E43` = the cause ([`crate::emcy::for_event`]); both axes run their fault
/// reaction (A29 / A540, E-129).
///
/// | Cause | When |
/// |---|---|
/// | [`PDO_TIMEOUT`](event52::PDO_TIMEOUT) (6) | the slave left Op: no RxPDO for longer than A258, or the ESC's SM watchdog (A258 = 65534) expired (AL 001Bh) |
/// | [`SYNC`](event52::SYNC) (7) | the slave left Op in DC mode for a synchronisation fault the PLL reported: SYNC0 timeout (0034h), late frames (0033h), lost lock (0032h) (E-131; the spec's cell merges synchronisation and connection errors, uncertain) |
/// | [`WRONG_FIRMWARE`](event52::WRONG_FIRMWARE) (15) | the projected fieldbus identification E59\[2\] ≠ the firmware's (E-130) |
pub mod event52 {
    /// `E82` of the event.
    pub const EVENT: u8 = 52;
    /// Cause 6: EtherCAT PDO timeout (process data missing).
    pub const PDO_TIMEOUT: u8 = 6;
    /// Cause 7: synchronisation (or connection) error; the value
    /// `dcsync::EVENT52_CAUSE_SYNC` the PLL reports.
    pub const SYNC: u8 = dcsync::EVENT52_CAUSE_SYNC;
    /// Cause 15: wrong firmware for the application.
    pub const WRONG_FIRMWARE: u8 = 15;
}

/// The event 52 cause of a loss of Op.
pub const fn event52_cause(loss: OpLoss) -> u8 {
    match loss {
        OpLoss::PdoTimeout => event52::PDO_TIMEOUT,
        OpLoss::Sync => event52::SYNC,
    }
}

/// The drive's dictionary (with its live values) as the slave stack's
/// application: the [`od::Dictionary`] of the CoE server (the runtime
/// passes [`DriveObjects::parameter_channel`](crate::DriveObjects::parameter_channel):
/// SDO values of the A213-scaled entries in A213\[1\]'s representation), and
/// the settings of [`ecat::Application`] read from A150 and A258.
pub struct EcatApp<'a, L: LiveValues>(pub WithLive<'a, L>);

impl<L: LiveValues> EcatApp<'_, L> {
    /// A150 in ns.
    fn a150_ns(&self) -> u32 {
        let us = self
            .0
            .objects
            .get(A150, 0)
            .ok()
            .and_then(|v| u32::try_from(v).ok())
            .unwrap_or(crate::params::A150_FALLBACK_US);
        us.saturating_mul(1000)
    }
}

impl<L: LiveValues> Dictionary for EcatApp<'_, L> {
    fn object(&self, index: u16) -> Option<&'static ObjectInfo> {
        self.0.object(index)
    }
    fn next_object(&self, after: Option<u16>) -> Option<&'static ObjectInfo> {
        self.0.next_object(after)
    }
    fn read(&mut self, index: u16, sub: u8, buf: &mut [u8], state: CommState) -> Result<usize, SdoAbort> {
        self.0.read(index, sub, buf, state)
    }
    fn write(&mut self, index: u16, sub: u8, data: &[u8], state: CommState) -> Result<(), SdoAbort> {
        self.0.write(index, sub, data, state)
    }
    fn process_data_bytes(&self) -> Option<(usize, usize)> {
        self.0.process_data_bytes()
    }
    fn sdo_info_enabled(&self) -> bool {
        self.0.sdo_info_enabled()
    }
    fn listed(&self, index: u16) -> bool {
        self.0.listed(index)
    }
}

impl<L: LiveValues> Application for EcatApp<'_, L> {
    fn cycle_ns(&mut self) -> u32 {
        self.a150_ns()
    }

    fn pdo_timeout(&mut self) -> PdoTimeout {
        let a258 = self
            .0
            .objects
            .get(A258, 0)
            .ok()
            .and_then(|v| u16::try_from(v).ok());
        pdo_timeout(a258.unwrap_or(0))
    }

    /// E-029, E-112…: the SYNC0 cycle a multiple k of A150 (≤ 8 ms), the
    /// SM cycles consistent ([`dcsync::validate()`]).
    fn check_dc(&mut self, dc: &DcRequest) -> Result<u32, AlStatusCode> {
        dcsync::validate(dc.sync0_ns, self.a150_ns(), dc.sm2_cycle_ns, dc.sm3_cycle_ns)
            .map_err(|e| AlStatusCode(e.al_status_code()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// E-126 / E-127: the A258 values and the monitoring they choose.
    #[test]
    fn e126_e127_a258_values_choose_the_monitoring() {
        assert_eq!(pdo_timeout(0), PdoTimeout::Off);
        assert_eq!(pdo_timeout(65535), PdoTimeout::Off);
        assert_eq!(pdo_timeout(1), PdoTimeout::Ms(1));
        assert_eq!(pdo_timeout(65531), PdoTimeout::Ms(65531));
        assert_eq!(pdo_timeout(65532), PdoTimeout::LostFrames(1));
        assert_eq!(pdo_timeout(65533), PdoTimeout::LostFrames(3));
        assert_eq!(pdo_timeout(65534), PdoTimeout::EscWatchdog);
        assert_eq!(A150, 0x2096);
        assert_eq!(A258, 0x2102);
    }

    #[test]
    fn e089_e131_event52_cause_codes() {
        assert_eq!(event52::EVENT, 52);
        assert_eq!(event52_cause(OpLoss::PdoTimeout), 6);
        assert_eq!(event52_cause(OpLoss::Sync), 7);
        assert_eq!(event52::WRONG_FIRMWARE, 15);
        let e = crate::emcy::for_event(event52::EVENT, event52::SYNC, 0).to_bytes();
        assert_eq!(&e[..5], &[0x00, 0x75, 0x10, 52, 7]);
    }
}
