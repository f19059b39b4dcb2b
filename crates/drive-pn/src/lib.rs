//! The drive on PROFINET: [`PnDrive`] puts the PROFINET IO device
//! ([`profinet::device::Device`]) in front of the fieldbus-neutral drive core
//! ([`drive_core`]: the object dictionary and both axes) and its parameter
//! store ([`store::ParamStore`]), the way `drive` puts the EtherCAT slave
//! stack in front of it.
//!
//! What the personality translates:
//!
//! | core | PROFINET |
//! |---|---|
//! | a fault raised (T13): E82 event HH, E43 cause S | a diagnosis alarm "appears", ChannelErrorType 0x1000 + HH, ExtChannelErrorType 0x1000 + S (P-030…P-033, Q-13) |
//! | the fault reset (T15) | "disappears" (P-035) |
//! | event 52 cause 6 (communication: process data lost), both axes, fault reaction | the AR lost: the output CR's watchdog expired or the alarm channel failed (P-036, Q-07) |
//! | a new set-point each control cycle | a valid output frame since the last cycle |
//! | A270…A278, the PROFINET operating parameters ([`settings`]) | the device's name and IP at start, DCP Set / Reset to factory written back and saved, PROFINET on or off |
//! | A275 and the power stages ([`energy`]) | PROFIenergy (record 0x80A0): the pause switches both power stages' supply off, taken only with the axes idle (P-015, P-016) |
//!
//! Parameters (spec §2.4). At start ([`PnDrive::new`]) the newest saved
//! set is loaded from the flash; the device starts with the name of station
//! A271 (P-007) and the static IP suite A272…A274 (P-010, used until DCP
//! assigns another). DCP events go into the objects:
//!
//! - a permanent Set of the name or the IP suite writes A271 / A272…A274
//!   and saves (P-009: a DCP IP overwrites the stored static one);
//! - a temporary Set writes them in RAM and saves their defaults (empty,
//!   0.0.0.0): the value is gone after a restart and the one stored before
//!   does not come back. Until the restart every save ([`PnDrive::save`])
//!   stores the default in its place, so the temporary value never reaches
//!   the flash;
//! - Reset to factory: the communication modes clear name and IP (the DCP
//!   server raises the matching permanent Sets); mode "All" restores every
//!   parameter default first; mode 1 ("application data") restores every
//!   default except the PROFINET parameters A270…A278. Each is saved.
//!   The communication modes and "All" also blank I&M1…4.
//!
//! I&M1…4 (P-039) written by a controller are saved at once, behind the
//! parameter image in the same store record ([`settings::im_trailer`]), and
//! come back at the next start ([`PnParamFlash`] holds both).
//!
//! PROFINET active (A270, P-012/P-013) is read at start: with 0 the drive
//! is silent from power-on. Switched off while running it takes effect at
//! once (sampled at every [`receive`](PnDrive::receive),
//! [`poll`](PnDrive::poll) and [`control_cycle`](PnDrive::control_cycle)):
//! every received frame is dropped unseen (counted,
//! [`PnDrive::dropped_inactive`]) and everything the device would send is
//! discarded, while its timers keep running, so a running AR's watchdog
//! expires and the axes get the AR-loss fault as for any lost AR. Switched
//! on again it stays off until the next start: activation needs a save and a
//! restart (Save & Reset, P-019), as the spec says.
//!
//! Saving is synchronous here ([`PnDrive::save`]: the image is built and
//! the flash written in one call). The EtherCAT runtime's save job
//! (`drive_ecat::runtime::Drive::begin_save` / `SaveJob::write` / `end_save`,
//! the flash written without holding the drive) is the model for the board.
//!
//! The telegram mapping of the profile (CW1/ZSW1, PNU) is the next layer
//! (issue 17); until then the cyclic data is reachable as bytes
//! ([`PnDrive::device`]).
#![no_std]
#![deny(missing_docs)]

use core::mem::MaybeUninit;
use core::ptr::addr_of_mut;
use drive_core::actions::Actions;
use drive_core::axis::{Axis, AxisCache, AxisCommand, AxisIo};
use drive_core::faults::{FaultChange, E82_INACTIVE};
use drive_core::objects::LAYOUT_HASH;
use drive_core::params::{A00, A150, A150_FALLBACK_US, A270, A271, A275, E43, E82, PROFINET_PARAMS};
use drive_core::DriveObjects;
use nanos::Nanos;
use profinet::cm::CmEvent;
use profinet::cm::{ImData, NoRecords, RecordHook};
use profinet::dcp::{Event as DcpEvent, IpSuite, NameOfStation, ResetMode};
use profinet::device::{Device, DeviceEvent, RtEvent};
use profinet::profienergy::ProfiEnergy;
use store::{Flash, ParamStore};

pub mod bmp_record;
mod cycle;
pub mod energy;
pub mod profile;
pub mod scope_record;
pub mod settings;
pub use energy::{DriveEnergy, PnRecords};
use settings::NAME_LEN;
pub use settings::{Hardware, PnParamFlash, STORED_BYTES};

#[cfg(test)]
extern crate std;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_bmp;
#[cfg(test)]
mod tests_energy;
#[cfg(test)]
mod tests_params;
#[cfg(test)]
mod tests_scope;
#[cfg(test)]
mod tests_snmp;

/// The event a lost AR raises on both axes: event 52 (communication).
pub const AR_LOST_EVENT: u8 = 52;
/// Its cause: 6, process data lost (the cause EtherCAT's PDO timeout uses).
pub const AR_LOST_CAUSE: u8 = 6;

/// What happened to the saved parameters at start.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Startup {
    /// A saved set was loaded.
    Loaded,
    /// Nothing saved yet, from another declaration, or unreadable: defaults.
    Defaults,
}

/// Which of the DCP-set values in RAM are temporary (their stored value is
/// the default until a restart).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
struct Temporary {
    name: bool,
    ip: bool,
}

/// The drive on PROFINET. See the [crate documentation](crate).
pub struct PnDrive<F: Flash, H: RecordHook = NoRecords> {
    device: Device<PnRecords<H>>,
    objects: DriveObjects,
    store: ParamStore<F>,
    startup: Startup,
    /// PROFINET active: A270 at start, cleared for good (until the next
    /// start) as soon as A270 reads 0.
    active: bool,
    /// Frames dropped while PROFINET is off.
    dropped_inactive: u32,
    temporary: Temporary,
    axes: [Axis; 2],
    caches: [AxisCache; 2],
    /// The diagnosis (HH, S) each axis' fault raised, to clear it on T15.
    raised: [Option<(u8, u8)>; 2],
    /// A valid output frame arrived since the last control cycle.
    exchanged: bool,
    /// Each axis' power stage was on in the last control cycle.
    powered: [bool; 2],
    /// The PROFIdrive-style profile on axis A (issue 17).
    profile: profile::Profile,
    /// A frame arrived since the profile last took the receive telegram:
    /// the next control cycle decodes and applies it and builds the
    /// response (issue 36: the profile per telegram, not per cycle).
    telegram_new: bool,
    /// Axis A's mode display (6061h) when the profile last ran: a change
    /// (the core took the mode a telegram bound) runs it again (P-086).
    profile_mode: Option<i64>,
    /// The A75/A69 actions (E-140), A75 written through the parameter
    /// access (PKW, record 0xB02E): the motor actions on PROFINET (issue 35).
    actions: Actions,
    /// The profile's PKW write count when the actions last looked at A75.
    actions_seen_writes: u32,
}

impl<F: Flash> PnDrive<F, NoRecords> {
    /// Powers the drive on: defaults, then the newest saved set from
    /// `flash`; the device gets its name and IP from the objects
    /// ([`settings::device_config`]) and the rest from `hw`.
    pub fn new(flash: F, hw: Hardware) -> PnDrive<F, NoRecords> {
        PnDrive::with_hook(flash, hw, NoRecords)
    }

    /// [`new`](PnDrive::new) built in `slot` (a board's static): see
    /// [`init_with_hook`](PnDrive::init_with_hook).
    pub fn init(
        slot: &mut MaybeUninit<PnDrive<F, NoRecords>>,
        flash: F,
        hw: Hardware,
    ) -> &mut PnDrive<F, NoRecords> {
        PnDrive::init_with_hook(slot, flash, hw, NoRecords)
    }
}

impl<F: Flash, H: RecordHook> PnDrive<F, H> {
    /// [`new`](PnDrive::new) with a device that serves the profile's
    /// records through `hook`.
    pub fn with_hook(flash: F, hw: Hardware, hook: H) -> PnDrive<F, H> {
        let mut slot = MaybeUninit::uninit();
        PnDrive::init_with_hook(&mut slot, flash, hw, hook);
        // SAFETY: `init_with_hook` wrote every field of `slot`.
        #[allow(unsafe_code)]
        unsafe {
            slot.assume_init()
        }
    }

    /// [`with_hook`](PnDrive::with_hook) built in place: each part is
    /// written into `slot`'s field as it is made, so the caller's frame
    /// never holds a whole drive (about 50 KiB) beside its parts. The board
    /// images build their static drive with it: built by value and moved,
    /// the drive took an 86 KiB frame in `init`, more than the stack a
    /// board leaves (issue 36).
    #[allow(unsafe_code)]
    pub fn init_with_hook(
        slot: &mut MaybeUninit<PnDrive<F, H>>,
        flash: F,
        hw: Hardware,
        hook: H,
    ) -> &mut PnDrive<F, H> {
        let p = slot.as_mut_ptr();
        // SAFETY (every block below): `p` points to `slot`'s storage, valid
        // for writes and aligned; each field is written exactly once through
        // `addr_of_mut!` (no reference to uninitialised memory is made), and
        // a reference to a field is taken only after that field was written.
        // Every field is written before `assume_init_mut`.
        let (objects, store) = unsafe {
            addr_of_mut!((*p).objects).write(DriveObjects::new());
            addr_of_mut!((*p).store).write(ParamStore::new(flash));
            (&mut *addr_of_mut!((*p).objects), &mut *addr_of_mut!((*p).store))
        };
        let (startup, im, kept) = settings::load(store, objects);
        let active = objects.get(A270, 0) != Ok(0);
        let hw = Hardware {
            im: im.unwrap_or(hw.im),
            ..hw
        };
        let config = settings::device_config(objects, hw);
        let axes = unsafe {
            addr_of_mut!((*p).axes).write([Axis::new(0), Axis::new(1)]);
            &*addr_of_mut!((*p).axes)
        };
        let [axis_a, _] = axes;
        let profile = profile::Profile::new(objects, axis_a);
        unsafe {
            addr_of_mut!((*p).profile).write(profile);
            addr_of_mut!((*p).device).write(Device::new(
                config,
                PnRecords {
                    pe: ProfiEnergy::default(),
                    app: DriveEnergy::default(),
                    inner: bmp_record::WithBmp {
                        bmp: bmp_record::BmpRecord::default(),
                        inner: scope_record::WithScope {
                            scope: None,
                            inner: hook,
                        },
                    },
                },
            ));
            addr_of_mut!((*p).startup).write(startup);
            addr_of_mut!((*p).active).write(active);
            addr_of_mut!((*p).dropped_inactive).write(0);
            addr_of_mut!((*p).temporary).write(Temporary::default());
            addr_of_mut!((*p).caches).write([AxisCache::new(), AxisCache::new()]);
            addr_of_mut!((*p).raised).write([None; 2]);
            addr_of_mut!((*p).exchanged).write(false);
            addr_of_mut!((*p).powered).write([false; 2]);
            addr_of_mut!((*p).telegram_new).write(true);
            addr_of_mut!((*p).profile_mode).write(None);
            addr_of_mut!((*p).actions).write(Actions::by_parameter_access());
            addr_of_mut!((*p).actions_seen_writes).write(0);
        }
        // SAFETY: every field of `PnDrive` was written above.
        let drive = unsafe { slot.assume_init_mut() };
        if let Some(k) = kept {
            drive.device.set_snmp(k);
        }
        drive.prepare_axes();
        let [axis, _] = &drive.axes;
        drive.profile.warm_up(&drive.objects, axis);
        drive
    }

    /// The axes' caches of the control cycle and their configuration built
    /// here, outside it, when the configuration moved (start-up; a record,
    /// I&M or DCP write in the frame just received): the next control cycle
    /// reads only the set-points (issue 36). Cheap when nothing changed (a
    /// compare per axis: this runs in the eth task, whose hold of the drive
    /// blocks the control cycle).
    fn prepare_axes(&mut self) {
        for (axis, cache) in self.axes.iter_mut().zip(self.caches.iter_mut()) {
            axis.prepare(cache, &mut self.objects);
        }
        // a trace armed by a record write in this frame: its channels'
        // accesses here, not in the control cycle's first sample
        if let Some(scope) = self.device.hook_mut().inner.inner.scope.as_mut() {
            scope.prepare(&self.objects);
        }
    }

    /// The profile's part of [`prepare_axes`](Self::prepare_axes), after a
    /// frame and before it: the configuration values the receive telegram
    /// carries written ahead, the A279 unit choices and the prepared
    /// accesses of the telegram's entries brought to the configuration in
    /// force, so the next control cycle finds them current
    /// ([`profile::Profile::prepare`], issue 36).
    fn prepare_profile(&mut self) {
        let (slot, _) = self.data_slots();
        let frame = slot.and_then(|s| self.device.output_data(s));
        let [axis, _] = &mut self.axes;
        self.profile.prepare(frame, &mut self.objects, axis);
    }

    /// The PROFINET device.
    pub fn device(&self) -> &Device<PnRecords<H>> {
        &self.device
    }

    /// The PROFINET device, mutable (input data, link state).
    pub fn device_mut(&mut self) -> &mut Device<PnRecords<H>> {
        &mut self.device
    }

    /// The object dictionary.
    pub fn objects(&self) -> &DriveObjects {
        &self.objects
    }

    /// The object dictionary, mutable.
    pub fn objects_mut(&mut self) -> &mut DriveObjects {
        &mut self.objects
    }

    /// The axes.
    pub fn axes(&self) -> &[Axis; 2] {
        &self.axes
    }

    /// The axes, mutable.
    pub fn axes_mut(&mut self) -> &mut [Axis; 2] {
        &mut self.axes
    }

    /// The period of the control cycle: A150 (the cycle the axes integrate
    /// with, C-144), [`A150_FALLBACK_US`] while A150 holds no allowed cycle
    /// time. PROFINET has no SYNC0: the board's timer runs free at it.
    pub fn control_period(&self) -> Nanos {
        let a150_ns = self
            .objects
            .get(A150, 0)
            .ok()
            .and_then(|us| u32::try_from(us.saturating_mul(1000)).ok())
            .unwrap_or(0);
        Nanos::from_ns(u64::from(
            motion::cycle::application_cycle_ns(a150_ns).unwrap_or(A150_FALLBACK_US * 1000),
        ))
    }

    /// Whether the saved set was loaded at start.
    pub fn startup(&self) -> Startup {
        self.startup
    }

    /// The parameter flash (power-cycle simulation, fault injection).
    pub fn flash_mut(&mut self) -> &mut F {
        self.store.flash_mut()
    }

    /// Powers off: gives the flash back (RAM values are lost).
    pub fn into_flash(self) -> F {
        self.store.into_inner()
    }

    /// PROFINET active (A270) as in force: on only if it was 1 at start and
    /// has not read 0 since.
    pub fn profinet_active(&mut self) -> bool {
        if self.active && self.objects.get(A270, 0) == Ok(0) {
            self.active = false;
        }
        self.active
    }

    /// Frames dropped unseen because PROFINET is off.
    pub fn dropped_inactive(&self) -> u32 {
        self.dropped_inactive
    }

    /// Writes the persistent values to the store now (Save; A00\[1\]/\[2\]
    /// show progress and result as on EtherCAT). A name or IP suite DCP set
    /// temporarily is saved as its default. `false` when the store failed
    /// (the previous set is still intact).
    pub fn save(&mut self) -> bool {
        let mut name = [0u8; NAME_LEN];
        let name_len = if self.temporary.name {
            let n = settings::name_bytes(&mut self.objects, &mut name);
            settings::write_name(&mut self.objects, &NameOfStation::EMPTY);
            Some(n)
        } else {
            None
        };
        let ip = if self.temporary.ip {
            let s = settings::stored_ip(&self.objects);
            settings::write_ip(&mut self.objects, IpSuite::UNSET);
            Some(s)
        } else {
            None
        };
        let mut image = [0u8; STORED_BYTES];
        // the parameter image, then I&M1…4 (P-039)
        let trailer = settings::im_trailer(self.device.cm().im_data());
        // then the SNMP agent's sysContact/sysName/sysLocation (P-038)
        let block = settings::snmp_block(self.device.snmp());
        let len = self.objects.persistent_image(&mut image).ok().and_then(|n| {
            image.get_mut(n..n + block.len())?.copy_from_slice(&block);
            let n = n + block.len();
            image.get_mut(n..n + trailer.len())?.copy_from_slice(&trailer);
            Some(n + trailer.len())
        });
        if let Some(n) = name_len {
            let _ = self.objects.set_bytes(A271, 0, name.get(..n).unwrap_or(&[]));
        }
        if let Some(s) = ip {
            settings::write_ip(&mut self.objects, s);
        }
        let saved = len
            .and_then(|n| image.get(..n))
            .is_some_and(|img| self.store.save(img, LAYOUT_HASH).is_ok());
        // A00[0] back to 0 (done), [1] 100 %, [2] the result, as on EtherCAT
        let _ = self.objects.set(A00, 1, 0);
        let _ = self.objects.set(A00, 2, 100);
        let _ = self.objects.set(A00, 3, if saved { 0 } else { 1 });
        saved
    }

    /// A received Ethernet frame at `now`; answers go out through `tx`.
    /// Returns the device's events the application acts on (DCP signal, AR
    /// changes; name and IP are already written and saved), one at a time
    /// through `on_event`. While PROFINET is off the frame is dropped.
    pub fn receive(
        &mut self,
        now: Nanos,
        frame: &[u8],
        tx: &mut impl FnMut(&[u8]),
        on_event: &mut impl FnMut(&DeviceEvent),
    ) {
        if !self.profinet_active() {
            self.dropped_inactive = self.dropped_inactive.saturating_add(1);
            return;
        }
        self.energy_inputs();
        self.device.receive(now, frame, tx);
        // any frame may be the new receive telegram (or a record that
        // changed what the profile reads): the profile runs once more
        self.telegram_new = true;
        self.serve_bmp();
        self.events(on_event);
        self.prepare_profile();
        self.prepare_axes();
    }

    /// A parameter request written to record 0xB02E in the frame just
    /// received, served at once (P-206).
    fn serve_bmp(&mut self) {
        let Some((req, n)) = self.device.hook_mut().inner.bmp.take_request() else {
            return;
        };
        let mut out = [0u8; bmp_record::MAX_BYTES];
        let [a, _] = &mut self.axes;
        let hook = &mut self.device.hook_mut().inner;
        let len = self.profile.serve_bmp(
            req.get(..n).unwrap_or(&[]),
            &mut self.objects,
            a,
            &mut hook.inner,
            &mut out,
        );
        hook.bmp.set_response(out.get(..len).unwrap_or(&[]));
        self.serve_actions();
        // a save asked by this request is done before its response is read
        self.serve_saves();
    }

    /// The actions after a parameter access (A75 written: an action starts
    /// or stops) and every control cycle while a motor action measures
    /// (A69's progress and result): E-140 on PROFINET.
    fn serve_actions(&mut self) {
        let fx = self.actions.serve(&mut self.objects);
        for (axis, clear) in self.axes.iter_mut().zip(fx.clear_reference) {
            if clear {
                axis.clear_reference();
            }
        }
    }

    /// The device's timers at `now`; returns when to call again at the
    /// latest. While PROFINET is off the timers run and nothing is sent.
    pub fn poll(
        &mut self,
        now: Nanos,
        tx: &mut impl FnMut(&[u8]),
        on_event: &mut impl FnMut(&DeviceEvent),
    ) -> Nanos {
        self.energy_inputs();
        let next = if self.profinet_active() {
            self.device.poll(now, tx)
        } else {
            self.device.poll(now, &mut |_: &[u8]| {})
        };
        self.events(on_event);
        next
    }

    fn events(&mut self, on_event: &mut impl FnMut(&DeviceEvent)) {
        if self.device.exchanging() {
            self.exchanged = true;
        }
        let mut save = false;
        while let Some(e) = self.device.take_event() {
            match &e {
                DeviceEvent::Rt(RtEvent::ArLost(_)) => {
                    self.raise_ar_lost();
                    self.device.hook_mut().pe.end_pause();
                }
                DeviceEvent::Cm(CmEvent::Released(_) | CmEvent::Aborted(..)) => {
                    // the controller that paused is gone
                    let pe = &mut self.device.hook_mut().pe;
                    pe.end_pause();
                    pe.clear_response();
                }
                DeviceEvent::Dcp(d) => save |= self.apply_dcp(d),
                // I&M1…4 are kept with the parameters (P-039)
                DeviceEvent::Cm(CmEvent::ImWritten(_)) => save = true,
                // so are the SNMP agent's writable strings (P-038)
                DeviceEvent::SnmpChanged => save = true,
                _ => {}
            }
            on_event(&e);
        }
        if save {
            // the result shows in A00[2]
            let _ = self.save();
        }
    }

    /// PROFIenergy's view of the drive (A275, the power stages), before the
    /// device sees a frame or a timer; A275 = 0 ends a pause.
    fn energy_inputs(&mut self) {
        let enabled = self.objects.get(A275, 0) == Ok(1);
        let idle = !self.powered.contains(&true);
        let hook = self.device.hook_mut();
        hook.app = DriveEnergy { enabled, idle };
        if !enabled {
            hook.pe.end_pause();
        }
    }

    /// Whether the PROFIenergy pause (power stage off, [`energy`]) is in force.
    pub fn energy_paused(&self) -> bool {
        self.device.hook().pe.paused()
    }

    /// Writes a DCP change into the objects; returns whether to save.
    fn apply_dcp(&mut self, e: &DcpEvent) -> bool {
        match e {
            DcpEvent::NameOfStation { name, permanent } => {
                settings::write_name(&mut self.objects, name);
                self.temporary.name = !permanent;
                true
            }
            DcpEvent::IpSuite { suite, permanent } => {
                settings::write_ip(&mut self.objects, *suite);
                self.temporary.ip = !permanent;
                true
            }
            DcpEvent::ResetToFactory(ResetMode::All) => {
                self.objects.restore_defaults();
                self.temporary = Temporary::default();
                self.device.set_im_data(ImData::default());
                self.device.set_snmp(snmp::Agent::default());
                true
            }
            // name and IP follow as permanent Sets; I&M1…4 are cleared here
            DcpEvent::ResetToFactory(ResetMode::Communication) => {
                self.device.set_im_data(ImData::default());
                self.device.set_snmp(snmp::Agent::default());
                true
            }
            DcpEvent::ResetToFactory(ResetMode::ApplicationData) => {
                self.restore_application_defaults();
                true
            }
            DcpEvent::Signal { .. } => false,
        }
    }

    /// Every parameter default except the PROFINET parameters A270…A278.
    fn restore_application_defaults(&mut self) {
        let mut name = [0u8; NAME_LEN];
        let n = settings::name_bytes(&mut self.objects, &mut name);
        let mut kept = [0i64; PROFINET_PARAMS.len()];
        for (v, index) in kept.iter_mut().zip(PROFINET_PARAMS) {
            *v = self.objects.get(index, 0).unwrap_or(0);
        }
        self.objects.restore_defaults();
        for (v, index) in kept.iter().zip(PROFINET_PARAMS) {
            if index != A271 {
                let _ = self.objects.set(index, 0, *v);
            }
        }
        let _ = self.objects.set_bytes(A271, 0, name.get(..n).unwrap_or(&[]));
    }

    /// the AR is gone; both axes run their fault reaction.
    fn raise_ar_lost(&mut self) {
        let event = motion::Event {
            number: u16::from(AR_LOST_EVENT),
            cause: AR_LOST_CAUSE,
        };
        for axis in self.axes.iter_mut() {
            axis.raise_event(event);
        }
    }
}
