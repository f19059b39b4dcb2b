//! Actions over the fieldbus (spec §14; E-060, E-140…E-142): per axis the
//! action control byte A75 in the RxPDO and the action status word A69 in the
//! TxPDO.
//!
//! A75: bit 0 = Execute, bits 1–4 = the action selector (the bit position is
//! not in the manual: spec §14, our choice). A rising Execute starts the
//! selected action if its precondition on the axis's device state E48 holds;
//! the master clears Execute when A69 shows the end, and A69 returns to idle.
//!
//! A69 (layout not in the manual either, docs/conformance.md): bits 0–7 the
//! progress in % (100 at the end), bits 8–11 the selector of the action shown,
//! bits 12–15 its [`state`].
//!
//! The motor actions that need the power stage (B40 test phase, B41
//! calibrate motor, B42/B49 optimise current controller, B43 test winding,
//! B300 test brake, B301 grind brake, B44 identify mechanics:
//! [`crate::tuning`]) start
//! in Ready to switch on and run once the master enabled the axis (E-141;
//! B43 at once, without an enable): their measurement runs in the
//! control cycle ([`Actions::control`], which replaces the axis' command),
//! their progress and end show here; Execute low stops them.
//!
//! Action activation (E-142) is the commissioning option "action activation"
//! of the axis: here, A75 mapped in the axis's RxPDO channel (1600h for axis A,
//! 1601h for axis B), which is what that option sets up. A75 written over SDO,
//! or mapped in another channel, starts nothing ([`state::NOT_ACTIVATED`]).
//! On PROFINET ([`Actions::by_parameter_access`]) there is no such option and
//! no RxPDO: A75 is written through the parameter access (PKW in the
//! telegram, record 0xB02E), which is itself the activation.

use crate::axis::{sqrt, AxisCommand, AxisIo};
use crate::params::{
    A150, A150_FALLBACK_US, B05, B10, B300, B301, B40, B41, B42, B43, B44, B45, B46, B47, B48, B52, B53, B62,
    C31, C32, E48, I20,
};
use crate::tuning::align::{AlignOutcome, Alignment};
use crate::tuning::brake::{BrakeOutcome, BrakeTest};
use crate::tuning::grind::{GrindBrake, GrindFigures, GrindOutcome};
use crate::tuning::mechanics::{MechanicsOutcome, MechanicsTest, BACK_INC, TRAVEL_INC};
use crate::tuning::phase::{PhaseOutcome, PhaseTest};
use crate::tuning::winding::{WindingOutcome, WindingTest};
use crate::tuning::{CurrentTuning, Outcome};
use crate::{parameter_index, DriveObjects, AXIS_B_CIA402, AXIS_B_MANUFACTURER};

/// A75 control byte for actions (axis A; axis B + 8000h).
pub const A75: u16 = parameter_index(0, 75);
/// A69 status word for actions (axis A; axis B + 8000h).
pub const A69: u16 = parameter_index(0, 69);
/// A00 save values: \[1\] progress, \[2\] result (sub = element + 1).
const A00: u16 = parameter_index(0, 0);

/// A69 bits 12–15.
pub mod state {
    /// Nothing started (Execute low).
    pub const IDLE: u16 = 0;
    /// Started, not finished.
    pub const RUNNING: u16 = 1;
    /// Finished (progress 100 %).
    pub const DONE: u16 = 2;
    /// The precondition on E48 does not hold (E-141): not started.
    pub const REFUSED: u16 = 3;
    /// This drive cannot run the action (A37, I52: nothing to reset; B302:
    /// a second brake, S18: a safety module, neither of which it has): not
    /// started.
    pub const NOT_AVAILABLE: u16 = 4;
    /// Started and failed (e.g. the save found the store broken).
    pub const FAILED: u16 = 5;
    /// Action activation is off for the axis (E-142): not started.
    pub const NOT_ACTIVATED: u16 = 6;
    /// The selector names no action (0000b).
    pub const UNKNOWN: u16 = 7;
}

/// The actions of spec §14 by their 4-bit selector.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// 0001b, A00 save values.
    Save,
    /// 0010b, A09 restart.
    Restart,
    /// 0011b, A37 reset memorised values.
    ResetMemorised,
    /// 0100b, B300 test brake.
    TestBrake,
    /// 0101b, B301 grind brake.
    GrindBrake,
    /// 0110b, B302 grind brake 2.
    GrindBrake2,
    /// 0111b, I38 clear reference.
    ClearReference,
    /// 1000b, I52 delete limit-switch memory.
    DeleteLimitMemory,
    /// 1001b, S18 test brake (safety).
    TestBrakeSafety,
    /// 1010b, B40 test phase.
    TestPhase,
    /// 1011b, B41 calibrate motor.
    CalibrateMotor,
    /// 1100b, B42 optimise current controller.
    OptimiseCurrent,
    /// 1101b, B43 test winding.
    TestWinding,
    /// 1110b, B49 optimise current controller at standstill.
    OptimiseCurrentStandstill,
    /// 1111b (unused in the manual's table, ours), B44 identify mechanics
    /// ([`crate::tuning::mechanics`]).
    IdentifyMechanics,
}

impl Action {
    /// The action of selector `s` (bits 1–4 of A75); `None` for 0000b.
    pub const fn from_selector(s: u8) -> Option<Self> {
        Some(match s {
            0b0001 => Action::Save,
            0b0010 => Action::Restart,
            0b0011 => Action::ResetMemorised,
            0b0100 => Action::TestBrake,
            0b0101 => Action::GrindBrake,
            0b0110 => Action::GrindBrake2,
            0b0111 => Action::ClearReference,
            0b1000 => Action::DeleteLimitMemory,
            0b1001 => Action::TestBrakeSafety,
            0b1010 => Action::TestPhase,
            0b1011 => Action::CalibrateMotor,
            0b1100 => Action::OptimiseCurrent,
            0b1101 => Action::TestWinding,
            0b1110 => Action::OptimiseCurrentStandstill,
            0b1111 => Action::IdentifyMechanics,
            _ => return None,
        })
    }

    /// E-141: whether the action may start in device state `e48` (2 ready
    /// to switch on, 4 enabled, 7 quick stop).
    pub const fn may_start(self, e48: i64) -> bool {
        match self {
            Action::Save | Action::ResetMemorised | Action::ClearReference | Action::DeleteLimitMemory => {
                true
            }
            Action::Restart => e48 != 4 && e48 != 7,
            _ => e48 == 2,
        }
    }
}

/// What the caller does for the axes after [`Actions::serve`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Effects {
    /// Clear the axis's reference (I38), per axis.
    pub clear_reference: [bool; 2],
}

/// The running action of one axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Running {
    /// The save requested; done when A00 shows progress 100.
    Save,
    /// The restart requested; it ends with the restart.
    Restart,
    /// B42/B49 ([`AxisActions::tuning`]): runs in the control cycles.
    Tuning,
}

/// One axis's part: its last Execute bit, the running action, A69.
#[derive(Debug, Clone, Copy, Default)]
struct AxisActions {
    execute: bool,
    running: Option<Running>,
    status: u16,
    /// The motor action's measurement, started here and stepped by the
    /// control cycle ([`Actions::control`]).
    tuning: Option<Measurement>,
}

/// A motor action's part in the control cycle. (B44's windows make its
/// variant the largest; the unit lives in a static either way, one per
/// axis, no heap to box it in.)
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy)]
enum Measurement {
    /// B42/B49.
    Current(CurrentTuning),
    /// B41.
    Align(Alignment),
    /// B43.
    Winding(WindingTest),
    /// B40.
    Phase(PhaseTest),
    /// B300.
    Brake(BrakeTest),
    /// B301.
    Grind(GrindBrake),
    /// B44.
    Mechanics(MechanicsTest),
}

/// What activates the actions of an axis (E-142).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Activation {
    /// EtherCAT: A75 mapped in the axis's RxPDO channel (the commissioning
    /// option "action activation").
    #[default]
    RxPdo,
    /// PROFINET: A75 written through the parameter access (PKW, record
    /// 0xB02E); always active.
    ParameterAccess,
}

/// The action unit of both axes: the last Execute bits and what runs.
#[derive(Debug, Clone, Copy, Default)]
pub struct Actions {
    axes: [AxisActions; 2],
    activation: Activation,
}

fn offset(axis: usize) -> u16 {
    if axis == 0 {
        0
    } else {
        AXIS_B_MANUFACTURER
    }
}

/// A69's value.
const fn status(progress: u16, selector: u8, st: u16) -> u16 {
    progress | (selector as u16 & 0xF) << 8 | st << 12
}

impl Actions {
    /// Idle on both axes.
    pub const fn new() -> Self {
        const IDLE: AxisActions = AxisActions {
            execute: false,
            running: None,
            status: 0,
            tuning: None,
        };
        Self {
            axes: [IDLE; 2],
            activation: Activation::RxPdo,
        }
    }

    /// Idle on both axes, A75 taken from the parameter access (PROFINET:
    /// [`Activation::ParameterAccess`]).
    pub const fn by_parameter_access() -> Self {
        let mut a = Self::new();
        a.activation = Activation::ParameterAccess;
        a
    }

    /// Whether anything is shown or runs on either axis: Execute set, an
    /// action running or A69 not idle. A caller that serves A75 only after
    /// it was written (PROFINET: a PKW write) serves it every time while
    /// this holds.
    pub fn busy(&self) -> bool {
        self.axes
            .iter()
            .any(|a| a.execute || a.running.is_some() || a.tuning.is_some() || a.status != 0)
    }

    /// Whether a motor action runs in the control cycle on either axis (the
    /// caller then serves A69 every cycle, [`serve`](Self::serve)).
    pub fn measuring(&self) -> bool {
        self.axes.iter().any(|a| a.tuning.is_some())
    }

    /// A69 of `axis` as last set.
    pub fn status(&self, axis: usize) -> u16 {
        self.axes.get(axis).map_or(0, |a| a.status)
    }

    /// Whether action activation is on for `axis` (E-142): A75 of the axis
    /// mapped in its RxPDO channel.
    pub fn activated(objects: &DriveObjects, axis: usize) -> bool {
        let a75 = u32::from(A75 + offset(axis));
        let channel = 0x1600 + axis as u16;
        objects.mapping(channel).any(|m| m >> 16 == a75)
    }

    /// The control cycle's part of a running motor action on `axis` (B41,
    /// B42, B49): the axis' device state `e48` after its cycle and the
    /// cycle's inputs (the current loop's last report, the encoder) in; the
    /// command that replaces the axis' out (`None`: the axis' own). Call it
    /// once per control cycle after the axis' cycle.
    pub fn control(&mut self, axis: usize, e48: u8, io: &AxisIo) -> Option<AxisCommand> {
        match self.axes.get_mut(axis)?.tuning.as_mut()? {
            Measurement::Current(t) => t.cycle(e48, io.current.as_ref()),
            Measurement::Align(a) => a.cycle(e48, io.position_inc),
            Measurement::Winding(w) => w.cycle(e48, io.current.as_ref()),
            Measurement::Phase(p) => p.cycle(e48, io.position_inc, io.current.as_ref()),
            Measurement::Brake(b) => b.cycle(e48, io.position_inc),
            Measurement::Grind(g) => g.cycle(e48, io.position_inc),
            Measurement::Mechanics(m) => m.cycle(e48, io.position_inc),
        }
    }

    /// One pass after the RxPDO was decoded into `objects`: starts the
    /// action of a rising Execute, follows a running one, shows A69.
    pub fn serve(&mut self, objects: &mut DriveObjects) -> Effects {
        let mut fx = Effects::default();
        let activation = self.activation;
        for ((axis, a), clear) in self
            .axes
            .iter_mut()
            .enumerate()
            .zip(fx.clear_reference.iter_mut())
        {
            let off = offset(axis);
            let a75 = objects.get(A75 + off, 0).unwrap_or(0) as u8;
            let (execute, selector) = (a75 & 1 != 0, (a75 >> 1) & 0xF);
            let rising = execute && !a.execute;
            a.execute = execute;
            let before = a.status;
            if !execute {
                // the master ended it (or never started one); a running save
                // goes on, its result is no longer shown; a motor action
                // stops (its injection with it)
                a.status = status(0, 0, state::IDLE);
                if a.running == Some(Running::Tuning) {
                    a.running = None;
                }
                a.tuning = None;
            } else if rising {
                a.status = start(a, objects, axis, selector, clear, activation);
            } else if let Some(r) = a.running {
                a.status = match r {
                    Running::Tuning => match a.tuning.as_ref() {
                        Some(Measurement::Current(t)) => follow_tuning(objects, t, axis, selector),
                        Some(Measurement::Align(al)) => follow_alignment(objects, al, axis, selector),
                        Some(Measurement::Winding(w)) => follow_winding(objects, w, axis, selector),
                        Some(Measurement::Phase(p)) => follow_phase(objects, p, axis, selector),
                        Some(Measurement::Brake(b)) => follow_brake(objects, b, axis, selector),
                        Some(Measurement::Grind(g)) => follow_grind(objects, g, axis, selector),
                        Some(Measurement::Mechanics(m)) => follow_mechanics(objects, m, axis, selector),
                        None => None,
                    },
                    _ => follow(objects, r, selector),
                }
                .unwrap_or(a.status);
                if a.status >> 12 != state::RUNNING {
                    a.running = None;
                }
            }
            // (written only when it changes: a dictionary write per axis and
            // ESC poll cost the ESC task ~400 instructions, QEMU figure)
            if a.status != before {
                let _ = objects.set(A69 + off, 0, i64::from(a.status));
            }
        }
        fx
    }
}

/// Starts action `selector` on `axis` (E-140…E-142); returns A69.
fn start(
    a: &mut AxisActions,
    objects: &mut DriveObjects,
    axis: usize,
    selector: u8,
    clear: &mut bool,
    activation: Activation,
) -> u16 {
    let Some(action) = Action::from_selector(selector) else {
        return status(0, selector, state::UNKNOWN);
    };
    if activation == Activation::RxPdo && !Actions::activated(objects, axis) {
        return status(0, selector, state::NOT_ACTIVATED);
    }
    let e48 = objects.get(E48 + offset(axis), 0).unwrap_or(0);
    if !action.may_start(e48) {
        return status(0, selector, state::REFUSED);
    }
    match action {
        Action::Save => {
            let _ = objects.set(A00, 2, 0);
            objects.request_save();
            a.running = Some(Running::Save);
            status(0, selector, state::RUNNING)
        }
        Action::Restart => {
            objects.request_restart();
            a.running = Some(Running::Restart);
            status(0, selector, state::RUNNING)
        }
        Action::ClearReference => {
            *clear = true;
            status(100, selector, state::DONE)
        }
        Action::OptimiseCurrent | Action::OptimiseCurrentStandstill => {
            let rated_ma = objects.get(0x6075 + cia(axis), 0).unwrap_or(0);
            let r_mohm = objects.get(B53 + offset(axis), 0).unwrap_or(0);
            let standstill = action == Action::OptimiseCurrentStandstill;
            a.tuning = Some(Measurement::Current(CurrentTuning::new(
                rated_ma as f32 * 1e-3,
                r_mohm as f32 * 1e-3,
                standstill,
            )));
            a.running = Some(Running::Tuning);
            status(0, selector, state::RUNNING)
        }
        Action::TestPhase => {
            let rated_ma = objects.get(0x6075 + cia(axis), 0).unwrap_or(0);
            let r_mohm = objects.get(B53 + offset(axis), 0).unwrap_or(0);
            let pole_pairs = objects.get(B10 + offset(axis), 0).unwrap_or(4);
            a.tuning = Some(Measurement::Phase(PhaseTest::new(
                rated_ma as f32 * 1e-3,
                r_mohm as f32 * 1e-3,
                pole_pairs as u8,
            )));
            a.running = Some(Running::Tuning);
            status(0, selector, state::RUNNING)
        }
        Action::TestWinding => {
            let rated_ma = objects.get(0x6075 + cia(axis), 0).unwrap_or(0);
            let r_mohm = objects.get(B53 + offset(axis), 0).unwrap_or(0);
            a.tuning = Some(Measurement::Winding(WindingTest::new(
                rated_ma as f32 * 1e-3,
                r_mohm as f32 * 1e-3,
            )));
            a.running = Some(Running::Tuning);
            status(0, selector, state::RUNNING)
        }
        Action::CalibrateMotor => {
            let rated_ma = objects.get(0x6075 + cia(axis), 0).unwrap_or(0);
            let r_mohm = objects.get(B53 + offset(axis), 0).unwrap_or(0);
            let ud = (rated_ma as f32 * 1e-3) * (r_mohm as f32 * 1e-3);
            let pole_pairs = objects.get(B10 + offset(axis), 0).unwrap_or(4);
            a.tuning = Some(Measurement::Align(Alignment::new(ud, pole_pairs as u8)));
            a.running = Some(Running::Tuning);
            status(0, selector, state::RUNNING)
        }
        Action::TestBrake => {
            let rated_mnm = objects.get(0x6076 + cia(axis), 0).unwrap_or(0);
            let _ = objects.set(B300 + offset(axis), 3, rated_mnm);
            a.tuning = Some(Measurement::Brake(BrakeTest::new(rated_mnm as f32 * 1e-3)));
            a.running = Some(Running::Tuning);
            status(0, selector, state::RUNNING)
        }
        Action::GrindBrake => {
            let rated_mnm = objects.get(0x6076 + cia(axis), 0).unwrap_or(0);
            let max_permille = objects.get(0x6072 + cia(axis), 0).unwrap_or(0);
            let rated_nm = rated_mnm as f32 * 1e-3;
            a.tuning = Some(Measurement::Grind(GrindBrake::new(
                rated_nm,
                rated_nm * max_permille as f32 * 1e-3,
            )));
            a.running = Some(Running::Tuning);
            status(0, selector, state::RUNNING)
        }
        Action::IdentifyMechanics => start_mechanics(a, objects, axis, selector),
        // A37 (the memorised extreme values) and I52 (the limit-switch
        // memory) hold nothing in this drive; a second brake (B302) it does
        // not have (one brake per axis), and the safety's brake test (S18)
        // belongs to a safety module it does not have
        _ => status(0, selector, state::NOT_AVAILABLE),
    }
}

/// Starts B44 on `axis` unless its test move would pass a software limit
/// (607Dh, against 6064h) or a limit switch is active (60FDh bits 0, 1):
/// then refused before anything moves, B44\[0\] = 10.
fn start_mechanics(a: &mut AxisActions, objects: &mut DriveObjects, axis: usize, selector: u8) -> u16 {
    let (off, c) = (offset(axis), cia(axis));
    let get = |i: u16, s: u8| objects.get(i + c, s).unwrap_or(0);
    // the travel in the position unit of 6064h/607Dh: increments × 6092h
    // feed / (6091h gear ratio × 2^20 per revolution, 6092h:02 shaft revs)
    let per_inc = {
        let (motor, shaft) = (get(0x6091, 1) as f64, get(0x6091, 2) as f64);
        let (feed, revs) = (get(0x6092, 1) as f64, get(0x6092, 2) as f64);
        let k = feed * shaft / (revs * motor * f64::from(1u32 << 20));
        if k.is_finite() && k > 0.0 {
            k
        } else {
            1.0
        }
    };
    // (the casts saturate; + 1 rounds up)
    let travel = ((f64::from(TRAVEL_INC) * per_inc) as i64).saturating_add(1);
    let back = ((f64::from(BACK_INC) * per_inc) as i64).saturating_add(1);
    let inputs = get(0x60FD, 0);
    let within = MechanicsTest::travel_allowed(get(0x6064, 0), get(0x607D, 1), get(0x607D, 2), travel, back);
    if !within || inputs & 0b11 != 0 {
        let _ = objects.set(B44 + off, 1, i64::from(crate::tuning::result::LIMIT));
        return status(0, selector, state::REFUSED);
    }
    let cycle_us = match objects.get(A150, 0) {
        Ok(us) if us > 0 => us as f32,
        _ => A150_FALLBACK_US as f32,
    };
    let rated_nm = get(0x6076, 0) as f32 * 1e-3;
    let max_nm = rated_nm * get(0x6072, 0) as f32 * 1e-3;
    let _ = objects.set(B44 + off, 1, 0);
    let _ = objects.set(B44 + off, 2, 0);
    a.tuning = Some(Measurement::Mechanics(MechanicsTest::new(
        cycle_us * 1e-6,
        rated_nm,
        max_nm,
    )));
    a.running = Some(Running::Tuning);
    status(0, selector, state::RUNNING)
}

/// A69 of a running B44; at its end the figures in B45…B47, the gains for
/// B48's bandwidth in C31/C32/I20 (for the 250 µs reference cycle of the
/// gains, which the axis scales to A150), the result in B44.
fn follow_mechanics(objects: &mut DriveObjects, m: &MechanicsTest, axis: usize, selector: u8) -> Option<u16> {
    let off = offset(axis);
    let (code, excursion, st) = match m.outcome() {
        MechanicsOutcome::Running(p, _) => return Some(status(u16::from(p), selector, state::RUNNING)),
        MechanicsOutcome::Failed(code, excursion) => (code, excursion, state::FAILED),
        MechanicsOutcome::Done(id, excursion) => {
            let round = |x: f32| (x + 0.5) as i64;
            let cycle_us = match objects.get(A150, 0) {
                Ok(us) if us > 0 => us as f32,
                _ => A150_FALLBACK_US as f32,
            };
            // the reference cycle's gains scale by r = 250 µs / A150 (Kp),
            // 1/r (Ti), √r (Kv) above it
            let r = (250.0 / cycle_us).min(1.0);
            let bandwidth = objects.get(B48 + off, 0).unwrap_or(60) as f32;
            let g = id.gains(bandwidth);
            let written = objects.set(B45 + off, 0, round(id.inertia_kg_m2 * 1e7)).is_ok()
                && objects.set(B46 + off, 0, round(id.coulomb_nm * 1e6)).is_ok()
                && objects
                    .set(B47 + off, 0, round(id.viscous_nm_s_per_rad * 1e9))
                    .is_ok()
                && objects
                    .set(C31 + off, 0, round(g.kp_nm_s_per_rad / r * 1e6))
                    .is_ok()
                && objects.set(C32 + off, 0, round(g.ti_s * r * 1e6)).is_ok()
                && objects
                    .set(I20 + off, 0, round(g.kv_per_s / sqrt(r) * 10.0))
                    .is_ok();
            let _ = objects.set(B44 + off, 3, (id.load_nm * 1e6) as i64);
            if written {
                (crate::tuning::result::OK, excursion, state::DONE)
            } else {
                (crate::tuning::result::IMPLAUSIBLE, excursion, state::FAILED)
            }
        }
    };
    let _ = objects.set(B44 + off, 2, i64::from(excursion));
    let _ = objects.set(B44 + off, 1, i64::from(code));
    Some(status(if st == state::DONE { 100 } else { 0 }, selector, st))
}

/// The CiA 402 window offset of `axis`.
fn cia(axis: usize) -> u16 {
    if axis == 0 {
        0
    } else {
        AXIS_B_CIA402
    }
}

/// A69 of a running B42/B49; at its end its results in B42 and, identified,
/// R in B53 and L in B52 and B62 (the current loop's gains follow:
/// Kp = ω_c·L, Ki = ω_c·R).
fn follow_tuning(
    objects: &mut DriveObjects,
    tuning: &CurrentTuning,
    axis: usize,
    selector: u8,
) -> Option<u16> {
    let off = offset(axis);
    match tuning.outcome() {
        Outcome::Running(p) => Some(status(u16::from(p), selector, state::RUNNING)),
        Outcome::Done(id) => {
            let r_mohm = (id.r_ohm * 1e3 + 0.5) as i64;
            let l_uh = (id.l_h * 1e6 + 0.5) as i64;
            let _ = objects.set(B42 + off, 2, r_mohm);
            let _ = objects.set(B42 + off, 3, l_uh);
            let written = objects.set(B53 + off, 0, r_mohm).is_ok()
                && objects.set(B52 + off, 0, l_uh).is_ok()
                && objects.set(B62 + off, 0, l_uh).is_ok();
            let code = if written {
                crate::tuning::result::OK
            } else {
                crate::tuning::result::IMPLAUSIBLE
            };
            let _ = objects.set(B42 + off, 1, i64::from(code));
            Some(if written {
                status(100, selector, state::DONE)
            } else {
                status(100, selector, state::FAILED)
            })
        }
        Outcome::Failed(code) => {
            let _ = objects.set(B42 + off, 1, i64::from(code));
            Some(status(0, selector, state::FAILED))
        }
    }
}

/// A69 of a running B40; at its end its result and figures in B40.
fn follow_phase(objects: &mut DriveObjects, p: &PhaseTest, axis: usize, selector: u8) -> Option<u16> {
    let off = offset(axis);
    let (code, per_turn, pole_pairs, st) = match p.outcome() {
        PhaseOutcome::Running(pr) => return Some(status(u16::from(pr), selector, state::RUNNING)),
        PhaseOutcome::Done {
            per_turn_inc,
            pole_pairs,
        } => (0, per_turn_inc, pole_pairs, state::DONE),
        PhaseOutcome::Failed(code, per_turn) => (code, per_turn, 0, state::FAILED),
    };
    let _ = objects.set(B40 + off, 2, i64::from(per_turn));
    let _ = objects.set(B40 + off, 3, i64::from(pole_pairs));
    let _ = objects.set(B40 + off, 1, i64::from(code));
    Some(status(if st == state::DONE { 100 } else { 0 }, selector, st))
}

/// A69 of a running B43; at its end the resistances and the result in B43.
fn follow_winding(objects: &mut DriveObjects, w: &WindingTest, axis: usize, selector: u8) -> Option<u16> {
    let off = offset(axis);
    match w.outcome() {
        WindingOutcome::Running(p) => Some(status(u16::from(p), selector, state::RUNNING)),
        WindingOutcome::Done(r) => {
            for (sub, x) in (2u8..).zip(r) {
                let _ = objects.set(B43 + off, sub, (x * 1e3 + 0.5) as i64);
            }
            let code = WindingTest::code(&r);
            let _ = objects.set(B43 + off, 1, i64::from(code));
            let st = if code == crate::tuning::result::OK {
                state::DONE
            } else {
                state::FAILED
            };
            Some(status(100, selector, st))
        }
        WindingOutcome::Failed(code) => {
            let _ = objects.set(B43 + off, 1, i64::from(code));
            Some(status(0, selector, state::FAILED))
        }
    }
}

/// A69 of a running B300; at its end its result and the movement in B300.
fn follow_brake(objects: &mut DriveObjects, b: &BrakeTest, axis: usize, selector: u8) -> Option<u16> {
    let off = offset(axis);
    let (code, moved, st) = match b.outcome() {
        BrakeOutcome::Running(p) => return Some(status(u16::from(p), selector, state::RUNNING)),
        BrakeOutcome::Held(moved) => (crate::tuning::result::OK, moved, state::DONE),
        BrakeOutcome::Failed(code, moved) => (code, moved, state::FAILED),
    };
    let _ = objects.set(B300 + off, 2, i64::from(moved));
    let _ = objects.set(B300 + off, 1, i64::from(code));
    Some(status(if st == state::DONE { 100 } else { 0 }, selector, st))
}

/// A69 of a running B301; at its end its result and figures in B301.
fn follow_grind(objects: &mut DriveObjects, g: &GrindBrake, axis: usize, selector: u8) -> Option<u16> {
    let off = offset(axis);
    let (code, f, st): (u8, GrindFigures, u16) = match g.outcome() {
        GrindOutcome::Running(p) => return Some(status(u16::from(p), selector, state::RUNNING)),
        GrindOutcome::Done(f) => (crate::tuning::result::OK, f, state::DONE),
        GrindOutcome::Failed(code, f) => (code, f, state::FAILED),
    };
    let _ = objects.set(B301 + off, 2, i64::from(f.grind_travel_inc));
    let _ = objects.set(B301 + off, 3, i64::from(f.release_travel_inc));
    let torque_mnm = (f.grind_torque_nm * 1e3 + 0.5) as i64;
    let _ = objects.set(B301 + off, 4, torque_mnm);
    let _ = objects.set(B301 + off, 1, i64::from(code));
    Some(status(if st == state::DONE { 100 } else { 0 }, selector, st))
}

/// A69 of a running B41; at its end its result in B41 and the offset in B05.
fn follow_alignment(objects: &mut DriveObjects, al: &Alignment, axis: usize, selector: u8) -> Option<u16> {
    let off = offset(axis);
    match al.outcome() {
        AlignOutcome::Running(p) => Some(status(u16::from(p), selector, state::RUNNING)),
        AlignOutcome::Done {
            offset_inc,
            spread_inc,
        } => {
            let _ = objects.set(B41 + off, 2, i64::from(spread_inc));
            let written = objects.set(B05 + off, 0, i64::from(offset_inc)).is_ok();
            let code = if written {
                crate::tuning::result::OK
            } else {
                crate::tuning::result::IMPLAUSIBLE
            };
            let _ = objects.set(B41 + off, 1, i64::from(code));
            Some(status(
                100,
                selector,
                if written { state::DONE } else { state::FAILED },
            ))
        }
        AlignOutcome::Failed(code) => {
            let _ = objects.set(B41 + off, 1, i64::from(code));
            Some(status(0, selector, state::FAILED))
        }
    }
}

/// A69 of running action `r`; `None` while it runs unchanged.
fn follow(objects: &DriveObjects, r: Running, selector: u8) -> Option<u16> {
    match r {
        Running::Save => {
            let progress = objects.get(A00, 2).ok()?;
            if objects.requests().save || progress != 100 {
                return None;
            }
            let failed = objects.get(A00, 3).unwrap_or(0) != 0;
            Some(if failed {
                status(100, selector, state::FAILED)
            } else {
                status(100, selector, state::DONE)
            })
        }
        Running::Restart | Running::Tuning => None,
    }
}

#[cfg(test)]
mod tests;
