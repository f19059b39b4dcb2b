//! What the slave stack asks of the application beyond its object
//! dictionary: the few settings the stack acts on itself (the process-data
//! cycle without a master's one, the RxPDO monitoring in Op, the check of a
//! DC configuration at P→S). A product maps its own parameters onto them;
//! the stack knows no manufacturer object.

use crate::coe::Dictionary;
use esc::AlStatusCode;

/// How a missing RxPDO is monitored in Op (spec §13.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PdoTimeout {
    /// No monitoring.
    #[default]
    Off,
    /// No new RxPDO for longer than this many ms (1 … 65531) is a timeout.
    Ms(u16),
    /// This many consecutive lost frames are tolerated (a gap of
    /// `lost + 1` process-data cycles passes, plus half a cycle for jitter).
    LostFrames(u8),
    /// The ESC's SyncManager watchdog decides (the master's setting).
    EscWatchdog,
}

/// A DC configuration the master asks for at P→S.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DcRequest {
    /// SYNC0 cycle (0x09A0), ns.
    pub sync0_ns: u32,
    /// `1C32h:02`, ns (0 = not set).
    pub sm2_cycle_ns: u32,
    /// `1C33h:02`, ns (0 = not set).
    pub sm3_cycle_ns: u32,
}

/// The application behind [`crate::Slave`]: its dictionary and the
/// settings the stack follows. The defaults describe an application that
/// runs every 1 ms, has no RxPDO monitoring and accepts any SYNC0 cycle.
pub trait Application: Dictionary {
    /// The application's own cycle, ns: the process-data cycle in free run
    /// and SM-sync when the master set none (`1C32h:02` = 0).
    fn cycle_ns(&mut self) -> u32 {
        1_000_000
    }

    /// The RxPDO monitoring in Op (read at P→S and at each S→O request).
    fn pdo_timeout(&mut self) -> PdoTimeout {
        PdoTimeout::Off
    }

    /// Whether the application can run on the DC configuration `dc`: the
    /// number of application cycles per SYNC0 cycle, or the AL status code
    /// to refuse P→S with.
    fn check_dc(&mut self, dc: &DcRequest) -> Result<u32, AlStatusCode> {
        let _ = dc;
        Ok(1)
    }
}
