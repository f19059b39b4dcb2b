//! The drive's communication runtime: the slave stack, the object dictionary
//! and the non-volatile store composed once, so the firmware and the
//! simulator run the same code.
//!
//! Each [`Drive::poll`] runs the slave stack over the given PDI, then feeds
//! the live objects that mirror the EtherCAT state (A254, A255, A256, A257\[3\])
//! and serves the dictionary's requests: "save values" (A00, 1010h) writes the
//! persistent image through [`store::ParamStore`]; at construction the newest
//! saved image is loaded (E-018, E-020).
//!
//! Process data (E-032…E-035) goes through a [`PdoImage`] compiled from the
//! mapping at every change into Safe-Op: in Safe-Op and Op the TxPDO image is
//! filled from the objects every poll (before the slave stack copies it to
//! SM3); in Op every new RxPDO frame is decoded into the objects; on leaving
//! Op the RxPDO-mapped objects fall back to their "internal defaults": the
//! defaults declared in the dictionary for set-points (controlword 0, target
//! values 0, digital outputs 0), and for RxPDO-mapped parameters (persistent
//! entries, e.g. 6060h modes of operation = A541) the value they had when Op
//! was entered (the saved or SDO-configured parameter, else the declared
//! default), so the master's process data never changes a parameter for good.
//! Below Op the RxPDO objects keep those defaults (or what an SDO write put
//! there): RxPDO content is never evaluated outside Op.
//!
//! DC-Sync (E-107…E-118): the drive owns one [`dcsync::Pll`] while SYNC0
//! pulses arrive. The firmware's SYNC0 interrupt calls [`Drive::on_sync0`]
//! (the PLL is built at the first pulse from the ESC's SYNC0 cycle 0x09A0
//! and A150/A292/A149/A290; a configuration the PLL refuses leaves it off
//! and is kept in [`Drive::sync_error`]), the control-cycle timer interrupt
//! calls [`Drive::cycle_start`] and programs the next start from the
//! returned period, the SM2 event calls [`Drive::on_frame`]. A296, A298 and
//! A261 follow the PLL. Going back to Init drops the PLL.
//!
//! The slave stack learns the synchronisation state through
//! [`ecat::Slave::set_sync_state`], set from the PLL before each slave poll
//! while the mode accepted at P→S is DC SYNC0 and the PLL is enabled (A290 =
//! 1): Safe-Op → Op waits for the lock (002Dh without SYNC0, 0032h not
//! locked), a latched PLL fault in Op drops to Safe-Op with its AL code and
//! EMCY 7500h cause 7 (spec §3.3, §13.4). The master's error acknowledge
//! clears the PLL fault, and so does Pre-Op → Safe-Op (a fault latched
//! below Safe-Op, where no error is shown, is not the new configuration's). In SM-Sync the SM2 event drives the PLL instead
//! of SYNC0 (E-110, [`Drive::on_frame`]).
//!
//! Event 52 "Communication" (E-128…E-131): when the slave leaves Op for a
//! PDO timeout (cause 6) or a sync fault (cause 7), or the projected
//! fieldbus identification does not match (cause 15), both axes run the
//! fault reaction of 605Eh (A540) and end in Fault ([`Drive::raise_event52`]),
//! with one EMCY for the event.
//!
//! Firmware update (issue 8): a drive built with [`Drive::with_boot`] holds
//! the firmware slots ([`boot::BootSlots`]) and passes FoE writes in
//! Bootstrap through to them ([`FirmwareFoe`]): a file named
//! `firmware…` ([`FIRMWARE_FILE`]) goes into the inactive slot, is
//! CRC-checked and its signature verified against [`FIRMWARE_PUBLIC_KEY`]
//! at its end (issue 18) and marked pending; the next boot tries it and
//! the running image confirms itself with [`Drive::confirm_firmware`].
//! [`Drive::new`] has no slots: FoE writes are refused (8002h).
//!
//! Diagnosis (E-132…E-139): A257[0..2] from the ESC's DL status and error
//! counters (read every poll), A257\[3\] from the AL status code, and the
//! four LEDs as patterns of `ecat::led` ([`Drive::leds`]).

mod control;
mod diag;
mod eoe;
mod foe;
mod power;
mod save;
mod slots;
mod sync;

use crate::faults::FaultChange;
use diag::{is_event52, PortDiag, Text};
pub use diag::{Leds, DIAG_AL_STATUS, DIAG_EMCY};
pub use eoe::IpSettings;
pub use foe::{
    foe_error, update_slot_value, FirmwareFoe, FirmwareStored, FIRMWARE_FILE, FIRMWARE_KEY_IS_DEVELOPMENT,
    FIRMWARE_PUBLIC_KEY,
};
pub use save::{save_result, SaveJob, RESTART_DELAY};
use slots::RuntimeSlots;
use sync::PllSettings;

use crate::axis::{Axis, AxisCache, AxisCommand, AxisIo};
use crate::dictionary::{
    read_slot, write_slot, DriveObjects, LiveValues, NoLive, Slot, PERSISTENT_IMAGE_BYTES,
};
use crate::ecat_app::{event52, event52_cause, EcatApp};
use crate::pdo_image::{PdoImage, PdoImageError};
use boot::{BootSlots, NoFlash, UpdateError};
use ecat::diag::{DiagHistory, DiagMessage, DiagType};
use ecat::esm::{SyncMode, SyncState};
use ecat::foe::{Accept, FoeError, FoeHandler};
use ecat::led::Pattern;
use ecat::{Slave, StateChange};
use esc::{regs, AlState, AlStatusCode, Pdi, PdiExt};
use nanos::Nanos;
use od::SdoAbort;
use store::{Flash, ParamStore, StoreError};

/// The DC-Sync crate (PLL, A298/A261 types), re-exported for the firmware and tests.
pub use dcsync;
use dcsync::CycleSequence;
pub use dcsync::{CycleCommand, FrameTiming, Pll, Step, SyncError};

use crate::params::{
    A00, A149, A150, A254, A255, A256, A257, A261, A287, A290, A291, A292, A296, A298, E43, E54, E59, E82,
};

/// This firmware's fieldbus identification (EtherCAT), compared with the
/// projected one (E59\[2\], [`Drive::set_projected_fieldbus`]) for event 52
/// cause 15 (E-130). The code is our choice: the sources give no values.
pub const FIELDBUS_ID: u16 = 1;

/// Versions of the EtherCAT diagnosis parameters as this firmware lays
/// them out (E-139, spec §13.6, the S edition): (line of group A, version).
/// A255 V3: 17/18/20/24 error states; A257 V2: four texts, `[0]` without
/// `StX`, `[3]` "AL xxxx"; A287 V3: action with progress and result.
pub const PARAMETER_VERSIONS: [(u16, u8); 7] = [
    (254, 0),
    (255, 3),
    (256, 1),
    (257, 2),
    (259, 1),
    (261, 1),
    (287, 3),
];

/// Tick frequency of the control-cycle timer the PLL trims, Hz (the
/// reference board's CCU4 at 144 MHz; the simulator models the same).
pub const TIMER_HZ: u32 = 144_000_000;

/// Distance the A287 measurement keeps between the drive's Rx/Tx and the
/// master's frame when it proposes the A292 range, ns (our choice).
pub const OPTIMIZE_GUARD_NS: u32 = 5_000;

/// The live objects the runtime owns: 10F3h from the diagnosis history;
/// the rest asked of the shell's provider `extra` (the scope's objects,
/// [`drive_core::scope`]; [`NoLive`] where the shell has none).
struct Live<'a, L: LiveValues> {
    diag: &'a mut DiagHistory,
    extra: &'a mut L,
}

impl<L: LiveValues> LiveValues for Live<'_, L> {
    fn read(&mut self, index: u16, sub: u8, buf: &mut [u8]) -> Option<Result<usize, SdoAbort>> {
        if index == 0x10F3 {
            Some(self.diag.read(sub, buf))
        } else {
            self.extra.read(index, sub, buf)
        }
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        if index == 0x10F3 {
            self.diag.write(sub, data)
        } else {
            self.extra.write(index, sub, data)
        }
    }

    fn provide(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        self.extra.provide(index, sub, data)
    }
}

/// What happened to the saved parameters at start-up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Startup {
    /// A saved set was loaded.
    Loaded,
    /// Nothing saved yet (or from another firmware layout): defaults.
    Defaults,
}

/// One drive on the bus: slave stack + object dictionary + parameter store
/// (+ the firmware slots on flash `B`, see [`Drive::with_boot`]).
#[derive(Clone)]
pub struct Drive<F: Flash, B: Flash = NoFlash> {
    /// The EtherCAT slave stack.
    slave: Slave,
    /// The EoE interface (E-095): the Ethernet frames the master tunnels
    /// to the drive and those the IP stack (crate `net`) sends back, and the
    /// IP parameters the master set (E-096). See [`Drive::with_eoe`].
    eoe: ecat::eoe_queue::EoeQueue,
    /// The object dictionary (values in RAM).
    objects: DriveObjects,
    /// The parameter store; out in a [`SaveJob`] while one runs.
    store: Option<ParamStore<F>>,
    /// The firmware slots (FoE firmware update), if the drive has them.
    boot: Option<BootSlots<B>>,
    /// The last FoE download verified and stored, until
    /// [`take_firmware_stored`](Drive::take_firmware_stored).
    firmware_stored: Option<FirmwareStored>,
    /// Diagnosis history 10F3h (volatile, E-145).
    diag: DiagHistory,
    startup: Startup,
    last_code: AlStatusCode,
    /// The process images of the mapping in force (compiled at P→S).
    pdo: PdoImage,
    /// Why the last compilation failed (the image is then empty).
    pdo_error: Option<PdoImageError>,
    /// The slave's state after the previous poll.
    last_state: AlState,
    /// `Slave::outputs_received` after the previous poll.
    last_rx_frames: u32,
    /// The two axes (A, B), stepped by [`Drive::control_cycle`].
    axes: [Axis; 2],
    /// A75/A69 actions over the fieldbus (E-140), served after each RxPDO.
    actions: drive_core::actions::Actions,
    /// Each axis' snapshot and slots, read in place by the control cycle.
    axis_caches: [AxisCache; 2],
    /// `Slave::outputs_received` at the previous control cycle (new
    /// cyclic set-points).
    ctl_rx_frames: u32,
    /// The DC-Sync PLL while SYNC0 runs (built at the first pulse).
    pll: Option<Pll>,
    /// The PLL settings of the objects (A292, A149, A290) with the
    /// configuration generation they were read at: read again only when
    /// it moved.
    pll_settings: Option<(u32, PllSettings)>,
    /// The PLL's status and fault as A298 and the sync diagnostics show
    /// them (`None` without a PLL): rewritten only when they differ.
    sync_shown: Option<(dcsync::PllStatus, Option<dcsync::SyncFault>)>,
    /// The entries of the cyclic paths.
    slots: RuntimeSlots,
    /// Why the PLL could not be built for the last SYNC0 configuration.
    sync_error: Option<SyncError>,
    /// The A287 measurement.
    optimizer: dcsync::Optimizer,
    /// Arrival of the last SM2 frame relative to SYNC0 (local ns), not yet
    /// given to the A287 measurement.
    frame_rel_sync0_ns: Option<i64>,
    /// Rx and Tx of the aligned cycle after its start, ns (for A287).
    step_offsets_ns: (u32, u32),
    /// The control cycle ([`Drive::sync_cycle`]) runs Rx and Tx: the poll
    /// leaves the process images alone.
    cycle_pdo: bool,
    /// Per axis: an event 52 was injected whose EMCY is already queued, so
    /// the axis' own EMCY at T13 is dropped (one EMCY per event, E-087).
    event52_emcy_sent: [bool; 2],
    /// Per axis: the fault its last T13 raised, for the diagnosis history
    /// at the next poll (which reads the time stamp, E-144).
    fault_diag: [Option<drive_core::faults::Fault>; 2],
    /// When A09 requested a restart ([`Drive::restart_due`]).
    restart_requested: Option<Nanos>,
    /// The projected fieldbus identification (E59[2]).
    projected_fieldbus: u16,
    /// Event 52 cause 15 was raised for the present mismatch.
    wrong_firmware: bool,
    /// SNTP time minus local time, ns (DC epoch), while an SNTP client
    /// keeps the time ([`Drive::set_sntp_time`]).
    sntp_offset_ns: Option<i64>,
    /// The ESC's port and error registers as the last poll read them.
    ports: PortDiag,
    /// A257 Er9 (SM1, mailbox Tx) or Er10 (SM0, mailbox Rx) for the last
    /// refused I→P (AL 0016h).
    mailbox_er: u8,
    /// The PLL follows the SM2 event (SM-Sync, E-110), not SYNC0.
    pll_from_sm: bool,
}

impl<F: Flash, B: Flash> Drive<F, B> {
    /// The EtherCAT slave stack (ESM state, sync status, counters, FoE,
    /// EoE server).
    pub fn slave(&self) -> &Slave {
        &self.slave
    }

    /// The slave stack, mutable: for board support and tests that work on
    /// it directly (the process images, a queued emergency).
    pub fn slave_mut(&mut self) -> &mut Slave {
        &mut self.slave
    }

    /// The object dictionary.
    pub fn objects(&self) -> &DriveObjects {
        &self.objects
    }

    /// The object dictionary, mutable: what a local write (board support,
    /// tests, the simulator's set-up) goes through.
    pub fn objects_mut(&mut self) -> &mut DriveObjects {
        &mut self.objects
    }

    /// The EoE interface's frame queues (E-095): see [`Drive::with_eoe`].
    pub fn eoe(&self) -> &ecat::eoe_queue::EoeQueue {
        &self.eoe
    }

    /// The EoE queues, mutable (an IP stack bound to them, tests).
    pub fn eoe_mut(&mut self) -> &mut ecat::eoe_queue::EoeQueue {
        &mut self.eoe
    }

    /// The two axes (A, B).
    pub fn axes(&self) -> &[Axis; 2] {
        &self.axes
    }

    /// The axes, mutable (their parameters, tests).
    pub fn axes_mut(&mut self) -> &mut [Axis; 2] {
        &mut self.axes
    }

    /// The diagnosis history 10F3h.
    pub fn diag(&self) -> &DiagHistory {
        &self.diag
    }

    /// The process images in force (compiled at the last change into Safe-Op).
    pub fn pdo_image(&self) -> &PdoImage {
        &self.pdo
    }

    /// Why the last compilation of the mapping failed, if it did (the
    /// process images are then empty: nothing decoded, zeros sent).
    pub fn pdo_image_error(&self) -> Option<PdoImageError> {
        self.pdo_error
    }

    /// Compiles the current mapping into [`Self::pdo_image`].
    fn compile_pdo_image(&mut self) {
        // field by field: a (image, error) tuple cost several copies of the
        // image on the ESC task's stack
        match PdoImage::compile(&self.objects) {
            Ok(image) => {
                self.pdo = image;
                self.pdo_error = None;
            }
            Err(e) => {
                self.pdo = PdoImage::EMPTY;
                self.pdo_error = Some(e);
            }
        }
    }

    /// Runs the slave stack once at `now`, then process data, the live
    /// objects and the dictionary's requests.
    pub fn poll<P: Pdi>(&mut self, pdi: &mut P, now: Nanos) -> Result<Option<StateChange>, P::Error> {
        self.poll_with(pdi, now, &mut NoLive)
    }

    /// [`poll`](Self::poll) with the shell's provider of further live
    /// objects (the scope's recorder: its objects are answered by it, the
    /// mailbox reads and writes them through it).
    pub fn poll_with<P: Pdi, L: LiveValues>(
        &mut self,
        pdi: &mut P,
        now: Nanos,
        extra: &mut L,
    ) -> Result<Option<StateChange>, P::Error> {
        let change = self.poll_parts(pdi, now, true, extra)?;
        let _ = self.serve_requests();
        Ok(change)
    }

    /// The ESC-event part of [`poll`](Self::poll) for the priority-2 task:
    /// AL control, process data, monitoring, live values; the mailbox
    /// waits for [`poll_mailbox`](Self::poll_mailbox).
    pub fn poll_esc<P: Pdi>(&mut self, pdi: &mut P, now: Nanos) -> Result<Option<StateChange>, P::Error> {
        self.poll_parts(pdi, now, false, &mut NoLive)
    }

    /// The mailbox part of [`poll`](Self::poll) for the low-priority task:
    /// one CoE/EoE/FoE request answered, queued EMCYs and EoE fragments
    /// sent. A save it requests waits for the idle loop's
    /// [`begin_save`](Self::begin_save).
    pub fn poll_mailbox<P: Pdi>(&mut self, pdi: &mut P, now: Nanos) -> Result<(), P::Error> {
        self.poll_mailbox_with(pdi, now, &mut NoLive)
    }

    /// [`poll_mailbox`](Self::poll_mailbox) with the shell's provider of
    /// further live objects (the board's scope recorder: group T is read and
    /// written through it, as [`poll_with`](Self::poll_with) does in one poll).
    pub fn poll_mailbox_with<P: Pdi, L: LiveValues>(
        &mut self,
        pdi: &mut P,
        now: Nanos,
        extra: &mut L,
    ) -> Result<(), P::Error> {
        self.update_live();
        self.with_mailbox(extra, |slave, app, foe, eoe| {
            slave.poll_mailbox_only(pdi, app, foe, eoe, now)
        })
    }

    /// `f` on the slave stack with one poll's mailbox services: the
    /// dictionary's parameter channel (the diagnosis history and `extra` as
    /// live values), the firmware slots' FoE handler and the EoE queue; an
    /// image the handler stored is kept for
    /// [`take_firmware_stored`](Self::take_firmware_stored) when `f` succeeds.
    fn with_mailbox<L: LiveValues, R, E>(
        &mut self,
        extra: &mut L,
        f: impl FnOnce(
            &mut Slave,
            &mut EcatApp<'_, Live<'_, L>>,
            &mut FirmwareFoe<'_, B>,
            &mut ecat::eoe_queue::EoeQueue,
        ) -> Result<R, E>,
    ) -> Result<R, E> {
        let mut live = Live {
            diag: &mut self.diag,
            extra,
        };
        let mut foe = FirmwareFoe::new(self.boot.as_mut());
        let app = &mut EcatApp(self.objects.parameter_channel(&mut live));
        let r = f(&mut self.slave, app, &mut foe, &mut self.eoe)?;
        self.firmware_stored = foe.stored().or(self.firmware_stored);
        Ok(r)
    }

    /// The FoE download verified and stored since the last call (issue 33):
    /// the slot it is in and its version, for the log ("the image landed").
    pub fn take_firmware_stored(&mut self) -> Option<FirmwareStored> {
        self.firmware_stored.take()
    }

    /// The SNTP time now, ns since 2000-01-01 (the DC epoch), from the IP
    /// stack's SNTP client (`None`: no time); `local_now` is the local
    /// time it belongs to. Message time stamps use it when DC is not
    /// synchronised (E-147).
    pub fn set_sntp_time(&mut self, sntp: Option<Nanos>, local_now: Nanos) {
        self.sntp_offset_ns = sntp.map(|t| (t.as_ns() as i64).wrapping_sub(local_now.as_ns() as i64));
    }

    /// The time stamp of a diagnosis message at local `now` (E-147,
    /// spec §17): the DC system time (0x0910) when the drive runs DC-Sync
    /// with the PLL locked, else the SNTP time, else 0.
    fn message_time_stamp<P: Pdi>(&self, pdi: &mut P, now: Nanos) -> Result<Nanos, P::Error> {
        let dc_synced = self.slave.sync_status().mode == SyncMode::DcSync0
            && self.pll.as_ref().is_some_and(|p| p.is_locked());
        if dc_synced {
            let mut t = [0u8; 8];
            pdi.read(regs::dc::SYSTEM_TIME, &mut t)?;
            return Ok(Nanos::from_ns(u64::from_le_bytes(t)));
        }
        Ok(self.sntp_offset_ns.map_or(Nanos::ZERO, |o| {
            Nanos::from_ns((now.as_ns() as i64).wrapping_add(o) as u64)
        }))
    }

    fn poll_parts<P: Pdi, L: LiveValues>(
        &mut self,
        pdi: &mut P,
        now: Nanos,
        mailbox: bool,
        extra: &mut L,
    ) -> Result<Option<StateChange>, P::Error> {
        if !self.cycle_owns_pdo() {
            self.process_inputs();
        }
        self.slave.set_sync_state(self.sync_state());
        let change = self.with_mailbox(extra, |slave, app, foe, eoe| {
            if mailbox {
                slave.poll_with_eoe(pdi, app, foe, eoe, now)
            } else {
                slave.poll_esc(pdi, app, now)
            }
        })?;
        if self.slave.take_error_ack() {
            // the master acknowledged the error: a latched PLL fault goes
            // (a new one latches again at the next occurrence)
            if let Some(pll) = self.pll.as_mut() {
                pll.clear_fault();
            }
            self.update_sync_live();
        }
        self.process_outputs();
        // E-140: the axes' A75 as the RxPDO (or an SDO) left it
        let fx = self.actions.serve(&mut self.objects);
        for (axis, clear) in self.axes.iter_mut().zip(fx.clear_reference) {
            if clear {
                axis.clear_reference();
            }
        }
        if let Some(loss) = self.slave.take_op_loss() {
            // the slave left Op by itself: event 52 with its EMCY 7500h
            self.raise_event52(event52_cause(loss));
        }
        self.check_fieldbus_identification();
        if change.is_some_and(|c| c.code == AlStatusCode::INVALID_MAILBOX_CONFIG) {
            // Er10: the mailbox the master writes (SM0), Er9: the one it reads
            self.mailbox_er = if self.slave.mailbox_fault() == Some(1) {
                9
            } else {
                10
            };
        }
        self.read_ports(pdi)?;
        if let Some(c) = change.filter(|c| c.code != AlStatusCode::NO_ERROR) {
            // a refused state change is an error message in the history (E-144)
            let msg = DiagMessage::new(DIAG_AL_STATUS | u32::from(c.code.0), DiagType::Error, c.code.0);
            let stamp = self.message_time_stamp(pdi, now)?;
            self.diag.push(msg, stamp);
        }
        self.push_fault_messages(pdi, now)?;
        if change.is_some() {
            // A254/A256 as the ESC has them after the master's configuration
            let alias = pdi.read_u16(regs::STATION_ALIAS)?;
            let address = pdi.read_u16(regs::STATION_ADDRESS)?;
            let _ = self.objects.set(A254, 0, i64::from(alias));
            let _ = self.objects.set(A256, 0, i64::from(address));
        }
        self.update_live();
        self.update_optimizer();
        Ok(change)
    }

    /// State changes and the RxPDO: on leaving Op the RxPDO objects fall back
    /// to their defaults (E-035); on entering Safe-Op the mapping is compiled
    /// (E-019); on entering Op the RxPDO-mapped parameters are captured as
    /// their fallbacks; in Op each new SM2 frame is decoded (E-034). Safe-Op frames
    /// are counted by the slave but never decoded (E-032).
    fn process_outputs(&mut self) {
        let state = self.slave.state();
        if state != self.last_state {
            if self.last_state == AlState::Op {
                self.pdo.restore_rx_defaults(&mut self.objects);
            }
            if state == AlState::SafeOp {
                self.compile_pdo_image();
                // a PLL fault latched below Safe-Op (SYNC0 stopped in Init or
                // Pre-Op, where the drive shows no error to acknowledge) is
                // not this synchronisation's: S→O asks for SYNC0 and the lock
                if self.last_state == AlState::PreOp {
                    if let Some(pll) = self.pll.as_mut() {
                        pll.clear_fault();
                    }
                }
            }
            if state == AlState::Init || (self.pll_from_sm && state == AlState::PreOp) {
                self.pll_from_sm = false;
                self.pll = None;
                self.sync_shown = None;
                self.sync_error = None;
                self.cycle_pdo = false;
                self.update_sync_live();
            }
            if state == AlState::Op {
                self.pdo.capture_fallbacks(&self.objects);
            }
            self.last_state = state;
        }
        if !self.cycle_owns_pdo() {
            self.read_outputs();
        }
    }

    /// Rx: decodes a new RxPDO frame (read from SM2 by the last poll) into
    /// the objects, in Op only. Returns whether there was one.
    fn read_outputs(&mut self) -> bool {
        let frames = self.slave.outputs_received();
        let new = self.slave.state() == AlState::Op && frames != self.last_rx_frames;
        if new {
            self.pdo.apply_outputs(self.slave.outputs(), &mut self.objects);
        }
        self.last_rx_frames = frames;
        new
    }

    /// Whether the control cycle runs Rx and Tx ([`Drive::sync_cycle`]
    /// under the PLL) rather than every poll.
    fn cycle_owns_pdo(&self) -> bool {
        self.cycle_pdo && self.pll.is_some()
    }

    /// In Safe-Op and Op the TxPDO image follows the objects (E-032, E-034).
    /// Runs before the slave's poll, which copies the image to SM3 at once:
    /// a value set between two polls is on the bus after the next poll.
    fn process_inputs(&mut self) {
        if matches!(self.slave.state(), AlState::SafeOp | AlState::Op) {
            // 10F3h:04 (A250) is answered live; the image needs its value in RAM
            write_slot(
                &mut self.objects,
                self.slots.new_messages,
                i64::from(self.diag.new_messages()),
            );
            self.pdo.fill_inputs(&self.objects, self.slave.inputs_mut());
        }
    }

    /// Reads an object as the bus sees it (live values included), without the bus.
    pub fn read_object(
        &mut self,
        index: u16,
        sub: u8,
        buf: &mut [u8],
        state: od::CommState,
    ) -> Result<usize, SdoAbort> {
        use od::Dictionary as _;
        let mut live = Live {
            diag: &mut self.diag,
            extra: &mut NoLive,
        };
        self.objects
            .parameter_channel(&mut live)
            .read(index, sub, buf, state)
    }

    /// A255 (state, +16 with error) and A257[3] ("AL xxxx") follow the slave.
    fn update_live(&mut self) {
        let state = i64::from(self.slave.state().code()) + if self.slave.error() { 16 } else { 0 };
        write_slot(&mut self.objects, self.slots.a255, state);
        let code = self.slave.al_status_code();
        if code != self.last_code {
            self.last_code = code;
            let mut t = Text::new();
            t.put(b"AL ");
            t.hex(code.0, 4);
            let _ = self.objects.set_bytes(A257, 4, t.bytes());
        }
        if self.ports.shown && self.er_code() != self.ports.er {
            self.ports.er = self.er_code();
            self.update_a257_texts();
        }
    }
}
