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
//! Time is an argument (`now_ns`); the ESC keeps the latest time it was
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

mod dc;
mod eeprom;
mod sm;

pub use dc::{LineTiming, SyncPulses, MAX_CORRECTION_PPT, MAX_DRIFT_PPB};

use ::esc::{
    regs::{self, al_event},
    Fmmu, Pdi, SyncManager,
};
use core::convert::Infallible;

use crate::frame::{Command, Datagram};
use dc::DcState;
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
    pub sii_busy_ns: u64,
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
        sii_busy_ns: 0,
        clock_drift_ppb: 0,
        clock_offset_ns: 0,
    };
}

impl Default for EscConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Who accesses the memory.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Side {
    /// The master, through datagrams.
    Ecat,
    /// The slave's application processor.
    Pdi,
}

/// What an access does with each byte.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Op {
    /// Memory → data.
    Read,
    /// Memory OR-ed into data (broadcast read).
    ReadOr,
    /// Data → memory.
    Write,
    /// Old memory → data, incoming data → memory.
    ReadWrite,
    /// Old memory OR-ed into data, incoming data → memory.
    ReadOrWrite,
}

impl Op {
    fn reads(self) -> bool {
        !matches!(self, Op::Write)
    }
    fn writes(self) -> bool {
        matches!(self, Op::Write | Op::ReadWrite | Op::ReadOrWrite)
    }
    fn ors(self) -> bool {
        matches!(self, Op::ReadOr | Op::ReadOrWrite)
    }
}

/// Result of one access: whether the read and the write part took place
/// (a SyncManager may refuse either; the WKC then does not count it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
struct Outcome {
    read: bool,
    written: bool,
}

/// How a command counts towards the working counter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Read,
    Write,
    ReadWrite,
}

impl Kind {
    fn wkc(self, o: Outcome) -> u16 {
        match self {
            Kind::Read => u16::from(o.read),
            Kind::Write => u16::from(o.written),
            Kind::ReadWrite => u16::from(o.read) + 2 * u16::from(o.written),
        }
    }
    fn op(self) -> Op {
        match self {
            Kind::Read => Op::Read,
            Kind::Write => Op::Write,
            Kind::ReadWrite => Op::ReadWrite,
        }
    }
}

/// A pending SII EEPROM command (BUSY until `done_at`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct SiiPending {
    command: u16,
    done_at: u64,
}

/// One simulated ESC.
#[derive(Clone)]
pub struct Esc {
    config: EscConfig,
    mem: [u8; MEM_SIZE],
    sii: [u8; SII_MAX_BYTES],
    sm: [SmState; MAX_SM],
    now_ns: u64,
    sii_pending: Option<SiiPending>,
    /// Last retrigger of the process-data watchdog (None: not running / expired).
    pd_wd_trigger: Option<u64>,
    /// Last retrigger of the PDI watchdog (None: not running / expired).
    pdi_wd_trigger: Option<u64>,
    /// Distributed clocks: local clock, drift-control loop, cyclic unit.
    dc: DcState,
    /// Time of the last frame that passed the ESC (port 0 receives every
    /// frame; port 1 forwards it when it has a link).
    last_frame_ns: Option<u64>,
}

/// How long a port counts as active after a frame (the LA_EC LED
/// flickers), ns: two flicker periods (ETG.1300), our choice.
pub const ACTIVITY_WINDOW_NS: u64 = 100_000_000;

impl core::fmt::Debug for Esc {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Esc")
            .field("config", &self.config)
            .field("station_address", &self.station_address())
            .field("al_status", &self.al_status())
            .field("now_ns", &self.now_ns)
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
            last_frame_ns: None,
            now_ns: 0,
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
    pub fn now_ns(&self) -> u64 {
        self.now_ns
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
            *b = self.computed(a, self.now_ns).unwrap_or_else(|| self.raw(a));
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

    /// Whether `port` (0 or 1) carried a frame within [`ACTIVITY_WINDOW_NS`]
    /// before `now_ns` (what the ESC's LA_EC LED outputs show, E-134).
    pub fn port_activity(&self, port: u8, now_ns: u64) -> bool {
        let link = match port {
            0 => true,
            1..=3 => self.get_u16(regs::DL_STATUS) & (1 << (4 + port)) != 0,
            _ => false,
        };
        link && self
            .last_frame_ns
            .is_some_and(|t| now_ns.saturating_sub(t) < ACTIVITY_WINDOW_NS)
    }

    /// A PDI handle (implements [`::esc::Pdi`]); [`Esc`] implements it too.
    pub fn pdi(&mut self) -> EscPdi<'_> {
        EscPdi { esc: self }
    }

    // ------------------------------------------------------------------- time

    /// Advances the ESC's time to `now_ns` (never backwards): completes a
    /// pending SII command, checks the process-data and PDI watchdogs and
    /// generates the SYNC pulses that are due. [`Esc::process_datagram`] calls
    /// it too.
    pub fn tick(&mut self, now_ns: u64) {
        self.now_ns = self.now_ns.max(now_ns);
        let now = self.now_ns;
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

    /// Watchdog period in ns for the time register at `reg`; `None` when the time is 0 (disabled).
    fn wd_period(&self, reg: u16) -> Option<u64> {
        let time = u64::from(self.get_u16(reg));
        if time == 0 {
            return None;
        }
        let div = u64::from(self.get_u16(regs::WATCHDOG_DIVIDER)) + 2;
        Some(time * div * 40)
    }

    /// Retriggers the process-data watchdog (completed ECAT write to an SM with the watchdog bit).
    fn retrigger_pd_watchdog(&mut self) {
        self.pd_wd_trigger = Some(self.now_ns);
        let st = self.get_u16(regs::WATCHDOG_STATUS_PD) | 1;
        self.set_u16(regs::WATCHDOG_STATUS_PD, st);
    }

    /// Any PDI access retriggers the PDI watchdog.
    fn pdi_touch(&mut self) {
        self.pdi_wd_trigger = Some(self.now_ns);
        let s = self.get_u16(regs::DL_STATUS) | dl::PDI_WATCHDOG;
        self.set_u16(regs::DL_STATUS, s);
    }

    // ------------------------------------------------------------- datagrams

    /// Processes one datagram as it passes this ESC: addressing, memory access
    /// with all side effects, working counter, ADP auto-increment. `now_ns` is
    /// the time the frame entered the line; DC registers use the frame's
    /// arrival at this ESC (see [`Esc::set_line_timing`]).
    pub fn process_datagram(&mut self, dg: &mut Datagram<'_>, now_ns: u64) {
        self.tick(now_ns);
        self.last_frame_ns = Some(self.now_ns);
        self.dc.ecat_time = self.now_ns.saturating_add(self.dc.line.arrival_ns);
        let adp = dg.adp();
        let ado = u32::from(dg.ado());
        let cmd = dg.command();
        let wkc = match cmd {
            Command::Nop | Command::Unknown(_) => 0,
            Command::Aprd | Command::Apwr | Command::Aprw => {
                dg.set_adp(adp.wrapping_add(1));
                if adp == 0 {
                    let kind = physical_kind(cmd);
                    kind.wkc(self.access(Side::Ecat, ado, dg.data_mut(), kind.op()))
                } else {
                    0
                }
            }
            Command::Fprd | Command::Fpwr | Command::Fprw => {
                if self.configured_match(adp) {
                    let kind = physical_kind(cmd);
                    kind.wkc(self.access(Side::Ecat, ado, dg.data_mut(), kind.op()))
                } else {
                    0
                }
            }
            Command::Brd => {
                dg.set_adp(adp.wrapping_add(1));
                Kind::Read.wkc(self.access(Side::Ecat, ado, dg.data_mut(), Op::ReadOr))
            }
            Command::Bwr => {
                dg.set_adp(adp.wrapping_add(1));
                Kind::Write.wkc(self.access(Side::Ecat, ado, dg.data_mut(), Op::Write))
            }
            Command::Brw => {
                dg.set_adp(adp.wrapping_add(1));
                Kind::ReadWrite.wkc(self.access(Side::Ecat, ado, dg.data_mut(), Op::ReadOrWrite))
            }
            Command::Lrd | Command::Lwr | Command::Lrw => {
                let kind = match cmd {
                    Command::Lrd => Kind::Read,
                    Command::Lwr => Kind::Write,
                    _ => Kind::ReadWrite,
                };
                let laddr = dg.logical_address();
                kind.wkc(self.logical(kind, laddr, dg.data_mut()))
            }
            Command::Armw => {
                dg.set_adp(adp.wrapping_add(1));
                self.read_multiple_write(adp == 0, ado, dg.data_mut())
            }
            Command::Frmw => {
                let me = self.configured_match(adp);
                self.read_multiple_write(me, ado, dg.data_mut())
            }
        };
        if wkc != 0 {
            dg.add_wkc(wkc);
        }
    }

    /// ARMW/FRMW: the addressed slave reads, every other slave writes; +1 either way.
    /// A write that includes 0x0910 (the system time) feeds the drift-control loop.
    fn read_multiple_write(&mut self, addressed: bool, ado: u32, data: &mut [u8]) -> u16 {
        if addressed {
            Kind::Read.wkc(self.access(Side::Ecat, ado, data, Op::Read))
        } else {
            let wkc = Kind::Write.wkc(self.access(Side::Ecat, ado, data, Op::Write));
            let st = u32::from(regs::dc::SYSTEM_TIME);
            if let Some(off) = st.checked_sub(ado) {
                let off = off as usize;
                if let Some(w) = data.get(off..data.len().min(off.saturating_add(8))) {
                    self.dc_system_time_written(w);
                }
            }
            wkc
        }
    }

    /// Configured-address match: station address, or the alias when DL control bit 24 is set.
    fn configured_match(&self, adp: u16) -> bool {
        adp == self.station_address()
            || (self.get_u32(regs::DL_CONTROL) & (1 << 24) != 0 && adp == self.station_alias())
    }

    /// Logical access through the enabled FMMUs. Write-only mappings go first,
    /// then read-write, then read-only ones, so an LRW returns inputs while the
    /// outputs written are the master's.
    fn logical(&mut self, kind: Kind, laddr: u32, data: &mut [u8]) -> Outcome {
        let mut out = Outcome::default();
        let d_lo = u64::from(laddr);
        let d_hi = d_lo + data.len() as u64;
        for pass in [Op::Write, Op::ReadWrite, Op::Read] {
            for n in 0..self.config.fmmu_count {
                let f = self.fmmu(n);
                if !f.enabled() {
                    continue;
                }
                let r = kind != Kind::Write && f.kind & Fmmu::READ != 0;
                let w = kind != Kind::Read && f.kind & Fmmu::WRITE != 0;
                let op = match (r, w) {
                    (true, true) => Op::ReadWrite,
                    (true, false) => Op::Read,
                    (false, true) => Op::Write,
                    (false, false) => continue,
                };
                if op != pass {
                    continue;
                }
                let f_lo = u64::from(f.logical_start);
                let f_hi = f_lo + u64::from(f.length);
                let lo = d_lo.max(f_lo);
                let hi = d_hi.min(f_hi);
                if lo >= hi {
                    continue;
                }
                let Some(phys) = u32::try_from(lo).ok().and_then(|l| f.map(l)) else {
                    continue;
                };
                let Some(sub) = data.get_mut((lo - d_lo) as usize..(hi - d_lo) as usize) else {
                    continue;
                };
                let o = self.access(Side::Ecat, u32::from(phys), sub, op);
                out.read |= o.read;
                out.written |= o.written;
            }
        }
        out
    }

    // ------------------------------------------------------------ core access

    /// End of the present memory (exclusive).
    fn present_end(&self) -> u32 {
        RAM_START + u32::from(self.config.ram_kib.min(8)) * 1024
    }

    /// Raw memory byte; 0 when not present.
    fn raw(&self, a: u32) -> u8 {
        if a < self.present_end() {
            self.mem.get(a as usize).copied().unwrap_or(0)
        } else {
            0
        }
    }

    /// Bytes computed on read at time `t`: the DC system time (local time + offset).
    fn computed(&self, a: u32, t: u64) -> Option<u8> {
        self.dc_computed(a, t)
    }

    /// One access from `side` at `addr` with all ESC side effects.
    fn access(&mut self, side: Side, addr: u32, data: &mut [u8], op: Op) -> Outcome {
        if side == Side::Pdi {
            self.pdi_touch();
        }
        let len = data.len() as u32;
        let end = addr.saturating_add(len);
        // Old values of the bytes with write side effects.
        let old_activate = self.sm_bytes(6);
        let old_pdi_control = self.sm_bytes(7);

        // SyncManager pre-phase: permission, buffer selection, opening.
        let mut plans = [sm::Plan::default(); MAX_SM];
        let mut out = Outcome {
            read: op.reads(),
            written: op.writes(),
        };
        for n in 0..usize::from(self.config.sm_count) {
            let regs_n = self.sync_manager(n as u8);
            let Some(plan) = plans.get_mut(n) else { break };
            *plan = sm::Plan::new(&regs_n, side);
            if !plan.active || !plan.overlaps(addr, end) {
                continue;
            }
            plan.involved = true;
            let Some(state) = self.sm.get_mut(n) else { break };
            let full = regs_n.status & ::esc::sm::status::MAILBOX_FULL != 0;
            plan.decide(state, op, full, addr, end);
            if op.reads() && !plan.read_ok {
                out.read = false;
            }
            if op.writes() && !plan.write_ok {
                out.written = false;
            }
        }
        for n in 0..usize::from(self.config.sm_count) {
            let Some(plan) = plans.get(n).copied() else { break };
            if plan.involved && (plan.read_ok || plan.write_ok) {
                self.sm_open(n as u8, &plan);
            }
        }

        // Data phase, byte by byte.
        let present = self.present_end();
        let t_read = match side {
            Side::Ecat => self.dc.ecat_time,
            Side::Pdi => self.now_ns,
        };
        for (i, byte) in data.iter_mut().enumerate() {
            let a = addr + i as u32;
            let incoming = *byte;
            let (phys, rd, wr) = match sm::classify(&plans, a) {
                sm::Where::Buffer(p) => {
                    if !(p.read_ok || p.write_ok) {
                        if side == Side::Pdi && op.reads() {
                            *byte = 0;
                        }
                        continue;
                    }
                    (a + u32::from(p.buffer) * p.len, p.read_ok, p.write_ok)
                }
                sm::Where::Hidden => (a, false, false),
                sm::Where::Plain => {
                    // the EEPROM address and data registers are locked while busy
                    let sii_locked = self.sii_pending.is_some() && (0x0504..=0x050F).contains(&a);
                    (a, op.reads(), op.writes() && writable(side, a) && !sii_locked)
                }
            };
            let value = if a >= present || !rd {
                0
            } else {
                self.computed(a, t_read).unwrap_or_else(|| self.raw(phys))
            };
            if op.reads() {
                if op.ors() {
                    *byte |= value;
                } else {
                    *byte = value;
                }
            }
            if wr && phys < present {
                if let Some(m) = self.mem.get_mut(phys as usize) {
                    *m = incoming;
                }
            }
        }

        // SyncManager post-phase: completion on the last byte.
        for n in 0..usize::from(self.config.sm_count) {
            let Some(plan) = plans.get(n).copied() else { break };
            if plan.involved && plan.touches_last {
                if plan.read_ok {
                    self.sm_read_done(n as u8, &plan);
                }
                if plan.write_ok {
                    self.sm_write_done(n as u8, &plan);
                }
            }
        }

        // Register side effects.
        let touches = |lo: u16, hi: u16| addr <= u32::from(hi) && u32::from(lo) < end;
        match side {
            Side::Ecat if op.writes() => {
                if touches(regs::AL_CONTROL, regs::AL_CONTROL + 1) {
                    self.set_al_event(al_event::AL_CONTROL);
                }
                for n in 0..self.config.sm_count {
                    let a = regs::sm(n) + 6;
                    if touches(a, a) {
                        let old = old_activate.get(usize::from(n)).copied().unwrap_or(0);
                        self.sm_activate_written(n, old);
                    }
                }
                if touches(regs::SII_CONTROL + 1, regs::SII_CONTROL + 1) {
                    let lo = if touches(regs::SII_CONTROL, regs::SII_CONTROL) {
                        data.get((u32::from(regs::SII_CONTROL) - addr) as usize)
                            .copied()
                            .unwrap_or(0)
                    } else {
                        0
                    };
                    let hi = data
                        .get((u32::from(regs::SII_CONTROL) + 1 - addr) as usize)
                        .copied()
                        .unwrap_or(0);
                    self.sii_command_written(u16::from_le_bytes([lo, hi]));
                }
                if touches(regs::dc::RECEIVE_TIME_PORT0, regs::dc::RECEIVE_TIME_PORT0 + 3) {
                    self.dc_latch_receive_times();
                }
                if touches(regs::dc::SPEED_COUNTER_START, regs::dc::SPEED_COUNTER_START + 1) {
                    self.dc_loop_reset();
                }
                if touches(regs::dc::ACTIVATION, regs::dc::ACTIVATION) {
                    self.dc_activation_written();
                }
                for reg in [regs::WATCHDOG_COUNTER_PD, regs::WATCHDOG_COUNTER_PDI] {
                    if touches(reg, reg) {
                        self.set_u8(reg, 0);
                    }
                }
            }
            Side::Pdi => {
                if op.reads() {
                    if touches(regs::AL_CONTROL, regs::AL_CONTROL + 1) {
                        self.clear_al_event(al_event::AL_CONTROL);
                    }
                    if (0..self.config.sm_count).any(|n| touches(regs::sm(n) + 6, regs::sm(n) + 6)) {
                        self.clear_al_event(al_event::SM_ACTIVATION);
                    }
                    if touches(regs::WATCHDOG_STATUS_PD, regs::WATCHDOG_STATUS_PD + 1) {
                        self.clear_al_event(al_event::WATCHDOG_PD);
                    }
                    self.dc_pdi_read(|r| touches(r, r));
                }
                if op.writes() {
                    for n in 0..self.config.sm_count {
                        let a = regs::sm(n) + 7;
                        if touches(a, a) {
                            let old = old_pdi_control.get(usize::from(n)).copied().unwrap_or(0);
                            self.sm_pdi_control_written(n, old);
                        }
                    }
                    if touches(regs::AL_STATUS, regs::AL_STATUS + 1) {
                        // ECAT event request bit 3: AL status changed.
                        let e = self.get_u16(regs::ECAT_EVENT_REQUEST) | 1 << 3;
                        self.set_u16(regs::ECAT_EVENT_REQUEST, e);
                    }
                }
            }
            Side::Ecat => {}
        }
        out
    }

    /// Byte `off` of every SM register block (used to see what a write changed).
    fn sm_bytes(&self, off: u16) -> [u8; MAX_SM] {
        let mut b = [0u8; MAX_SM];
        for (n, v) in b.iter_mut().enumerate() {
            *v = self.get_u8(regs::sm(n as u8) + off);
        }
        b
    }

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

/// How a physical command counts.
fn physical_kind(cmd: Command) -> Kind {
    match cmd {
        Command::Aprd | Command::Fprd => Kind::Read,
        Command::Apwr | Command::Fpwr => Kind::Write,
        _ => Kind::ReadWrite,
    }
}

/// DL status bits, named as the simulated ESC uses them.
mod dl {
    use ::esc::regs::dl_status;
    pub const PDI_OPERATIONAL: u16 = dl_status::PDI_OPERATIONAL;
    pub const PDI_WATCHDOG: u16 = dl_status::PDI_WATCHDOG;
    pub const LINK0: u16 = dl_status::link(0);
    pub const LOOP1: u16 = dl_status::loop_closed(1);
    pub const COMM0: u16 = dl_status::communication(0);
    pub const LOOP2: u16 = dl_status::loop_closed(2);
    pub const LOOP3: u16 = dl_status::loop_closed(3);
}

/// Whether a plain (non-SyncManager) byte at `a` takes writes from `side`.
fn writable(side: Side, a: u32) -> bool {
    let sm_lo = u32::from(regs::SM_BASE);
    let sm_hi = sm_lo + u32::from(regs::SM_LEN) * MAX_SM as u32;
    match side {
        Side::Ecat => match a {
            0x0000..=0x000F => false,
            // alias and EEPROM-loaded configuration
            0x0012..=0x0013 | 0x0140..=0x0141 | 0x0150..=0x0153 => false,
            // DL status, AL status, AL status code
            0x0110..=0x0111 | 0x0130..=0x0137 => false,
            // event requests
            0x0210..=0x0211 | 0x0220..=0x0223 => false,
            // watchdog status; counters are cleared by a write (side effect)
            0x0440..=0x0443 => false,
            // SII control/status: command execution (side effect)
            0x0502..=0x0503 => false,
            // DC receive times (latched by a write), system time, receive time PU
            0x0900..=0x091F => false,
            // DC system time difference, speed counter difference, cyclic unit status
            0x092C..=0x092F | 0x0932..=0x0933 | 0x0984 | 0x098E..=0x098F | 0x0998..=0x099F => false,
            _ if (sm_lo..sm_hi).contains(&a) => !matches!((a - sm_lo) % 8, 5 | 7),
            _ => true,
        },
        Side::Pdi => match a {
            0x0000..=0x0011 => false,
            0x0110..=0x0111 | 0x0120..=0x0121 => false,
            0x0210..=0x0211 | 0x0220..=0x0223 => false,
            0x0440..=0x0443 => false,
            0x0502..=0x0503 => false,
            0x0600..=0x06FF => false,
            0x0900..=0x091F => false,
            _ if (sm_lo..sm_hi).contains(&a) => (a - sm_lo) % 8 == 7,
            _ => true,
        },
    }
}

impl Pdi for Esc {
    type Error = Infallible;

    fn read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Infallible> {
        self.access(Side::Pdi, u32::from(addr), buf, Op::Read);
        Ok(())
    }

    fn write(&mut self, addr: u16, data: &[u8]) -> Result<(), Infallible> {
        // The core access takes a mutable buffer (it reads into it for
        // read-write operations); copy through a stack chunk so the SM
        // handshake sees the whole write at once when it fits.
        let mut chunk = [0u8; PDI_CHUNK];
        let mut off = 0usize;
        while off < data.len() {
            let n = (data.len() - off).min(PDI_CHUNK);
            let (Some(dst), Some(src)) = (chunk.get_mut(..n), data.get(off..off + n)) else {
                break;
            };
            dst.copy_from_slice(src);
            self.access(Side::Pdi, u32::from(addr) + off as u32, dst, Op::Write);
            off += n;
        }
        Ok(())
    }

    fn al_event(&mut self) -> Result<u32, Infallible> {
        self.pdi_touch();
        Ok(self.al_event_request() & self.get_u32(regs::AL_EVENT_MASK))
    }
}

/// Bytes per internal PDI write step (a write longer than this is split; the
/// SyncManager handshake still completes on the last byte).
const PDI_CHUNK: usize = 256;

/// A PDI handle on an [`Esc`], as the slave stack holds it.
#[derive(Debug)]
pub struct EscPdi<'a> {
    esc: &'a mut Esc,
}

impl Pdi for EscPdi<'_> {
    type Error = Infallible;

    fn read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Infallible> {
        self.esc.read(addr, buf)
    }

    fn write(&mut self, addr: u16, data: &[u8]) -> Result<(), Infallible> {
        self.esc.write(addr, data)
    }

    fn al_event(&mut self) -> Result<u32, Infallible> {
        Pdi::al_event(self.esc)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::frame::testutil::{phys, xfer1};
    use ::esc::{
        sii::{config_checksum, control},
        sm::{activate, pdi_control, status},
        PdiExt, SmControl, SmDirection, SmMode,
    };
    use std::vec::Vec;

    const ALIAS: u16 = 0x1234;

    /// A small SII image with a valid configuration area, alias and identity.
    fn sii_image() -> [u8; 128] {
        let mut s = [0u8; 128];
        s[..4].copy_from_slice(&[0x80, 0x0C, 0x88, 0x88]);
        s[8..10].copy_from_slice(&ALIAS.to_le_bytes());
        s[14] = config_checksum(&s[..14]);
        // words 8..11: vendor id, product code
        s[16..24].copy_from_slice(&[0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08]);
        s
    }

    fn esc() -> Esc {
        Esc::new(EscConfig::default(), &sii_image())
    }

    fn wr(e: &mut Esc, addr: u16, data: &[u8], now: u64) -> u16 {
        xfer1(e, Command::Apwr, phys(0, addr), data, now).1
    }

    fn rd(e: &mut Esc, addr: u16, len: usize, now: u64) -> (Vec<u8>, u16) {
        xfer1(e, Command::Aprd, phys(0, addr), &std::vec![0xEE; len], now)
    }

    fn reg16(e: &Esc, addr: u16) -> u16 {
        let mut b = [0u8; 2];
        e.read_reg(addr, &mut b);
        u16::from_le_bytes(b)
    }

    fn setup_sm(e: &mut Esc, n: u8, start: u16, len: u16, control: u8) {
        let sm = SyncManager {
            start,
            length: len,
            control,
            status: 0,
            activate: activate::ENABLE,
            pdi_control: 0,
        };
        assert_eq!(wr(e, regs::sm(n), &sm.to_bytes(), 0), 1);
    }

    fn sm_status(e: &Esc, n: u8) -> u8 {
        e.sync_manager(n).status
    }

    const MBX_OUT: u8 = 0x26; // mailbox, master write, PDI IRQ
    const MBX_IN: u8 = 0x22; // mailbox, master read, PDI IRQ
    const PD_OUT: u8 = 0x64; // 3-buffer, master write, PDI IRQ, watchdog
    const PD_IN: u8 = 0x20; // 3-buffer, master read, PDI IRQ

    #[test]
    fn control_constants_match_the_register_map() {
        let c = |m, d, irq, wd| SmControl::new(m, d, irq, wd).0;
        assert_eq!(MBX_OUT, c(SmMode::Mailbox, SmDirection::MasterWrite, true, false));
        assert_eq!(MBX_IN, c(SmMode::Mailbox, SmDirection::MasterRead, true, false));
        assert_eq!(PD_OUT, c(SmMode::Buffered, SmDirection::MasterWrite, true, true));
        assert_eq!(PD_IN, c(SmMode::Buffered, SmDirection::MasterRead, true, false));
    }

    #[test]
    fn power_on_loads_sii_config_and_defaults() {
        let mut e = esc();
        assert_eq!(e.station_alias(), ALIAS);
        let mut b = [0u8; 2];
        e.read_reg(regs::PDI_CONTROL, &mut b);
        assert_eq!(b, [0x80, 0x0C]);
        assert_eq!(reg16(&e, regs::PDI_CONFIG), 0x8888);
        assert_eq!(reg16(&e, regs::SII_CONTROL), control::READ_8_BYTES);
        assert_eq!(e.al_status(), 0x0001);
        assert_eq!(reg16(&e, regs::WATCHDOG_DIVIDER), 2498);
        assert_eq!(reg16(&e, regs::WATCHDOG_TIME_PD), 1000);
        assert_eq!(reg16(&e, regs::WATCHDOG_TIME_PDI), 1000);
        let dl = reg16(&e, regs::DL_STATUS);
        assert_eq!(
            dl & (dl::PDI_OPERATIONAL | dl::LINK0 | dl::COMM0 | dl::LOOP1),
            0x0611
        );
        assert_eq!(e.read_u32(regs::AL_EVENT_MASK).unwrap(), 0xFFFF_FFFF);
        let (d, wkc) = rd(&mut e, regs::TYPE, 10, 0);
        assert_eq!(wkc, 1);
        assert_eq!(d[regs::FMMU_COUNT as usize], 8);
        assert_eq!(d[regs::SM_COUNT as usize], 8);
        assert_eq!(d[regs::RAM_SIZE as usize], 8);
        assert_eq!(u16::from_le_bytes([d[8], d[9]]) & FEATURES_DC, FEATURES_DC);
        assert_eq!(e.sii().len(), SII_MAX_BYTES);
        assert_eq!(&e.sii()[..128], &sii_image()[..]);
        assert!(e.sii()[128..].iter().all(|&b| b == 0xFF), "padded with 0xFF");
    }

    #[test]
    fn sii_bad_checksum_sets_bit_11() {
        let mut s = sii_image();
        s[14] ^= 1;
        let e = Esc::new(EscConfig::default(), &s);
        assert_eq!(reg16(&e, regs::SII_CONTROL) & control::CHECKSUM_ERROR, 1 << 11);
        assert_eq!(reg16(&e, regs::DL_STATUS) & dl::PDI_OPERATIONAL, 0);
        let e = Esc::new(EscConfig::default(), &[]);
        assert_ne!(reg16(&e, regs::SII_CONTROL) & control::CHECKSUM_ERROR, 0);
    }

    /// Sends an SII command the way ethercrab does: control, then the address, in one write.
    fn sii_cmd(e: &mut Esc, ctrl: u16, word: u16, now: u64) -> u16 {
        let mut b = [0u8; 6];
        b[..2].copy_from_slice(&ctrl.to_le_bytes());
        b[2..4].copy_from_slice(&word.to_le_bytes());
        wr(e, regs::SII_CONTROL, &b, now)
    }

    #[test]
    fn sii_read_words_8_to_11() {
        let mut e = esc();
        assert_eq!(sii_cmd(&mut e, control::CMD_READ, 8, 0), 1);
        let (st, _) = rd(&mut e, regs::SII_CONTROL, 2, 0);
        let st = u16::from_le_bytes([st[0], st[1]]);
        assert_eq!(st & (control::BUSY | control::ACK_ERROR | control::CMD_MASK), 0);
        let (d, wkc) = rd(&mut e, regs::SII_DATA, 8, 0);
        assert_eq!(wkc, 1);
        assert_eq!(d, &sii_image()[16..24]);
        // the last words of the EEPROM, then past it
        sii_cmd(&mut e, control::CMD_READ, 2046, 0);
        assert_eq!(rd(&mut e, regs::SII_DATA, 8, 0).0, [0xFF; 8]);
        assert_eq!(reg16(&e, regs::SII_CONTROL) & control::ACK_ERROR, 0);
        sii_cmd(&mut e, control::CMD_READ, 2048, 0);
        assert_ne!(reg16(&e, regs::SII_CONTROL) & control::ACK_ERROR, 0);
    }

    #[test]
    fn sii_invalid_command_sets_ack_error_until_next_command() {
        let mut e = esc();
        sii_cmd(&mut e, 0x0300, 0, 0);
        assert_ne!(reg16(&e, regs::SII_CONTROL) & control::ACK_ERROR, 0);
        sii_cmd(&mut e, control::CMD_READ, 0, 0);
        assert_eq!(reg16(&e, regs::SII_CONTROL) & control::ACK_ERROR, 0);
        assert_eq!(rd(&mut e, regs::SII_DATA, 8, 0).0, &sii_image()[..8]);
    }

    #[test]
    fn sii_write_without_enable_sets_error() {
        let mut e = esc();
        wr(&mut e, regs::SII_DATA, &[0xAA, 0xBB], 0);
        sii_cmd(&mut e, control::CMD_WRITE, 8, 0);
        assert_ne!(reg16(&e, regs::SII_CONTROL) & control::WRITE_ENABLE_ERROR, 0);
        assert_eq!(&e.sii()[16..18], &[0x01, 0x02]);
    }

    #[test]
    fn e152_sii_write_with_enable_and_reload_sets_alias() {
        let mut e = esc();
        let mut img = sii_image();
        img[8..10].copy_from_slice(&0x0777u16.to_le_bytes());
        let crc = config_checksum(&img[..14]);
        for (word, value) in [(4u16, 0x0777u16), (7, u16::from(crc))] {
            wr(&mut e, regs::SII_DATA, &value.to_le_bytes(), 0);
            sii_cmd(&mut e, control::CMD_WRITE | control::WRITE_ENABLE, word, 0);
            assert_eq!(reg16(&e, regs::SII_CONTROL) & 0x7000, 0, "no error");
        }
        assert_eq!(&e.sii()[8..10], &[0x77, 0x07]);
        assert_eq!(e.station_alias(), ALIAS, "registers change only on reload");
        sii_cmd(&mut e, control::CMD_RELOAD, 0, 0);
        assert_eq!(e.station_alias(), 0x0777);
        assert_eq!(reg16(&e, regs::SII_CONTROL) & control::CHECKSUM_ERROR, 0);
        // a reload with a stale checksum reports it
        wr(&mut e, regs::SII_DATA, &0x0888u16.to_le_bytes(), 0);
        sii_cmd(&mut e, control::CMD_WRITE | control::WRITE_ENABLE, 4, 0);
        sii_cmd(&mut e, control::CMD_RELOAD, 0, 0);
        assert_ne!(reg16(&e, regs::SII_CONTROL) & control::CHECKSUM_ERROR, 0);
    }

    #[test]
    fn sii_busy_clears_with_later_time() {
        let cfg = EscConfig {
            sii_busy_ns: 20_000,
            ..EscConfig::default()
        };
        let mut e = Esc::new(cfg, &sii_image());
        sii_cmd(&mut e, control::CMD_READ, 8, 1_000);
        assert_ne!(reg16(&e, regs::SII_CONTROL) & control::BUSY, 0);
        assert_eq!(rd(&mut e, regs::SII_DATA, 8, 20_999).0, [0; 8], "not yet");
        // a command while busy is ignored
        sii_cmd(&mut e, control::CMD_READ, 0, 21_000 - 1);
        e.tick(21_000);
        assert_eq!(
            reg16(&e, regs::SII_CONTROL) & (control::BUSY | control::CMD_MASK),
            0
        );
        assert_eq!(rd(&mut e, regs::SII_DATA, 8, 21_000).0, &sii_image()[16..24]);
        // completion also happens on a datagram with a later time
        sii_cmd(&mut e, control::CMD_READ, 0, 30_000);
        let (st, _) = rd(&mut e, regs::SII_CONTROL, 2, 50_000);
        assert_eq!(u16::from_le_bytes([st[0], st[1]]) & control::BUSY, 0);
        assert_eq!(rd(&mut e, regs::SII_DATA, 8, 50_000).0, &sii_image()[..8]);
    }

    #[test]
    fn al_control_write_sets_event_and_pdi_read_clears_it() {
        let mut e = esc();
        assert_eq!(e.al_event().unwrap() & al_event::AL_CONTROL, 0);
        assert_eq!(wr(&mut e, regs::AL_CONTROL, &[0x02, 0x00], 0), 1);
        assert_eq!(e.al_control(), 2);
        assert_ne!(e.al_event().unwrap() & al_event::AL_CONTROL, 0);
        // reading the event register does not clear it
        assert_ne!(e.al_event().unwrap() & al_event::AL_CONTROL, 0);
        assert_eq!(e.read_u16(regs::AL_CONTROL).unwrap(), 2);
        assert_eq!(e.al_event().unwrap() & al_event::AL_CONTROL, 0);
        // the PDI cannot write AL control
        e.write_u16(regs::AL_CONTROL, 8).unwrap();
        assert_eq!(e.al_control(), 2);
    }

    #[test]
    fn al_event_is_masked_by_the_mask_register() {
        let mut e = esc();
        wr(&mut e, regs::AL_CONTROL, &[0x02, 0x00], 0);
        e.write_u32(regs::AL_EVENT_MASK, !al_event::AL_CONTROL).unwrap();
        assert_eq!(e.pdi().al_event().unwrap() & al_event::AL_CONTROL, 0);
        assert_ne!(e.al_event_request() & al_event::AL_CONTROL, 0);
    }

    #[test]
    fn al_status_is_written_only_by_the_pdi() {
        let mut e = esc();
        assert_eq!(wr(&mut e, regs::AL_STATUS, &[0x08, 0x00, 0, 0, 0x1B, 0x00], 0), 1);
        assert_eq!(e.al_status(), 1);
        assert_eq!(e.al_status_code(), 0);
        let mut p = e.pdi();
        p.write_u16(regs::AL_STATUS, 0x12).unwrap();
        p.write_u16(regs::AL_STATUS_CODE, 0x001B).unwrap();
        assert_eq!(rd(&mut e, regs::AL_STATUS, 2, 0).0, [0x12, 0]);
        assert_eq!(e.al_status_code(), 0x001B);
    }

    #[test]
    fn registers_0000_to_000f_are_read_only_from_ecat() {
        let mut e = esc();
        let (before, _) = rd(&mut e, 0, 16, 0);
        assert_eq!(wr(&mut e, 0, &[0x55; 16], 0), 1);
        assert_eq!(rd(&mut e, 0, 16, 0).0, before);
        e.write(0, &[0x55; 16]).unwrap();
        assert_eq!(rd(&mut e, 0, 16, 0).0, before);
    }

    #[test]
    fn not_present_addresses_read_zero_but_count() {
        let mut e = esc();
        assert_eq!(wr(&mut e, 0x3000, &[1, 2, 3], 0), 1);
        assert_eq!(rd(&mut e, 0x3000, 3, 0), (std::vec![0, 0, 0], 1));
        // across the end of RAM and across 0xFFFF
        wr(&mut e, 0x2FFE, &[7, 7, 7, 7], 0);
        assert_eq!(rd(&mut e, 0x2FFE, 4, 0).0, [7, 7, 0, 0]);
        assert_eq!(rd(&mut e, 0xFFFE, 4, 0), (std::vec![0; 4], 1));
        // a smaller RAM
        let mut small = Esc::new(
            EscConfig {
                ram_kib: 4,
                ..EscConfig::default()
            },
            &[],
        );
        wr(&mut small, 0x2000, &[9], 0);
        assert_eq!(rd(&mut small, 0x2000, 1, 0).0, [0]);
        wr(&mut small, 0x1FFF, &[9], 0);
        assert_eq!(rd(&mut small, 0x1FFF, 1, 0).0, [9]);
    }

    #[test]
    fn mailbox_write_full_busy_and_pdi_read_empties() {
        let mut e = esc();
        setup_sm(&mut e, 0, 0x1000, 128, MBX_OUT);
        let msg1: Vec<u8> = (0..128).map(|i| i as u8).collect();
        // a write that misses the last byte does not complete the mailbox
        assert_eq!(wr(&mut e, 0x1000, &[0xAA; 16], 0), 1);
        assert_eq!(sm_status(&e, 0) & status::MAILBOX_FULL, 0);
        assert_eq!(wr(&mut e, 0x1000, &msg1, 0), 1);
        assert_ne!(sm_status(&e, 0) & status::MAILBOX_FULL, 0);
        assert_ne!(e.al_event().unwrap() & al_event::sm(0), 0);
        // full: the next write is refused and does not count
        assert_eq!(wr(&mut e, 0x1000, &[0x55; 128], 0), 0);
        let mut got = [0u8; 128];
        e.read(0x1000, &mut got).unwrap();
        assert_eq!(&got[..], &msg1[..]);
        assert_eq!(sm_status(&e, 0) & status::MAILBOX_FULL, 0);
        assert_eq!(e.al_event().unwrap() & al_event::sm(0), 0);
        // empty again: the PDI sees nothing, the master may write
        let mut again = [0xEEu8; 4];
        e.read(0x1000, &mut again).unwrap();
        assert_eq!(again, [0; 4], "reading an empty write mailbox is refused");
        assert_eq!(wr(&mut e, 0x1000, &[0x55; 128], 0), 1);
    }

    #[test]
    fn mailbox_without_pdi_irq_raises_no_event() {
        let mut e = esc();
        setup_sm(&mut e, 0, 0x1000, 16, MBX_OUT & !0x20);
        wr(&mut e, 0x1000, &[1; 16], 0);
        assert_ne!(sm_status(&e, 0) & status::MAILBOX_FULL, 0);
        assert_eq!(e.al_event().unwrap() & al_event::sm(0), 0);
    }

    #[test]
    fn mailbox_read_pdi_write_then_ecat_read() {
        let mut e = esc();
        setup_sm(&mut e, 1, 0x1080, 64, MBX_IN);
        // empty: no data, WKC 0
        let (d, wkc) = rd(&mut e, 0x1080, 64, 0);
        assert_eq!(wkc, 0);
        assert!(d.iter().all(|&b| b == 0xEE), "data untouched");
        let msg: Vec<u8> = (0..64).map(|i| 100 + i as u8).collect();
        e.write(0x1080, &msg).unwrap();
        assert_ne!(sm_status(&e, 1) & status::MAILBOX_FULL, 0);
        // the PDI cannot overwrite a full mailbox
        e.write(0x1080, &[0; 64]).unwrap();
        let (d, wkc) = rd(&mut e, 0x1080, 64, 0);
        assert_eq!((d, wkc), (msg.clone(), 1));
        assert_eq!(sm_status(&e, 1) & status::MAILBOX_FULL, 0);
        assert_ne!(e.al_event().unwrap() & al_event::sm(1), 0, "read by the master");
        assert_eq!(rd(&mut e, 0x1080, 64, 0).1, 0, "empty again");
        // the next PDI write acknowledges the event
        e.write(0x1080, &msg).unwrap();
        assert_eq!(e.al_event().unwrap() & al_event::sm(1), 0);
    }

    #[test]
    fn mailbox_repeat_toggle_raises_event_and_allows_rewrite() {
        let mut e = esc();
        setup_sm(&mut e, 1, 0x1080, 16, MBX_IN);
        e.read_u8(regs::sm(1) + 6).unwrap(); // acknowledge the activation event
        assert_eq!(e.al_event().unwrap() & al_event::SM_ACTIVATION, 0);
        let msg = [0x42u8; 16];
        e.write(0x1080, &msg).unwrap();
        assert_eq!(rd(&mut e, 0x1080, 16, 0).1, 1); // ... and the reply gets lost
                                                    // the master toggles REPEAT
        assert_eq!(
            wr(&mut e, regs::sm(1) + 6, &[activate::ENABLE | activate::REPEAT], 0),
            1
        );
        assert_ne!(e.al_event().unwrap() & al_event::SM_ACTIVATION, 0);
        let act = e.read_u8(regs::sm(1) + 6).unwrap();
        assert_eq!(
            e.al_event().unwrap() & al_event::SM_ACTIVATION,
            0,
            "cleared by reading"
        );
        assert_ne!(act & activate::REPEAT, 0);
        e.write(0x1080, &msg).unwrap();
        e.write_u8(regs::sm(1) + 7, pdi_control::REPEAT_ACK).unwrap();
        let (pc, _) = rd(&mut e, regs::sm(1) + 7, 1, 0);
        assert_eq!(pc[0] & pdi_control::REPEAT_ACK, pdi_control::REPEAT_ACK);
        assert_eq!(rd(&mut e, 0x1080, 16, 0), (msg.to_vec(), 1));
        // a repeat while the mailbox is still full lets the PDI write it again
        e.write(0x1080, &[1; 16]).unwrap();
        wr(&mut e, regs::sm(1) + 6, &[activate::ENABLE], 0);
        e.write(0x1080, &[2; 16]).unwrap();
        assert_eq!(rd(&mut e, 0x1080, 16, 0), (std::vec![2; 16], 1));
    }

    #[test]
    fn sm_disable_resets_state_and_activation_raises_event() {
        let mut e = esc();
        setup_sm(&mut e, 0, 0x1000, 8, MBX_OUT);
        assert_ne!(e.al_event_request() & al_event::SM_ACTIVATION, 0);
        wr(&mut e, 0x1000, &[1; 8], 0);
        assert_eq!(wr(&mut e, 0x1000, &[2; 8], 0), 0);
        wr(&mut e, regs::sm(0) + 6, &[0], 0);
        assert_eq!(sm_status(&e, 0), 0);
        assert_eq!(e.al_event_request() & al_event::sm(0), 0);
        // disabled: plain memory
        assert_eq!(wr(&mut e, 0x1000, &[3; 8], 0), 1);
        wr(&mut e, regs::sm(0) + 6, &[activate::ENABLE], 0);
        assert_eq!(wr(&mut e, 0x1000, &[4; 8], 0), 1, "empty after re-enable");
    }

    #[test]
    fn sm_status_and_pdi_control_are_read_only_from_ecat() {
        let mut e = esc();
        let sm = SyncManager {
            start: 0x1000,
            length: 8,
            control: MBX_OUT,
            status: 0xFF,
            activate: 1,
            pdi_control: 0xFF,
        };
        wr(&mut e, regs::sm(0), &sm.to_bytes(), 0);
        let got = e.sync_manager(0);
        assert_eq!(
            (got.start, got.length, got.control, got.activate),
            (0x1000, 8, MBX_OUT, 1)
        );
        assert_eq!((got.status, got.pdi_control), (0, 0));
        // the PDI may write only the PDI control byte
        e.write(regs::sm(0), &[0x99; 8]).unwrap();
        let got = e.sync_manager(0);
        assert_eq!((got.start, got.control, got.pdi_control), (0x1000, MBX_OUT, 0x99));
    }

    #[test]
    fn three_buffer_reader_gets_newest_complete_buffer() {
        let mut e = esc();
        setup_sm(&mut e, 2, 0x1100, 4, PD_OUT);
        assert_eq!(wr(&mut e, 0x1100, &[1; 4], 0), 1);
        assert_ne!(e.al_event().unwrap() & al_event::sm(2), 0);
        assert_eq!(wr(&mut e, 0x1100, &[2; 4], 0), 1);
        let mut b = [0u8; 4];
        e.read(0x1100, &mut b).unwrap();
        assert_eq!(b, [2; 4], "newest complete buffer");
        assert_eq!(
            e.al_event().unwrap() & al_event::sm(2),
            0,
            "acknowledged by the read"
        );
        // a partial write is never seen
        wr(&mut e, 0x1100, &[3, 3], 0);
        e.read(0x1100, &mut b).unwrap();
        assert_eq!(b, [2; 4]);
        wr(&mut e, 0x1102, &[4, 4], 0);
        e.read(0x1100, &mut b).unwrap();
        assert_eq!(b, [3, 3, 4, 4], "completed in the same buffer");
        // a read in progress keeps its buffer
        let mut half = [0u8; 2];
        wr(&mut e, 0x1100, &[5; 4], 0);
        e.read(0x1100, &mut half).unwrap();
        assert_eq!(half, [5, 5]);
        wr(&mut e, 0x1100, &[6; 4], 0);
        e.read(0x1102, &mut half).unwrap();
        assert_eq!(half, [5, 5], "locked buffer");
        e.read(0x1100, &mut b).unwrap();
        assert_eq!(b, [6; 4]);
        // nothing new: the last buffer is read again
        e.read(0x1100, &mut b).unwrap();
        assert_eq!(b, [6; 4]);
        // buffers 1 and 2 are hidden
        assert_eq!(rd(&mut e, 0x1104, 8, 0).0, [0; 8]);
        let mut raw = [0u8; 12];
        e.read_reg(0x1100, &mut raw);
        assert!(
            raw[4..].iter().any(|&x| x != 0),
            "physically stored behind the area"
        );
        // the master cannot read an output buffer
        assert_eq!(rd(&mut e, 0x1100, 4, 0).1, 0);
    }

    #[test]
    fn three_buffer_inputs_partial_pdi_write_never_seen() {
        let mut e = esc();
        setup_sm(&mut e, 3, 0x1400, 4, PD_IN);
        e.write(0x1400, &[1; 4]).unwrap();
        assert_eq!(rd(&mut e, 0x1400, 4, 0), (std::vec![1; 4], 1));
        assert_ne!(
            e.al_event().unwrap() & al_event::sm(3),
            0,
            "inputs read by the master"
        );
        e.write(0x1400, &[2, 2]).unwrap();
        assert_eq!(e.al_event().unwrap() & al_event::sm(3), 0);
        assert_eq!(rd(&mut e, 0x1400, 4, 0), (std::vec![1; 4], 1), "old buffer again");
        e.write(0x1402, &[5, 5]).unwrap();
        assert_eq!(rd(&mut e, 0x1400, 4, 0), (std::vec![2, 2, 5, 5], 1));
        let st = sm_status(&e, 3);
        assert_ne!(
            st & status::BUFFER_MASK,
            status::BUFFER_MASK,
            "a buffer was written"
        );
        assert_eq!(st & (status::READ_OPEN | status::WRITE_OPEN), 0);
    }

    #[test]
    fn pd_watchdog_expires_after_configured_time() {
        let mut e = esc();
        setup_sm(&mut e, 2, 0x1100, 4, PD_OUT);
        wr(&mut e, regs::WATCHDOG_TIME_PD, &10u16.to_le_bytes(), 0); // 10 × 100 µs
        wr(&mut e, 0x1100, &[1; 4], 1_000_000);
        assert_eq!(reg16(&e, regs::WATCHDOG_STATUS_PD) & 1, 1);
        e.tick(1_999_999);
        assert_eq!(reg16(&e, regs::WATCHDOG_STATUS_PD) & 1, 1);
        assert_eq!(e.al_event_request() & al_event::WATCHDOG_PD, 0);
        e.tick(2_000_000);
        assert_eq!(reg16(&e, regs::WATCHDOG_STATUS_PD) & 1, 0);
        assert_eq!(rd(&mut e, regs::WATCHDOG_COUNTER_PD, 1, 2_000_000).0, [1]);
        assert_ne!(e.al_event().unwrap() & al_event::WATCHDOG_PD, 0);
        e.read_u16(regs::WATCHDOG_STATUS_PD).unwrap();
        assert_eq!(e.al_event().unwrap() & al_event::WATCHDOG_PD, 0);
        // retriggered by the next output write, expires once more
        wr(&mut e, 0x1100, &[2; 4], 3_000_000);
        e.tick(3_500_000);
        assert_eq!(reg16(&e, regs::WATCHDOG_STATUS_PD) & 1, 1);
        e.tick(4_000_000);
        assert_eq!(rd(&mut e, regs::WATCHDOG_COUNTER_PD, 1, 4_000_000).0, [2]);
        // an ECAT write clears the counter; time 0 disables the watchdog
        wr(&mut e, regs::WATCHDOG_COUNTER_PD, &[0], 4_000_000);
        wr(&mut e, regs::WATCHDOG_TIME_PD, &[0, 0], 4_000_000);
        wr(&mut e, 0x1100, &[3; 4], 5_000_000);
        e.tick(1_000_000_000);
        assert_eq!(rd(&mut e, regs::WATCHDOG_COUNTER_PD, 1, 1_000_000_000).0, [0]);
    }

    #[test]
    fn pdi_watchdog_expires_without_pdi_access() {
        let mut e = esc();
        e.tick(1_000);
        e.read_u8(0).unwrap();
        assert_ne!(reg16(&e, regs::DL_STATUS) & dl::PDI_WATCHDOG, 0);
        e.tick(1_000 + 100_000_000 - 1);
        assert_eq!(e.read_u8(regs::WATCHDOG_COUNTER_PDI).unwrap(), 0); // also retriggers
        e.tick(200_000_998);
        assert_eq!(e.get_u8(regs::WATCHDOG_COUNTER_PDI), 0);
        e.tick(200_000_999);
        assert_eq!(e.get_u8(regs::WATCHDOG_COUNTER_PDI), 1);
        assert_eq!(reg16(&e, regs::DL_STATUS) & dl::PDI_WATCHDOG, 0);
    }

    #[test]
    fn dc_write_latches_receive_time_and_system_time_adds_offset() {
        let mut e = esc();
        let now = 0x1_2345_6789u64;
        assert_eq!(
            xfer1(
                &mut e,
                Command::Bwr,
                phys(0, regs::dc::RECEIVE_TIME_PORT0),
                &[0; 4],
                now
            )
            .1,
            1
        );
        let (d, _) = rd(&mut e, regs::dc::RECEIVE_TIME_PORT0, 16, now);
        assert_eq!(&d[..4], &(now as u32).to_le_bytes());
        assert_eq!(&d[4..8], &(now as u32).to_le_bytes());
        let (d, _) = rd(&mut e, regs::dc::RECEIVE_TIME_PU, 8, now);
        assert_eq!(d, now.to_le_bytes());
        wr(
            &mut e,
            regs::dc::SYSTEM_TIME_OFFSET,
            &(-1000i64).to_le_bytes(),
            now,
        );
        let (d, wkc) = rd(&mut e, regs::dc::SYSTEM_TIME, 8, now + 5);
        assert_eq!(
            (u64::from_le_bytes(d.try_into().unwrap()), wkc),
            (now + 5 - 1000, 1)
        );
        // a write of the system time does not overwrite it
        wr(&mut e, regs::dc::SYSTEM_TIME, &[0; 8], now + 10);
        let mut b = [0u8; 8];
        e.read(regs::dc::SYSTEM_TIME, &mut b).unwrap();
        assert_eq!(u64::from_le_bytes(b), now + 10 - 1000);
    }

    #[test]
    fn pdi_handle_and_direct_impl_agree() {
        let mut e = esc();
        e.pdi().write(0x1F00, &[1, 2, 3]).unwrap();
        let mut b = [0u8; 3];
        Pdi::read(&mut e, 0x1F00, &mut b).unwrap();
        assert_eq!(b, [1, 2, 3]);
        // a long PDI write into a mailbox completes it on its last byte
        setup_sm(&mut e, 1, 0x1200, 600, MBX_IN);
        let msg: Vec<u8> = (0..600).map(|i| (i % 251) as u8).collect();
        e.pdi().write(0x1200, &msg).unwrap();
        assert_ne!(sm_status(&e, 1) & status::MAILBOX_FULL, 0);
        assert_eq!(rd(&mut e, 0x1200, 600, 0), (msg, 1));
    }
}
