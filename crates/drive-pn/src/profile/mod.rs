//! The PROFIdrive-style profile of the Metronix manual on the drive (issue
//! 17): the thin personality spec §16 describes, over the drive core that
//! the CiA 402 side uses too.
//!
//! Once per receive telegram (issue 36: the control cycle after a frame
//! arrived, after axis A's mode display 6061h changed, and every cycle while
//! a homing run the profile started is active; the cycles between run the
//! core only, `PnDrive::control_cycle`), with valid output data from the
//! controller:
//! 1. the receive telegram ([`profidrive::telegram`]) writes its entries
//!    into the objects (RAM only, P-067) through [`access::DriveAccess`]
//!    (PNUs with their PROFINET units, CANopen objects as they are);
//!    telegram 0 selects positioning, telegram 1 speed control (P-051,
//!    P-052: 6060h = 1 / 2), telegrams 2 and 3 keep the mode (PNU 1500);
//! 2. the PKW request is served ([`profidrive::pkw`]);
//! 3. CW1 is applied last (P-066): bits 0–3 and 7 are the CiA 402
//!    controlword of axis A (the core's device state machine); in
//!    positioning the task bits go to the core's record positioning
//!    ([`drive_core::axis::RecordCommand`]) and bit 11 runs the core's
//!    homing (6060h = 6, the method PNU 1050 latched at the start edge,
//!    Q-11); in speed control bits 4–6 are the vl mode's ramp bits.
//!
//! After the axes' cycle the response telegram is built into the input
//! data: ZSW1 from the axis' state and statusword ([`status`]).

pub mod access;
pub mod lookup;
pub mod pnu;
pub mod status;
pub mod telegram_config;
pub mod unit_choice;
pub mod units;

use access::{DriveAccess, OwnValues};
use drive_core::axis::{Axis, RecordCommand};
use drive_core::{DriveObjects, LiveValues, NoLive};
use lookup::{Core, CoreSlots, Handle, PreparedCache, WrittenConfig};
use motion::units::UnitProfile;
use profidrive::cw1::{Context, Cw1Decoder, Mode, ModeCommands};
use profidrive::pkw::Pkw;
use profidrive::telegram::compiled::Compiled;
use profidrive::telegram::{ModeBinding, Telegrams, MAX_TELEGRAM_BYTES};
use units::UnitsCache;

/// The parameter access over the profile `$p`'s own parts (a macro, not a
/// method: the borrows stay per field, beside `$p.telegrams`).
macro_rules! drive_access {
    ($p:expr, $objects:expr, $axis:expr, $live:expr) => {
        DriveAccess {
            objects: $objects,
            axis: $axis,
            units: &$p.units,
            user_units: &mut $p.user_units,
            prepared: &mut $p.prepared,
            core: &$p.core,
            written: &mut $p.written,
            own: &mut $p.own,
            live: $live,
            pending: None,
        }
    };
}

/// 6040h bits 4–6: the vl ramp bits, the pp / homing "start" bit.
const BITS_4_6: u16 = 0x0070;
/// 6040h bit 4.
const BIT_4: u16 = 0x0010;

/// What the profile keeps between cycles.
pub struct Profile {
    telegrams: Option<Telegrams>,
    pkw: Pkw,
    pkw_response: [u8; 8],
    cw1: Cw1Decoder,
    units: UnitProfile,
    /// A279 as last looked at.
    unit_choice: unit_choice::UnitChoice,
    user_units: UnitsCache,
    prepared: PreparedCache,
    core: CoreSlots,
    own: OwnValues,
    /// The response telegram to send.
    response: Option<u8>,
    /// A homing run the profile started (bit 11) is active.
    homing: bool,
    /// Frames with an unknown identifier or another warning.
    warnings: u32,
    /// The configuration generation [`prepare`](Self::prepare) last
    /// brought the units and prepared accesses to.
    prepared_at: Option<u32>,
    /// The telegrams' entries resolved into handles (issue 36), compiled
    /// where the telegrams are configured and in [`prepare`](Self::prepare)
    /// when the layouts changed.
    handles: Compiled<Handle>,
    /// The configuration entries the telegram wrote last (issue 36).
    written: WrittenConfig,
}

impl Profile {
    /// The profile with the Example Function block's telegrams (P-071…P-074)
    /// and the default units (P-207).
    pub fn new(objects: &mut DriveObjects, axis: &Axis) -> Profile {
        let stored = telegram_config::stored(objects);
        // built in place, the telegrams configured through its own fields
        // (no second copy of the caches on the stack)
        let mut p = Profile {
            telegrams: None,
            pkw: Pkw::new(),
            pkw_response: [0; 8],
            cw1: Cw1Decoder::new(),
            units: UnitProfile::default_profile(),
            unit_choice: unit_choice::UnitChoice::default(),
            user_units: UnitsCache::new(),
            prepared: PreparedCache::new(),
            core: CoreSlots::new(),
            own: OwnValues::default(),
            response: None,
            homing: false,
            warnings: 0,
            prepared_at: None,
            handles: Compiled::new(),
            written: WrittenConfig::new(),
        };
        let access = drive_access!(p, objects, axis, &mut NoLive);
        // the stored configuration (A280, P-069), else the FB's
        if let Some(set) = stored {
            let mut t = Telegrams::new();
            if t.configure(&set, &access).is_ok() {
                p.telegrams = Some(t);
            }
        }
        if p.telegrams.is_none() {
            p.telegrams = Telegrams::with_defaults(&access).ok();
        }
        drop(access);
        if let Some(t) = &p.telegrams {
            p.own.edit = telegram_config::TelegramEdit::of(t.set());
        }
        p.compile_handles(objects, axis);
        p
    }

    /// The telegrams' entries resolved into handles when the layouts
    /// changed since they were (a compare otherwise): where the telegrams
    /// are configured and where the next cycle is prepared, not in the
    /// control cycle (issue 36). A handle holds no axis (an object's index
    /// is mapped at the access, as on the address path).
    fn compile_handles(&mut self, objects: &mut DriveObjects, axis: &Axis) {
        let Some(telegrams) = self.telegrams.as_ref() else {
            return;
        };
        if self.handles.is_for(telegrams) {
            return;
        }
        let mut access = drive_access!(self, objects, axis, &mut NoLive);
        self.handles.compile(telegrams, &mut access);
    }

    /// Whether the telegram configuration took (the catalogue holds every
    /// entry of the defaults).
    pub fn configured(&self) -> bool {
        self.telegrams.is_some()
    }

    /// The telegrams (layouts, live view).
    pub fn telegrams(&self) -> Option<&Telegrams> {
        self.telegrams.as_ref()
    }

    /// The PROFINET units in force (A279, P-208).
    pub fn units(&self) -> &UnitProfile {
        &self.units
    }

    /// The profile's own values (CW1, ZSW1, the homing method, …).
    pub fn own(&self) -> &OwnValues {
        &self.own
    }

    /// Axis A's mode display (6061h) as the core shows it.
    pub fn mode_display(&self, objects: &DriveObjects, axis: &Axis) -> i64 {
        self.core.get(objects, axis, Core::ModeDisplay)
    }

    /// A homing run the profile started (CW1 bit 11) is active.
    pub fn homing(&self) -> bool {
        self.homing
    }

    /// Frames that raised a warning (unknown identifier, length, refused
    /// entry).
    pub fn warnings(&self) -> u32 {
        self.warnings
    }

    /// A save asked through PNU 971: taken by the drive, which saves and
    /// reports back with [`save_done`](Self::save_done).
    pub fn take_save_request(&mut self) -> bool {
        core::mem::take(&mut self.own.save_requested)
    }

    /// PKW write requests served so far (wrapping; [`Pkw::writes`]).
    pub fn parameter_writes(&self) -> u32 {
        self.pkw.writes()
    }

    /// The save asked through PNU 971 is over (PNU 971 reads 0 again).
    pub fn save_done(&mut self) {
        self.own.saving = false;
    }

    /// At start-up, outside the control cycle (issue 36): the core
    /// entries resolved (the A279 unit choices are not read ahead: reading
    /// them here moved which entries the dictionary's lookup memo holds and
    /// cost telegram 0 about 8,000 instructions per frame on QEMU).
    pub fn warm_up(&mut self, objects: &DriveObjects, axis: &Axis) {
        self.core.resolve(objects, axis);
    }

    /// After a frame, in the bus task (issue 36: outside the control
    /// cycle), when the configuration moved: the unit choices A279 looked
    /// at (`refresh_units`, as the next telegram's
    /// first step would), the core entries resolved, the axis' user units
    /// read and the prepared accesses the telegrams used brought to the
    /// configuration in force. The control cycle's telegram then finds
    /// them current; what it computes is the same.
    ///
    /// With `frame`, the OUT module's data the next control cycle applies:
    /// its entries whose write is a configuration change (the vl ramps of
    /// telegram 1, PNU 1011.2 → 6048h/6049h) are written here first, when
    /// their bytes differ from the frame applied last or the configuration
    /// moved since (a value changed behind the telegram), so the axes'
    /// preparation after this reads the snapshot they make and the control
    /// cycle's telegram writes them unchanged (no new configuration
    /// generation inside it). Nothing else of the telegram (CW1, PKW, mode,
    /// set-points, records) is applied ahead.
    pub fn prepare(&mut self, frame: Option<&[u8]>, objects: &mut DriveObjects, axis: &mut Axis) {
        let before = objects.config_generation();
        let moved = self.prepared_at != Some(before);
        if moved {
            self.refresh_units(objects, axis);
            self.core.resolve(objects, axis);
        }
        if let (Some(frame), Some(telegrams)) = (frame, self.telegrams.as_ref()) {
            let mut access = drive_access!(self, objects, axis, &mut NoLive);
            telegrams.write_ahead(frame, &mut access, moved, |a, addr| a.is_config_entry(addr));
        }
        let g = objects.config_generation();
        if self.prepared_at != Some(g) {
            if g != before {
                // the write ahead moved the configuration: A279 again
                self.refresh_units(objects, axis);
            }
            let _ = self.user_units.get(objects, axis);
            self.prepared.refresh(objects);
            self.prepared_at = Some(g);
        }
        self.compile_handles(objects, axis);
    }

    /// The unit choices A279 (P-212): new units once they convert; a
    /// setting that does not raises 22-4 and the units stay.
    fn refresh_units(&mut self, objects: &DriveObjects, axis: &mut Axis) {
        match self.unit_choice.refresh(objects) {
            Ok(Some(u)) => {
                self.units = u;
                self.user_units.forget_conversions();
            }
            Ok(None) => {}
            Err(_) => axis.raise_event(unit_choice::UNIT_OVERFLOW),
        }
    }

    /// Step 1–3 of a cycle: the received OUT module's data `frame`.
    pub fn receive(&mut self, frame: &[u8], objects: &mut DriveObjects, axis: &mut Axis) {
        self.receive_with(frame, objects, axis, &mut NoLive);
    }

    /// [`receive`](Self::receive) with `live` answering the live entries
    /// the telegram's PKW reaches (the scope's group T,
    /// [`crate::scope_record`]).
    pub fn receive_with(
        &mut self,
        frame: &[u8],
        objects: &mut DriveObjects,
        axis: &mut Axis,
        live: &mut dyn LiveValues,
    ) {
        self.refresh_units(objects, axis);
        let Some(telegrams) = self.telegrams.as_mut() else {
            return;
        };
        self.core.resolve(objects, axis);
        let core = &self.core;
        // the access ends in place at the block's end (issue 36: `drop(access)`
        // moved its 92 bytes first)
        let (speed_limit, torque_limit, record_command) = {
            let mut access = drive_access!(self, objects, axis, live);
            let rx = telegrams.apply_receive_compiled(frame, &mut access, &self.handles);
            // the telegram's record fields stored before anything reads them
            access.flush_record();
            if !rx.warnings.is_empty() {
                self.warnings = self.warnings.saturating_add(1);
            }
            if rx.telegram.is_none() {
                // an unknown identifier changes nothing
                return;
            }
            self.response = rx.response;
            let binding = match rx.mode {
                ModeBinding::Positioning => Some(1),
                ModeBinding::Speed => Some(2),
                ModeBinding::None => None,
            };
            if let Some(code) = binding {
                let now = core.get(access.objects, axis, Core::Mode);
                // homing runs inside positioning (6060h = 6 while it runs)
                if !(code == 1 && now == 6 && self.homing) && now != code {
                    core.set(access.objects, axis, Core::Mode, code);
                }
            }
            if let Some(req) = rx.pkw {
                self.pkw_response = self.pkw.step(req, &mut access);
            }
            // a telegram select or apply the PKW step asked for
            if access.own.edit.request.is_some() {
                let mut edit = access.own.edit;
                telegram_config::serve(&mut edit, telegrams, &mut access);
                access.own.edit = edit;
            }
            if let Some(cw1) = rx.cw1 {
                access.own.cw1 = cw1;
            }
            // the mode this frame's CW1 counts in: the one its telegram binds
            // (6060h, set above, which the core takes at its next cycle, where
            // CW1 acts) or else 6061h; the display alone lagged a cycle behind
            // a telegram switch, so the first positioning cycle ran without a
            // record command and a jog bit of the next frame was no edge (P-086)
            let shown = core.get(access.objects, axis, Core::ModeDisplay);
            let display = match binding {
                Some(1) if matches!(shown, 1 | 6 | -1) => shown,
                Some(code) => code,
                None => shown,
            };
            let mode = match Ok::<i64, ()>(display) {
                Ok(1 | 6 | -1) => Mode::Positioning,
                Ok(2 | 3) => Mode::Speed,
                _ => Mode::Other,
            };
            let t = self.cw1.decode(
                rx.cw1,
                Context {
                    mode,
                    homing_active: self.homing,
                },
            );
            if !t.evaluated {
                return;
            }
            let mut controlword = t.controlword;
            let record_command = match t.mode {
                ModeCommands::Positioning(p) => {
                    if p.homing_start && !self.homing {
                        if let Some(m) = access::core_homing_method(access.own.homing_method) {
                            let _ = access.objects.set(axis.cia402_index(0x6098), 0, i64::from(m));
                            let _ = access.objects.set(axis.cia402_index(0x6060), 0, 6);
                            self.homing = true;
                        }
                    }
                    if p.homing_cancel {
                        self.homing = false;
                    }
                    if self.homing {
                        // 6040h bit 4 starts and holds the homing run (its rising
                        // edge once the axis is in homing mode); clearing it ends
                        // the run without an error
                        if display == 6 {
                            controlword |= BIT_4;
                        }
                        None
                    } else {
                        Some(RecordCommand {
                            enable: !p.cancel,
                            proceed: !p.intermediate_stop,
                            start: p.start,
                            relative: p.relative,
                            immediate: p.immediate,
                            jog_positive: p.jog_positive,
                            jog_negative: p.jog_negative,
                            setup_mode: false,
                        })
                    }
                }
                ModeCommands::Speed(s) => {
                    // vl: bit 4 enable ramp, bit 5 unlock ramp, bit 6 use the
                    // set-point (Q-04: PROFIdrive polarity, 1 = the ramp runs)
                    controlword &= !BITS_4_6;
                    if s.rfg_enable {
                        controlword |= 0x0010;
                    }
                    if !s.rfg_freeze {
                        controlword |= 0x0020;
                    }
                    if s.setpoint_enable {
                        controlword |= 0x0040;
                    }
                    None
                }
                ModeCommands::Other => None,
            };
            core.set(access.objects, axis, Core::Controlword, i64::from(controlword));
            // torque control: 2416h.02 (the PROFINET velocity unit, rpm by
            // default) is the speed limit in both directions (P-130)
            let speed_limit = (display == 4).then(|| {
                let bus = i64::from(access.own.speed_limit);
                self.units
                    .velocity
                    .from_bus(bus)
                    .map_or(f32::MAX, |v| v.unsigned_abs() as f32)
            });
            // speed control: 2415h.02 (mA) limits the torque through the motor's
            // rated current (P-133); 0 sets no limit
            let current = access.own.current_limit_ma;
            let torque_limit = (matches!(display, 2 | 3) && current > 0).then(|| {
                let rated = u64::from(axis.motor().rated_current_ma().max(1));
                (u64::from(current.unsigned_abs()) * 1000 / rated).min(u64::from(u16::MAX - 1)) as u16
            });
            (speed_limit, torque_limit, record_command)
        };
        axis.set_torque_mode_speed_limit(speed_limit);
        axis.set_torque_limit_per_mille(torque_limit);
        axis.set_record_command(record_command);
    }

    /// Serves a PROFIdrive parameter request (record 0xB02E, P-206) over
    /// the same parameter access as the PKW channel; the response goes
    /// into `out`, its length is returned (0: nothing to answer, the
    /// request shorter than its header); `live` answers the live entries
    /// (the scope's group T, [`crate::scope_record`]).
    pub fn serve_bmp(
        &mut self,
        req: &[u8],
        objects: &mut DriveObjects,
        axis: &Axis,
        live: &mut dyn LiveValues,
        out: &mut [u8],
    ) -> usize {
        let mut access = drive_access!(self, objects, axis, live);
        profidrive::bmp::serve(req, &mut access, out).unwrap_or(0)
    }

    /// After the cycle: ends a finished homing run (back to positioning)
    /// and builds the response telegram into `buf` (the IN module's
    /// length); returns the bytes written, `None` before any telegram.
    pub fn respond(&mut self, objects: &mut DriveObjects, axis: &Axis, buf: &mut [u8]) -> Option<usize> {
        self.core.resolve(objects, axis);
        if self.homing {
            let sw = self.core.get(objects, axis, Core::Statusword);
            let mode = self.core.get(objects, axis, Core::ModeDisplay);
            // homing attained (bit 12) or an error (bit 13): the run is over
            if mode == 6 && sw & 0x3000 != 0 {
                self.homing = false;
                let _ = objects.set(axis.cia402_index(0x6060), 0, 1);
            }
        }
        self.own.zsw1 = status::zsw1(objects, &self.core, axis, self.cw1.last(), self.homing);
        let n = self.response?;
        let telegrams = self.telegrams.as_mut()?;
        let mut access = drive_access!(self, objects, axis, &mut NoLive);
        // straight into the module's data (the telegram is cut to it or
        // zero-padded up to it)
        let len = buf.len().min(MAX_TELEGRAM_BYTES);
        let out = buf.get_mut(..len)?;
        let tx = telegrams.build_response_compiled(n, &mut access, self.pkw_response, out, &self.handles)?;
        if !tx.warnings.is_empty() {
            self.warnings = self.warnings.saturating_add(1);
        }
        Some(len)
    }
}

#[cfg(test)]
mod pnu_doc;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_handles;
