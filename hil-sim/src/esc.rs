//! One simulated EtherCAT slave controller (ESC), register level.
//!
//! The ESC holds a fixed memory image: registers 0x0000–0x0FFF and up to
//! 8 KiB process RAM 0x1000–0x2FFF. Addresses above the RAM are not present:
//! reads return 0, writes are ignored, the datagram still counts.
//!
//! The master reaches it through [`Esc::process_datagram`] (normally via
//! [`crate::frame::process_frame`]), the slave stack through [`::esc::Pdi`]
//! (implemented by [`Esc`] and by the [`EscPdi`] handle). Both sides see the
//! ESC's side effects: SyncManager mailbox and three-buffer handshakes, AL
//! control/status ownership, AL events, the SII EEPROM interface, watchdogs
//! and the distributed-clock receive-time latch.
//!
//! Time is an argument (`now`, [`Nanos`]); the ESC keeps the latest time it was
//! given and uses it for PDI accesses. `no_std`, heap-free, never panics on
//! frame input.
//!
//! # Event rules (AL event request 0x0220)
//!
//! - bit 0 `AL_CONTROL`: set by an ECAT write touching 0x0120/0x0121, cleared
//!   by a PDI read touching 0x0120/0x0121.
//! - bit 4 `SM_ACTIVATION`: set by any ECAT write of an SM activate byte
//!   (0x0806 + 8n), cleared by a PDI read touching any SM activate byte.
//! - bit 6 `WATCHDOG_PD`: set when the process-data watchdog expires, cleared
//!   by a PDI read touching 0x0440.
//! - bit 8+n `sm(n)` (only if the SM's control bit 5 "PDI IRQ" is set): set
//!   when ECAT completes a buffer (writes the last byte of a MasterWrite SM or
//!   reads the last byte of a MasterRead SM); cleared by any PDI access to the
//!   buffer that touches its first or its last byte.
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]
#![deny(missing_docs)]

mod access;
mod dc;
mod eeprom;
mod pdi;
mod sm;

pub use dc::{LineTiming, SyncPulses, MAX_CORRECTION_PPT, MAX_DRIFT_PPB};

use ::esc::{
    regs::{self, al_event},
    Fmmu, Pdi, SyncManager,
};
use core::convert::Infallible;
use nanos::Nanos;

use crate::frame::{Command, Datagram};
use access::{dl, Op, Side};
use dc::DcState;
pub use pdi::EscPdi;
use sm::SmState;

/// Size of the memory image: registers 0x0000–0x0FFF plus 8 KiB process RAM.
pub const MEM_SIZE: usize = 0x3000;
/// First address of the process RAM.
pub const RAM_START: u32 = regs::PROCESS_RAM as u32;
/// Largest SII image in bytes (2048 words); shorter images are padded with 0xFF.
pub const SII_MAX_BYTES: usize = 4096;
/// Most SyncManagers / FMMUs the register map has room for.
pub const MAX_SM: usize = 16;
/// Most FMMUs the register map has room for.
pub const MAX_FMMU: usize = 16;
/// Features register (0x0008) bits added when [`EscConfig::dc_supported`] is set:
/// bit 2 distributed clocks, bit 3 64-bit DC.
pub const FEATURES_DC: u16 = 0x000C;
/// Default watchdog divider (0x0400): 2498 + 2 ticks of 40 ns = 100 µs.
pub const DEFAULT_WATCHDOG_DIVIDER: u16 = 2498;
/// Default watchdog times (0x0410, 0x0420): 1000 × 100 µs = 100 ms.
pub const DEFAULT_WATCHDOG_TIME: u16 = 1000;

/// Static properties of the simulated ESC (registers 0x0000–0x0008 and timing).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EscConfig {
    /// ESC type (0x0000).
    pub esc_type: u8,
    /// Revision (0x0001).
    pub revision: u8,
    /// Build (0x0002).
    pub build: u16,
    /// Number of FMMUs (0x0004), at most [`MAX_FMMU`].
    pub fmmu_count: u8,
    /// Number of SyncManagers (0x0005), at most [`MAX_SM`].
    pub sm_count: u8,
    /// Process RAM in KiB (0x0006), at most 8 are simulated.
    pub ram_kib: u8,
    /// Port descriptor (0x0007), 2 bits per port (0b11 = MII).
    pub port_descriptor: u8,
    /// Features (0x0008); [`FEATURES_DC`] is added when `dc_supported`.
    pub features: u16,
    /// Distributed clocks present: receive-time latch and system time work.
    pub dc_supported: bool,
    /// Simulated duration of an SII EEPROM command; 0 completes immediately
    /// (BUSY is then never seen).
    pub sii_busy: Nanos,
    /// Drift of the ESC's oscillator, ppb (+: the local clock runs fast),
    /// clamped to ±[`MAX_DRIFT_PPB`].
    pub clock_drift_ppb: i32,
    /// Local time at simulation time 0, ns.
    pub clock_offset_ns: u64,
}

impl EscConfig {
    /// ET1100-like defaults: 8 FMMUs, 8 SMs, 8 KiB RAM, ports 0 and 1 MII, DC.
    pub const DEFAULT: Self = Self {
        esc_type: 0x11,
        revision: 0x00,
        build: 0x0002,
        fmmu_count: 8,
        sm_count: 8,
        ram_kib: 8,
        port_descriptor: 0x0F,
        features: 0,
        dc_supported: true,
        sii_busy: Nanos::ZERO,
        clock_drift_ppb: 0,
        clock_offset_ns: 0,
    };
}

impl Default for EscConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// A pending SII EEPROM command (BUSY until `done_at`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct SiiPending {
    command: u16,
    done_at: Nanos,
}

/// One simulated ESC.
#[derive(Clone)]
pub struct Esc {
    config: EscConfig,
    mem: [u8; MEM_SIZE],
    sii: [u8; SII_MAX_BYTES],
    sm: [SmState; MAX_SM],
    now: Nanos,
    sii_pending: Option<SiiPending>,
    /// Last retrigger of the process-data watchdog (None: not running / expired).
    pd_wd_trigger: Option<Nanos>,
    /// Last retrigger of the PDI watchdog (None: not running / expired).
    pdi_wd_trigger: Option<Nanos>,
    /// Distributed clocks: local clock, drift-control loop, cyclic unit.
    dc: DcState,
    /// Time of the last frame that passed the ESC (port 0 receives every
    /// frame; port 1 forwards it when it has a link).
    last_frame: Option<Nanos>,
}

/// How long a port counts as active after a frame (the LA_EC LED
/// flickers): two flicker periods (ETG.1300), our choice.
pub const ACTIVITY_WINDOW: Nanos = Nanos::from_ms(100);

impl core::fmt::Debug for Esc {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Esc")
            .field("config", &self.config)
            .field("station_address", &self.station_address())
            .field("al_status", &self.al_status())
            .field("now", &self.now)
            .finish_non_exhaustive()
    }
}

impl Esc {
    /// Powers on an ESC with `config` and the SII EEPROM image `sii` (at most
    /// 4 KiB are kept, shorter images are padded with 0xFF), loading the ESC
    /// configuration area as a real ESC does.
    pub fn new(config: EscConfig, sii: &[u8]) -> Self {
        let config = EscConfig {
            fmmu_count: config.fmmu_count.min(MAX_FMMU as u8),
            sm_count: config.sm_count.min(MAX_SM as u8),
            ..config
        };
        let mut esc = Self {
            config,
            mem: [0; MEM_SIZE],
            sii: [0xFF; SII_MAX_BYTES],
            sm: [SmState::default(); MAX_SM],
            last_frame: None,
            now: Nanos::ZERO,
            sii_pending: None,
            pd_wd_trigger: None,
            pdi_wd_trigger: None,
            dc: DcState::new(config.clock_drift_ppb, config.clock_offset_ns),
        };
        for (dst, src) in esc.sii.iter_mut().zip(sii) {
            *dst = *src;
        }
        let c = config;
        esc.set_u8(regs::TYPE, c.esc_type);
        esc.set_u8(regs::REVISION, c.revision);
        esc.set_u16(regs::BUILD, c.build);
        esc.set_u8(regs::FMMU_COUNT, c.fmmu_count);
        esc.set_u8(regs::SM_COUNT, c.sm_count);
        esc.set_u8(regs::RAM_SIZE, c.ram_kib);
        esc.set_u8(regs::PORT_DESCRIPTOR, c.port_descriptor);
        let features = c.features | if c.dc_supported { FEATURES_DC } else { 0 };
        esc.set_u16(regs::FEATURES, features);
        esc.set_u32(regs::DL_CONTROL, 0x0000_0001);
        // DL status: port 0 link + communication, ports 1..3 closed (loop).
        esc.set_u16(
            regs::DL_STATUS,
            dl::LINK0 | dl::COMM0 | dl::LOOP1 | dl::LOOP2 | dl::LOOP3,
        );
        esc.set_u16(regs::AL_CONTROL, 0x0001);
        esc.set_u16(regs::AL_STATUS, 0x0001);
        esc.set_u32(regs::AL_EVENT_MASK, 0xFFFF_FFFF);
        esc.set_u16(regs::WATCHDOG_DIVIDER, DEFAULT_WATCHDOG_DIVIDER);
        esc.set_u16(regs::WATCHDOG_TIME_PDI, DEFAULT_WATCHDOG_TIME);
        esc.set_u16(regs::WATCHDOG_TIME_PD, DEFAULT_WATCHDOG_TIME);
        // ET1100 defaults of the drift-control loop
        esc.set_u16(regs::dc::SPEED_COUNTER_START, 0x1000);
        esc.set_u8(regs::dc::FILTER_DEPTH_TIME, 0x04);
        esc.set_u8(regs::dc::FILTER_DEPTH_SPEED, 0x0C);
        esc.load_sii_config();
        esc
    }

    // ----------------------------------------------------------------- accessors

    /// The configuration the ESC was built with (counts clamped).
    pub fn config(&self) -> &EscConfig {
        &self.config
    }

    /// The SII EEPROM image (always 4 KiB; master writes change it).
    pub fn sii(&self) -> &[u8] {
        &self.sii
    }

    /// The SII image, to change (a test's damaged EEPROM); the ESC takes it
    /// over at the next [`reload_sii`](Self::reload_sii).
    pub fn sii_mut(&mut self) -> &mut [u8] {
        &mut self.sii
    }

    /// Loads the configuration area from the SII image as at power on (the
    /// reload command): alias, PDI and ESC configuration, the checksum check.
    pub fn reload_sii(&mut self) {
        self.load_sii_config();
    }

    /// AL status (0x0130) as written by the PDI.
    pub fn al_status(&self) -> u16 {
        self.get_u16(regs::AL_STATUS)
    }

    /// AL status code (0x0134).
    pub fn al_status_code(&self) -> u16 {
        self.get_u16(regs::AL_STATUS_CODE)
    }

    /// AL control (0x0120) as last written by the master.
    pub fn al_control(&self) -> u16 {
        self.get_u16(regs::AL_CONTROL)
    }

    /// Raw AL event request (0x0220), unmasked.
    pub fn al_event_request(&self) -> u32 {
        self.get_u32(regs::AL_EVENT_REQUEST)
    }

    /// Configured station address (0x0010).
    pub fn station_address(&self) -> u16 {
        self.get_u16(regs::STATION_ADDRESS)
    }

    /// Configured station alias (0x0012).
    pub fn station_alias(&self) -> u16 {
        self.get_u16(regs::STATION_ALIAS)
    }

    /// The latest time the ESC has seen (from datagrams or [`Esc::tick`]).
    pub fn now(&self) -> Nanos {
        self.now
    }

    /// SyncManager `n`'s register block (default for `n` out of range).
    pub fn sync_manager(&self, n: u8) -> SyncManager {
        let a = usize::from(regs::sm(n));
        self.mem
            .get(a..a + SyncManager::LEN)
            .and_then(|b| SyncManager::parse(b).ok())
            .unwrap_or_default()
    }

    /// FMMU `n`'s register block (default for `n` out of range).
    pub fn fmmu(&self, n: u8) -> Fmmu {
        let a = usize::from(regs::fmmu(n));
        self.mem
            .get(a..a + Fmmu::LEN)
            .and_then(|b| Fmmu::parse(b).ok())
            .unwrap_or_default()
    }

    /// Reads physical memory without side effects (tests, CLI): no SyncManager
    /// buffer mapping, no event clearing. Not-present addresses read 0; the
    /// DC system time (0x0910) is computed as on a real read (at the ESC's time).
    pub fn read_reg(&self, addr: u16, buf: &mut [u8]) {
        for (i, b) in buf.iter_mut().enumerate() {
            let a = u32::from(addr) + i as u32;
            *b = self.computed(a, self.now).unwrap_or_else(|| self.raw(a));
        }
    }

    /// Writes physical memory without side effects (tests, CLI fault injection).
    /// Not-present addresses are ignored.
    pub fn write_reg(&mut self, addr: u16, data: &[u8]) {
        for (i, b) in data.iter().enumerate() {
            let a = u32::from(addr) + i as u32;
            if a < self.present_end() {
                if let Some(m) = self.mem.get_mut(a as usize) {
                    *m = *b;
                }
            }
        }
    }

    /// Sets link and loop state of `port` (0..3) in the DL status: with link the
    /// port is open and communicating, without it is closed (loop).
    pub fn set_port_link(&mut self, port: u8, link: bool) {
        if port > 3 {
            return;
        }
        let link_bit = 1u16 << (4 + port);
        let loop_bit = 1u16 << (8 + 2 * port);
        let comm_bit = 1u16 << (9 + 2 * port);
        let before = self.get_u16(regs::DL_STATUS);
        if before & link_bit != 0 && !link {
            // a lost link counts in 0x0310 + port (saturating, E-137)
            let a = regs::LOST_LINK_COUNTER + u16::from(port);
            self.set_u8(a, self.get_u8(a).saturating_add(1));
        }
        let mut s = before & !(link_bit | loop_bit | comm_bit);
        s |= if link { link_bit | comm_bit } else { loop_bit };
        self.set_u16(regs::DL_STATUS, s);
    }

    /// Counts a receive error on `port` (0..3) in its RX error counter
    /// (0x0300 + 2·port: `invalid_frame` = the invalid-frame counter, else
    /// 0x0301 + 2·port, the physical-layer RX error counter), saturating, as
    /// an ESC does for a corrupted frame (E-138 fault injection).
    pub fn inject_rx_error(&mut self, port: u8, invalid_frame: bool) {
        if port > 3 {
            return;
        }
        let a = regs::RX_ERROR_COUNTER + 2 * u16::from(port) + u16::from(!invalid_frame);
        self.set_u8(a, self.get_u8(a).saturating_add(1));
    }

    /// Whether `port` (0 or 1) carried a frame within [`ACTIVITY_WINDOW`]
    /// before `now` (what the ESC's LA_EC LED outputs show, E-134).
    pub fn port_activity(&self, port: u8, now: Nanos) -> bool {
        let link = match port {
            0 => true,
            1..=3 => self.get_u16(regs::DL_STATUS) & (1 << (4 + port)) != 0,
            _ => false,
        };
        link && self.last_frame.is_some_and(|t| now.since(t) < ACTIVITY_WINDOW)
    }

    /// A PDI handle (implements [`::esc::Pdi`]); [`Esc`] implements it too.
    pub fn pdi(&mut self) -> EscPdi<'_> {
        EscPdi { esc: self }
    }

    // ------------------------------------------------------------------- time

    /// Advances the ESC's time to `now` (never backwards): completes a
    /// pending SII command, checks the process-data and PDI watchdogs and
    /// generates the SYNC pulses that are due. [`Esc::process_datagram`] calls
    /// it too.
    pub fn tick(&mut self, now: Nanos) {
        self.now = self.now.max(now);
        let now = self.now;
        if let Some(p) = self.sii_pending {
            if now >= p.done_at {
                self.sii_pending = None;
                self.sii_execute(p.command);
            }
        }
        if let (Some(t0), Some(period)) = (self.pd_wd_trigger, self.wd_period(regs::WATCHDOG_TIME_PD)) {
            if now >= t0.saturating_add(period) {
                self.pd_wd_trigger = None;
                let st = self.get_u16(regs::WATCHDOG_STATUS_PD) & !1;
                self.set_u16(regs::WATCHDOG_STATUS_PD, st);
                let c = self.get_u8(regs::WATCHDOG_COUNTER_PD).saturating_add(1);
                self.set_u8(regs::WATCHDOG_COUNTER_PD, c);
                self.set_al_event(al_event::WATCHDOG_PD);
            }
        }
        if let (Some(t0), Some(period)) = (self.pdi_wd_trigger, self.wd_period(regs::WATCHDOG_TIME_PDI)) {
            if now >= t0.saturating_add(period) {
                self.pdi_wd_trigger = None;
                let s = self.get_u16(regs::DL_STATUS) & !dl::PDI_WATCHDOG;
                self.set_u16(regs::DL_STATUS, s);
                let c = self.get_u8(regs::WATCHDOG_COUNTER_PDI).saturating_add(1);
                self.set_u8(regs::WATCHDOG_COUNTER_PDI, c);
            }
        }
        self.dc_tick(now);
    }

    /// Watchdog period for the time register at `reg`; `None` when the time is 0 (disabled).
    fn wd_period(&self, reg: u16) -> Option<Nanos> {
        let time = u64::from(self.get_u16(reg));
        if time == 0 {
            return None;
        }
        let div = u64::from(self.get_u16(regs::WATCHDOG_DIVIDER)) + 2;
        Some(Nanos::from_ns(time * div * 40))
    }

    /// Retriggers the process-data watchdog (completed ECAT write to an SM with the watchdog bit).
    fn retrigger_pd_watchdog(&mut self) {
        self.pd_wd_trigger = Some(self.now);
        let st = self.get_u16(regs::WATCHDOG_STATUS_PD) | 1;
        self.set_u16(regs::WATCHDOG_STATUS_PD, st);
    }

    /// Any PDI access retriggers the PDI watchdog.
    fn pdi_touch(&mut self) {
        self.pdi_wd_trigger = Some(self.now);
        let s = self.get_u16(regs::DL_STATUS) | dl::PDI_WATCHDOG;
        self.set_u16(regs::DL_STATUS, s);
    }

    // ------------------------------------------------------------- datagrams

    // ------------------------------------------------------------ core access

    // ------------------------------------------------------------- AL events

    fn set_al_event(&mut self, bits: u32) {
        let e = self.al_event_request() | bits;
        self.set_u32(regs::AL_EVENT_REQUEST, e);
    }

    fn clear_al_event(&mut self, bits: u32) {
        let e = self.al_event_request() & !bits;
        self.set_u32(regs::AL_EVENT_REQUEST, e);
    }

    fn set_ecat_event(&mut self, bits: u16) {
        let e = self.get_u16(regs::ECAT_EVENT_REQUEST) | bits;
        self.set_u16(regs::ECAT_EVENT_REQUEST, e);
    }

    fn clear_ecat_event(&mut self, bits: u16) {
        let e = self.get_u16(regs::ECAT_EVENT_REQUEST) & !bits;
        self.set_u16(regs::ECAT_EVENT_REQUEST, e);
    }

    // ---------------------------------------------------------------- memory

    fn get_u8(&self, a: u16) -> u8 {
        self.mem.get(usize::from(a)).copied().unwrap_or(0)
    }

    fn set_u8(&mut self, a: u16, v: u8) {
        if let Some(m) = self.mem.get_mut(usize::from(a)) {
            *m = v;
        }
    }

    fn get_u16(&self, a: u16) -> u16 {
        u16::from_le_bytes([self.get_u8(a), self.get_u8(a.wrapping_add(1))])
    }

    fn set_u16(&mut self, a: u16, v: u16) {
        self.set_bytes(a, &v.to_le_bytes());
    }

    fn get_u32(&self, a: u16) -> u32 {
        let mut b = [0u8; 4];
        self.get_bytes(a, &mut b);
        u32::from_le_bytes(b)
    }

    fn set_u32(&mut self, a: u16, v: u32) {
        self.set_bytes(a, &v.to_le_bytes());
    }

    fn get_u64(&self, a: u16) -> u64 {
        let mut b = [0u8; 8];
        self.get_bytes(a, &mut b);
        u64::from_le_bytes(b)
    }

    fn set_u64(&mut self, a: u16, v: u64) {
        self.set_bytes(a, &v.to_le_bytes());
    }

    fn get_bytes(&self, a: u16, buf: &mut [u8]) {
        let a = usize::from(a);
        if let Some(s) = self.mem.get(a..a + buf.len()) {
            buf.copy_from_slice(s);
        }
    }

    fn set_bytes(&mut self, a: u16, data: &[u8]) {
        let a = usize::from(a);
        if let Some(s) = self.mem.get_mut(a..a + data.len()) {
            s.copy_from_slice(data);
        }
    }
}

#[cfg(test)]
mod tests;
