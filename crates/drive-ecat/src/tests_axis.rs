//! The axis runtime against a rigid-body motor model: J = 1e-4 kg·m², viscous
//! friction, one control cycle of actuation delay. Objects are written with
//! `DriveObjects::set`, as the PDO/SDO side would.

use crate::axis::*;
use crate::params::E48;
use crate::runtime::Drive;
use cia402::{State, SW_INTERNAL_LIMIT, SW_MODE_BIT12, SW_MODE_BIT13, SW_TARGET_REACHED};
use motion::{Event, INCREMENTS_PER_REVOLUTION};
use nanos::Nanos;

use store::RamFlash;

type Flash = RamFlash<4096, 2>;

/// A150 default: 1 ms.
const DT_NS: u64 = 1_000_000;
const REV_I: i64 = 1 << 20;
const TAU: f64 = core::f64::consts::TAU;

/// Rigid body: J·dω/dt = τ(t − 1 cycle) − b·ω + load.
struct Motor {
    theta: f64,
    omega: f64,
    j: f64,
    b: f64,
    /// Load torque, N·m.
    load: f64,
    /// The command of the last cycle (one-cycle actuation delay).
    pending: f64,
}

impl Motor {
    fn new() -> Self {
        Self {
            theta: 0.0,
            omega: 0.0,
            j: 1e-4,
            b: 1e-4,
            load: 0.0,
            pending: 0.0,
        }
    }

    fn position_inc(&self) -> i32 {
        let inc = self.theta * REV_I as f64 / TAU;
        let r = if inc >= 0.0 { inc + 0.5 } else { inc - 0.5 };
        r as i64 as i32
    }

    fn velocity_inc_per_s(&self) -> f64 {
        self.omega * REV_I as f64 / TAU
    }

    fn step(&mut self, cmd: &AxisCommand, dt_ns: u64) {
        let torque = self.pending;
        self.pending = if cmd.power_stage {
            f64::from(cmd.torque_nm)
        } else {
            0.0
        };
        const SUB: u32 = 20;
        let h = dt_ns as f64 * 1e-9 / f64::from(SUB);
        for _ in 0..SUB {
            let a = (torque - self.b * self.omega + self.load) / self.j;
            self.omega += a * h;
            self.theta += self.omega * h;
        }
    }
}

struct Rig {
    drive: Drive<Flash>,
    motors: [Motor; 2],
    io: [AxisIo; 2],
    now: Nanos,
    commands: [AxisCommand; 2],
    new_setpoint: Option<[bool; 2]>,
}

impl Rig {
    /// A rising edge of touch-probe input 1 of axis A now, latched at
    /// `position_inc` (None: no position with it).
    fn probe1_rising(&mut self, position_inc: Option<i32>) {
        self.io[0].probe_edges[0] = Some(ProbeEdge {
            input: 1,
            rising: true,
            time_ns: self.now,
            position_inc,
        });
    }

    /// A new rig after two cycles with touch probe 1 of axis A switched on
    /// for its first rising edge (60B8h = 0011h), one cycle on.
    fn probe1_armed() -> Self {
        let mut rig = Self::new();
        rig.run(2);
        rig.set(0, 0x60B8, 0, 0x11);
        rig.run(1);
        rig
    }

    fn new() -> Self {
        Self {
            drive: Drive::new(Flash::new()),
            motors: [Motor::new(), Motor::new()],
            io: [AxisIo::ready(0), AxisIo::ready(0)],
            now: Nanos::ZERO,
            commands: [AxisCommand::OFF; 2],
            new_setpoint: None,
        }
    }

    fn index(axis: usize, index: u16) -> u16 {
        if axis == 0 {
            index
        } else if index >= 0x6000 {
            index + crate::AXIS_B_CIA402
        } else {
            index + crate::AXIS_B_MANUFACTURER
        }
    }

    fn set(&mut self, axis: usize, index: u16, sub: u8, value: i64) {
        self.drive
            .objects_mut()
            .set(Self::index(axis, index), sub, value)
            .unwrap();
    }

    fn get(&self, axis: usize, index: u16, sub: u8) -> i64 {
        self.drive.objects().get(Self::index(axis, index), sub).unwrap()
    }

    fn sw(&self, axis: usize) -> u16 {
        self.get(axis, 0x6041, 0) as u16
    }

    fn cycle(&mut self) {
        for (io, m) in self.io.iter_mut().zip(&self.motors) {
            io.position_inc = m.position_inc();
        }
        self.commands = match self.new_setpoint {
            None => self.drive.control_cycle(self.now, &self.io),
            Some(n) => self.drive.control_cycle_with(self.now, &self.io, n),
        };
        for (m, c) in self.motors.iter_mut().zip(&self.commands) {
            m.step(c, DT_NS);
        }
        // edges are one-cycle events
        for io in &mut self.io {
            io.probe_edges = [None; 4];
            io.index = None;
        }
        self.now += Nanos::from_ns(DT_NS);
    }

    fn run(&mut self, cycles: usize) {
        for _ in 0..cycles {
            self.cycle();
        }
    }

    /// Runs until `done` or `max` cycles; returns the cycles taken.
    fn run_until(&mut self, max: usize, mut done: impl FnMut(&Self) -> bool) -> usize {
        for n in 0..max {
            if done(self) {
                return n;
            }
            self.cycle();
        }
        panic!("condition not met within {max} cycles");
    }

    fn controlword(&mut self, axis: usize, cw: u16) {
        self.set(axis, 0x6040, 0, i64::from(cw));
    }

    /// 6 → 7 → 15 (C-002, C-004, C-005).
    fn enable(&mut self, axis: usize) {
        self.run(2);
        for (cw, pattern) in [(0x06, 0x21), (0x07, 0x23), (0x0F, 0x27)] {
            self.controlword(axis, cw);
            self.run(2);
            assert_eq!(self.sw(axis) & 0x6F, pattern, "controlword {cw:#x}");
        }
    }

    fn position(&self, axis: usize) -> i32 {
        self.get(axis, 0x6064, 0) as i32
    }

    fn velocity(&self, axis: usize) -> i32 {
        self.get(axis, 0x606C, 0) as i32
    }

    fn state(&self, axis: usize) -> State {
        State::from_statusword(self.sw(axis)).unwrap()
    }
}

#[test]
fn c018_enable_sequence_reaches_operation_enabled() {
    let mut rig = Rig::new();
    rig.run(2);
    // T1 on its own, statusword 0x0040 pattern, E48 = 1
    assert_eq!(rig.sw(0) & 0x4F, 0x40);
    assert_eq!(rig.get(0, E48, 0), 1);
    assert!(!rig.commands[0].power_stage);
    rig.enable(0);
    assert_eq!(rig.state(0), State::OperationEnabled);
    assert_eq!(rig.sw(0) & 0x6F, 0x0027);
    // voltage enabled (bit 4) and remote (bit 9)
    assert_ne!(rig.sw(0) & (1 << 4), 0);
    assert_ne!(rig.sw(0) & (1 << 9), 0);
    assert_eq!(rig.get(0, E48, 0), 4);
    assert_eq!(rig.get(0, 0x6061, 0), 8, "csp is the default mode (C-026)");
    assert!(rig.commands[0].power_stage);
    // csp: the brake opens on the active cyclic command (C-021)
    assert!(rig.commands[0].brake_release);
    // holding still: no drift
    rig.run(100);
    assert!(rig.position(0).abs() < 50, "drifted to {}", rig.position(0));
}

#[test]
fn c003_enable_refused_without_additional_enable() {
    let mut rig = Rig::new();
    rig.io[0].additional_enable = false;
    rig.run(2);
    rig.controlword(0, 0x06);
    rig.run(3);
    assert_eq!(rig.state(0), State::SwitchOnDisabled);
    rig.io[0].additional_enable = true;
    rig.run(2);
    assert_eq!(rig.state(0), State::ReadyToSwitchOn);
}

/// A44 (issue 40, spec cia402.md transitions 9 and 11): losing A60 in
/// Operation enabled switches the power stage off with A44 = 0 (the
/// default) and quick-stops with A44 = 1, set in the dictionary.
#[test]
fn c003_a44_decides_what_losing_a60_does() {
    for (a44, want) in [(0, State::SwitchOnDisabled), (1, State::QuickStopActive)] {
        let mut rig = Rig::new();
        rig.set(0, crate::params::A44, 0, a44);
        rig.enable(0);
        rig.io[0].additional_enable = false;
        rig.run(2);
        assert_eq!(rig.state(0), want, "A44 = {a44}");
    }
}

/// A master trajectory at 1 ms: 100 ms at 20 rev/s² to 2 rev/s, 300 ms
/// at 2 rev/s, 100 ms braking; increments at cycle `k`.
fn trajectory(k: i64) -> i64 {
    let a = 20.0 * REV_I as f64; // inc/s²
    let t = k as f64 * 1e-3;
    let x = if t < 0.1 {
        0.5 * a * t * t
    } else if t < 0.4 {
        0.5 * a * 0.01 + 0.1 * a * (t - 0.1)
    } else if t < 0.5 {
        let u = t - 0.4;
        0.5 * a * 0.01 + 0.1 * a * 0.3 + 2.0 * REV_I as f64 * u - 0.5 * a * u * u
    } else {
        0.5 * a * 0.01 + 0.1 * a * 0.3 + 0.5 * a * 0.01
    };
    x as i64
}

/// Axis A (enabled in csp) sent the 500 cycles of [`trajectory`], `each`
/// after every cycle; the largest following error 60F4h seen, inc.
fn follow_trajectory(rig: &mut Rig, mut each: impl FnMut(&Rig)) -> i64 {
    let mut max_fe = 0i64;
    for k in 1..=500 {
        rig.set(0, 0x607A, 0, trajectory(k));
        rig.cycle();
        max_fe = max_fe.max(rig.get(0, 0x60F4, 0).abs());
        each(rig);
    }
    max_fe
}

#[test]
fn c035_csp_follows_target_position() {
    let mut rig = Rig::new();
    rig.enable(0);
    // bit 12: the drive follows the set position
    let max_fe = follow_trajectory(&mut rig, |r| assert_ne!(r.sw(0) & SW_MODE_BIT12, 0));
    // ≈ 1° at most on 20 rev/s² without acceleration feedforward
    assert!(max_fe < REV_I / 360, "max following error {max_fe} inc");
    let target = trajectory(500);
    assert!((target - 4 * REV_I / 5).abs() <= 1, "0.8 rev: {target}");
    rig.run(200);
    let pos = i64::from(rig.position(0));
    assert!((pos - target).abs() < 100, "stopped at {pos}, target {target}");
    assert!(rig.velocity(0).abs() < 5000);
    assert!((i64::from(rig.motors[0].position_inc()) - target).abs() < 100);
    assert_eq!(rig.sw(0) & SW_MODE_BIT13, 0, "no following error bit");
}

#[test]
fn c035_csp_with_acceleration_feedforward_tracks_closely() {
    let mut rig = Rig::new();
    rig.drive.axes_mut()[0].params_mut().cascade.inertia_kg_m2 = 1e-4;
    // I425 = 4: quadratic, internal feedforward (acceleration from ∇²),
    // written as a master does (issue 40)
    rig.set(0, crate::params::I425, 0, 4);
    rig.enable(0);
    let max_fe = follow_trajectory(&mut rig, |_| {});
    // a third of the error without it
    assert!(max_fe < REV_I / 1000, "max following error {max_fe} inc");
}

#[test]
fn c037_csv_velocity_reached() {
    let mut rig = Rig::new();
    rig.set(0, 0x6060, 0, 9);
    rig.enable(0);
    assert_eq!(rig.get(0, 0x6061, 0), 9);
    let v = 5 * REV_I;
    rig.set(0, 0x60FF, 0, v);
    rig.run(300);
    let actual = i64::from(rig.velocity(0));
    assert!((actual - v).abs() < v / 100, "velocity {actual}, set {v}");
    assert!((rig.motors[0].velocity_inc_per_s() - v as f64).abs() < v as f64 / 100.0);
    assert_ne!(rig.sw(0) & SW_MODE_BIT12, 0);
}

#[test]
fn c038_cst_torque_produced() {
    let mut rig = Rig::new();
    // G472/G475: let the axis run up to 40 % of I10 (20 rev/s) in the torque modes
    rig.set(0, crate::params::G472, 0, 400);
    rig.set(0, crate::params::G475, 0, 400);
    rig.set(0, 0x6060, 0, 10);
    rig.enable(0);
    rig.set(0, 0x6071, 0, 100); // 10 % of 1.3 N·m
    rig.run(5);
    assert!(
        (rig.commands[0].torque_nm - 0.13).abs() < 1e-4,
        "{}",
        rig.commands[0].torque_nm
    );
    assert_eq!(rig.get(0, 0x6077, 0), 100);
    assert_eq!(rig.get(0, 0x6076, 0), 1300, "rated torque in mN·m");
    rig.run(20);
    // 0.13 N·m on 1e-4 kg·m²: about 1300 rad/s² → positive velocity
    assert!(rig.velocity(0) > REV_I as i32, "velocity {}", rig.velocity(0));
    assert_ne!(rig.sw(0) & SW_MODE_BIT12, 0);
}

#[test]
fn c039_cst_default_speed_limit_keeps_the_axis_still() {
    let mut rig = Rig::new();
    rig.set(0, 0x6060, 0, 10);
    rig.enable(0);
    rig.set(0, 0x6071, 0, 500);
    rig.run(200);
    assert!(
        rig.velocity(0).abs() < REV_I as i32 / 10,
        "velocity {}",
        rig.velocity(0)
    );
    // the speed limiter is an internal limit (bit 11)
    assert_ne!(rig.sw(0) & SW_INTERNAL_LIMIT, 0);
    // a raised G472 lets the same torque move the axis, up to G472 · I10
    // (the refusal of a value beyond 100 % is checked through SOEM)
    rig.set(0, crate::params::G472, 0, 100); // 10 % of 50 rev/s
    rig.run(400);
    let limit = 5 * REV_I as i32;
    assert!(
        (rig.velocity(0) - limit).abs() < limit / 50,
        "velocity {} at the limit {limit}",
        rig.velocity(0)
    );
    assert_ne!(rig.sw(0) & SW_INTERNAL_LIMIT, 0);
}

/// Homing method 35 (O, reference at the current position) on axis `a`.
fn home_here(rig: &mut Rig, a: usize, home_offset: i64) {
    rig.set(a, 0x6060, 0, 6);
    rig.set(a, 0x607C, 0, home_offset);
    rig.run(3);
    assert_eq!(rig.get(a, 0x6061, 0), 6);
    // 001: not started
    assert_eq!(rig.sw(a) & 0x3400, SW_TARGET_REACHED);
    rig.controlword(a, 0x1F);
    rig.run_until(100, |r| r.sw(a) & 0x3400 == SW_TARGET_REACHED | SW_MODE_BIT12);
    rig.controlword(a, 0x0F);
    rig.run(2);
}

#[test]
fn c061_homing_sets_the_home_offset() {
    let mut rig = Rig::new();
    rig.motors[0].theta = 1.0; // somewhere
    rig.set(0, 0x6060, 0, 6);
    rig.enable(0);
    let before = rig.position(0);
    assert!((i64::from(before) - REV_I / 6).abs() < REV_I / 100, "{before}");
    home_here(&mut rig, 0, 1234);
    assert!(
        (rig.position(0) - 1234).abs() < 20,
        "position {}",
        rig.position(0)
    );
    assert!(rig.drive.axes()[0].is_referenced());
}

#[test]
fn c041_c048_pp_move_sets_target_reached() {
    let mut rig = Rig::new();
    rig.enable(0);
    // C-050: an absolute move is refused before referencing
    rig.set(0, 0x6060, 0, 1);
    rig.set(0, 0x607A, 0, 5 * REV_I);
    rig.run(3);
    assert_eq!(rig.get(0, 0x6061, 0), 1);
    rig.controlword(0, 0x1F);
    rig.run(20);
    assert_eq!(rig.sw(0) & SW_MODE_BIT12, 0, "no acknowledge unreferenced");
    assert!(rig.position(0).abs() < 100);

    rig.controlword(0, 0x0F);
    home_here(&mut rig, 0, 0);
    rig.set(0, 0x6060, 0, 1);
    rig.run(3);
    // a steady bit 4 starts nothing; the edge does (C-041)
    rig.controlword(0, 0x1F);
    rig.run(2);
    assert_ne!(rig.sw(0) & SW_MODE_BIT12, 0, "set-point acknowledge (C-042)");
    assert_eq!(rig.sw(0) & SW_TARGET_REACHED, 0);
    rig.controlword(0, 0x0F);
    rig.run(1);
    assert_eq!(rig.sw(0) & SW_MODE_BIT12, 0, "acknowledge follows bit 4");
    let n = rig.run_until(3000, |r| r.sw(0) & SW_TARGET_REACHED != 0);
    // 5 rev at 10 rev/s with 100 rev/s² ramps: ≈ 0.6 s
    assert!((500..1000).contains(&n), "took {n} cycles");
    let pos = i64::from(rig.position(0));
    assert!((pos - 5 * REV_I).abs() <= i64::from(INCREMENTS_PER_REVOLUTION / 360));
    assert_eq!(rig.sw(0) & SW_MODE_BIT13, 0);
}

#[test]
fn c046_pp_relative_move_is_additive() {
    let mut rig = Rig::new();
    rig.enable(0);
    rig.set(0, 0x6060, 0, 1);
    rig.run(3);
    // relative moves need no reference
    rig.set(0, 0x607A, 0, REV_I);
    rig.controlword(0, 0x5F);
    rig.run(2);
    rig.controlword(0, 0x4F);
    rig.run_until(2000, |r| r.sw(0) & SW_TARGET_REACHED != 0);
    rig.controlword(0, 0x5F);
    rig.run(2);
    rig.controlword(0, 0x4F);
    rig.run(2);
    rig.run_until(2000, |r| r.sw(0) & SW_TARGET_REACHED != 0);
    assert!((i64::from(rig.position(0)) - 2 * REV_I).abs() < 3000);
}

#[test]
fn c010_c011_quick_stop_to_standstill_then_switch_on_disabled() {
    let mut rig = Rig::new();
    rig.set(0, 0x6060, 0, 9);
    rig.set(0, 0x6085, 0, 50 * REV_I); // 50 rev/s²
    rig.enable(0);
    rig.set(0, 0x60FF, 0, 5 * REV_I);
    rig.run(300);
    assert!(rig.velocity(0) > 4 * REV_I as i32);
    rig.controlword(0, 0x0B); // bit 2 = 0: quick stop
    rig.run(2);
    assert_eq!(rig.state(0), State::QuickStopActive);
    assert_eq!(rig.sw(0) & 0x6F, 0x0007);
    assert_eq!(rig.get(0, E48, 0), 7);
    // 5 rev/s at 50 rev/s²: 100 ms
    let n = rig.run_until(400, |r| r.state(0) == State::SwitchOnDisabled);
    assert!((80..200).contains(&n), "quick stop took {n} cycles");
    assert!(rig.motors[0].velocity_inc_per_s().abs() < 0.1 * REV_I as f64);
    assert!(!rig.commands[0].power_stage);
    // no return to Operation enabled (no T16)
    rig.controlword(0, 0x0F);
    rig.run(3);
    assert_eq!(rig.state(0), State::SwitchOnDisabled);
}

#[test]
fn c036_following_error_fault_goes_to_fault_and_queues_emcy() {
    let mut rig = Rig::new();
    // I470 = 1: a following error is a fault
    rig.set(0, crate::params::I470, 0, 1);
    rig.set(0, 0x6065, 0, 1000);
    rig.set(0, 0x6066, 0, 2);
    rig.enable(0);
    assert_eq!(rig.drive.slave().emergencies_pending(), 0);
    // block the motor and ask for a revolution
    rig.set(0, 0x607A, 0, REV_I / 10);
    rig.run_until(200, |r| r.state(0) == State::Fault);
    assert_eq!(rig.sw(0) & 0x4F, 0x08);
    assert_eq!(rig.get(0, E48, 0), 5);
    assert_eq!(rig.drive.slave().emergencies_pending(), 1);
    assert_eq!(rig.get(0, 0x603F, 0), 0x8611);
    assert_ne!(rig.drive.objects().get(0x1001, 0).unwrap(), 0);
    assert!(!rig.commands[0].power_stage);
    // T15: fault reset edge → Switch on disabled, "fault cleared" EMCY
    rig.controlword(0, 0x80);
    rig.run(2);
    assert_eq!(rig.state(0), State::SwitchOnDisabled);
    assert_eq!(rig.drive.slave().emergencies_pending(), 2);
    assert_eq!(rig.get(0, 0x603F, 0), 0);
    assert_eq!(rig.drive.objects().get(0x1001, 0).unwrap(), 0);
}

#[test]
fn c117_missing_setpoints_extrapolate_then_fault() {
    let mut rig = Rig::new();
    rig.enable(0);
    let step = REV_I / 1000;
    for k in 1..=50 {
        rig.set(0, 0x607A, 0, k * step);
        rig.cycle();
    }
    // the master stops sending: extrapolation with the last increment (C-116)
    rig.new_setpoint = Some([false, true]);
    let p0 = rig.position(0);
    rig.run(5);
    assert!(rig.position(0) - p0 > 3 * step as i32, "keeps moving");
    assert_ne!(rig.state(0), State::Fault);
    // beyond I423 (10 ms): event 78 cause 3 → Fault
    rig.run_until(20, |r| r.state(0).is_fault());
    rig.run_until(500, |r| r.state(0) == State::Fault);
    assert_eq!(rig.get(0, 0x603F, 0), 0x8612);
}

#[test]
fn c134_axis_b_is_independent_of_axis_a() {
    let mut rig = Rig::new();
    rig.enable(1);
    assert_eq!(rig.state(1), State::OperationEnabled);
    assert_eq!(rig.state(0), State::SwitchOnDisabled);
    assert_eq!(rig.get(1, E48, 0), 4);
    assert_eq!(rig.get(0, E48, 0), 1);
    let mut target = 0;
    for _ in 0..200 {
        target += REV_I / 1000;
        rig.set(1, 0x607A, 0, target);
        rig.cycle();
    }
    rig.run(400);
    assert!(
        (i64::from(rig.position(1)) - target).abs() < 20,
        "{} vs {target}",
        rig.position(1)
    );
    assert_eq!(rig.position(0), 0);
    assert!(!rig.commands[0].power_stage);
    assert!(rig.commands[1].power_stage);
    // a fault on B leaves A alone
    rig.enable(0);
    rig.drive.axes_mut()[1].raise_event(Event { number: 54, cause: 1 });
    rig.run_until(100, |r| r.state(1) == State::Fault);
    assert_eq!(rig.state(0), State::OperationEnabled);
    assert_eq!(rig.get(1, 0x603F, 0), 0x8611);
    assert_eq!(rig.get(0, 0x603F, 0), 0);
}

#[test]
fn c122_touch_probe_latches_the_rising_edge() {
    let mut rig = Rig::probe1_armed();
    assert_eq!(rig.get(0, 0x60B9, 0), 0x01);
    rig.motors[0].theta = TAU; // one revolution
    rig.probe1_rising(Some(777));
    rig.cycle();
    assert_eq!(rig.get(0, 0x60BA, 0), 777);
    assert_eq!(rig.get(0, 0x60B9, 0), 0x03);
    // a second edge is ignored in first-event mode (C-124)
    rig.probe1_rising(None);
    rig.cycle();
    assert_eq!(rig.get(0, 0x60BA, 0), 777);
}

/// C-109 with C-122: a latched probe value is shown in the user units of
/// the moment, so a new feed constant (6092h) converts it again although
/// the probe latched nothing new.
#[test]
fn c109_c122_probe_value_follows_a_new_feed_constant() {
    let mut rig = Rig::probe1_armed();
    rig.probe1_rising(Some(1000));
    rig.cycle();
    rig.io[0].probe_edges[0] = None;
    assert_eq!(rig.get(0, 0x60BA, 0), 1000);
    rig.run(3);
    assert_eq!(rig.get(0, 0x60BA, 0), 1000);
    // half a user unit per increment
    rig.set(0, 0x6092, 1, REV_I / 2);
    rig.run(1);
    assert_eq!(rig.get(0, 0x60BA, 0), 500);
}

#[test]
fn c027_mode_change_between_classes_waits_for_standstill() {
    let mut rig = Rig::new();
    rig.set(0, 0x6060, 0, 9);
    rig.enable(0);
    rig.set(0, 0x60FF, 0, 2 * REV_I);
    rig.run(100);
    rig.set(0, 0x6060, 0, 3); // pv: drive-based
    rig.run(5);
    assert_eq!(rig.get(0, 0x6061, 0), 9, "moving: csv stays");
    rig.set(0, 0x60FF, 0, 0);
    rig.run_until(300, |r| r.get(0, 0x6061, 0) == 3);
    // pv then runs on its own profile
    rig.set(0, 0x60FF, 0, REV_I);
    rig.run_until(500, |r| r.sw(0) & SW_TARGET_REACHED != 0);
    rig.run(200);
    assert!(
        (i64::from(rig.velocity(0)) - REV_I).abs() < REV_I / 50,
        "{}",
        rig.velocity(0)
    );
}

#[test]
fn c088_jog_positive_and_stop() {
    let mut rig = Rig::new();
    rig.set(0, 0x6060, 0, -1);
    rig.enable(0);
    rig.controlword(0, 0x1F);
    rig.run(300);
    let v = rig.velocity(0);
    assert!((i64::from(v) - REV_I).abs() < REV_I / 20, "jog velocity {v}");
    rig.controlword(0, 0x0F);
    rig.run(300);
    assert!(rig.velocity(0).abs() < REV_I as i32 / 100);
}

#[test]
fn c110_polarity_inverts_position_and_torque() {
    let mut rig = Rig::new();
    rig.set(0, 0x607E, 0, 0x80);
    rig.set(0, 0x6060, 0, 9);
    rig.motors[0].theta = TAU / 4.0; // +1/4 rev at the motor
    rig.run(2);
    assert!((rig.position(0) + (1 << 18)).abs() <= 1, "{}", rig.position(0));
    rig.enable(0);
    rig.set(0, 0x60FF, 0, REV_I);
    rig.run(200);
    assert!((i64::from(rig.velocity(0)) - REV_I).abs() < REV_I / 50);
    assert!(rig.motors[0].velocity_inc_per_s() < -0.9 * REV_I as f64);
}

#[test]
fn c144_invalid_cycle_settings_fall_back() {
    let mut rig = Rig::new();
    // 60C2h = 3 ms over A150 = 1 ms: N = 3, set-points every cycle are fine
    rig.set(0, 0x60C2, 1, 3);
    rig.enable(0);
    assert_eq!(
        rig.drive.objects().get(objects_a291(), 0).unwrap(),
        3000,
        "60C2h copied into A291 (C-114)"
    );
    for k in 1..=300 {
        rig.set(0, 0x607A, 0, k * 1000);
        rig.cycle();
    }
    rig.run(300);
    assert!((rig.position(0) - 300_000).abs() < 100, "{}", rig.position(0));
    // a period that is no multiple of A150 falls back to N = 1
    rig.set(0, 0x60C2, 1, 15);
    rig.set(0, 0x60C2, 2, -4);
    rig.run(5);
    assert_eq!(rig.state(0), State::OperationEnabled);
}

fn objects_a291() -> u16 {
    crate::parameter_index(0, 291)
}

/// Arbitrary values in every set-point and configuration object never
/// panic and never leave the statusword without a state pattern.
#[test]
fn arbitrary_object_values_do_not_panic() {
    let mut rig = Rig::new();
    rig.set(1, 0x6040, 0, 0x0F);
    // both limit switches evaluated (I101/I102 = 1, the inputs), a
    // following error a fault (I470 = 1)
    for axis in 0..2 {
        rig.set(axis, crate::params::I101, 0, 1);
        rig.set(axis, crate::params::I101 + 1, 0, 1);
        rig.set(axis, crate::params::I470, 0, 1);
    }
    let mut seed: u64 = 0x1234_5678_9ABC_DEF0;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    let objects: &[(u16, u8)] = &[
        (0x6040, 0),
        (0x6060, 0),
        (0x607A, 0),
        (0x60FF, 0),
        (0x6071, 0),
        (0x60B1, 0),
        (0x60B2, 0),
        (0x6072, 0),
        (0x6081, 0),
        (0x6083, 0),
        (0x6084, 0),
        (0x6085, 0),
        (0x60A4, 1),
        (0x605A, 0),
        (0x605E, 0),
        (0x6065, 0),
        (0x607D, 1),
        (0x607D, 2),
        (0x607E, 0),
        (0x6098, 0),
        (0x6099, 1),
        (0x609A, 0),
        (0x60B8, 0),
        (0x60C1, 1),
        (0x60C2, 1),
        (0x60C2, 2),
        (0x6042, 0),
        (0x6087, 0),
        (0x60F2, 0),
    ];
    for _ in 0..3000 {
        let r = next();
        let (index, sub) = objects[(r % objects.len() as u64) as usize];
        let axis = (r >> 8) as usize % 2;
        // any value the type holds
        let _ = rig
            .drive
            .objects_mut()
            .set(Rig::index(axis, index), sub, (r >> 16) as i32 as i64);
        if r & 0x3000 == 0 {
            rig.io[axis].limit_positive ^= true;
        }
        if r & 0xC000 == 0 {
            rig.io[axis].limit_negative ^= true;
        }
        rig.cycle();
        for a in 0..2 {
            assert!(State::from_statusword(rig.sw(a)).is_some());
            assert!(rig.commands[a].torque_nm.is_finite());
        }
    }
}

#[test]
fn axis_memory_footprint() {
    extern crate std;
    std::println!("size_of::<Axis>() = {} bytes", core::mem::size_of::<Axis>());
    assert!(core::mem::size_of::<Axis>() < 4096);
}

#[test]
fn c094_c095_hardware_limit_switch_faults_and_locks_the_direction() {
    let mut rig = Rig::new();
    // I101 = 1: +LS from its input
    rig.set(0, crate::params::I101, 0, 1);
    rig.set(0, 0x6060, 0, 9);
    rig.enable(0);
    rig.set(0, 0x60FF, 0, REV_I);
    rig.run(100);
    rig.io[0].limit_positive = true;
    rig.run_until(200, |r| r.state(0) == State::Fault);
    assert_eq!(rig.get(0, 0x603F, 0), 0x8500, "event 53");
    assert_eq!(rig.drive.slave().emergencies_pending(), 1);
    // acknowledge, enable again: positive motion refused, negative allowed
    rig.controlword(0, 0x80);
    rig.run(2);
    rig.enable(0);
    rig.run(100);
    assert!(
        rig.velocity(0).abs() < REV_I as i32 / 100,
        "locked: {}",
        rig.velocity(0)
    );
    assert_ne!(
        rig.sw(0) & SW_INTERNAL_LIMIT,
        0,
        "direction lock shows as internal limit"
    );
    rig.set(0, 0x60FF, 0, -REV_I);
    rig.run(200);
    assert!(rig.velocity(0) < -(REV_I as i32) / 2);
    assert_eq!(rig.state(0), State::OperationEnabled);
}

/// Method 19 on a reference switch from X on (motor increments), with or
/// without the hardware's latched edge; returns the error of the edge's
/// reading against 607Ch.
fn method_19_edge_error(latched: bool) -> i64 {
    const X: i32 = 300_000;
    let mut rig = Rig::new();
    rig.set(0, 0x6098, 0, 19);
    rig.set(0, 0x607C, 0, 0);
    rig.set(0, 0x6060, 0, 6);
    rig.enable(0);
    rig.controlword(0, 0x1F);
    let mut last = rig.motors[0].position_inc();
    let mut done = false;
    for _ in 0..10_000 {
        let now = rig.motors[0].position_inc();
        rig.io[0].reference = now >= X;
        rig.io[0].switch_edges = [None; 4];
        if latched && (last >= X) != (now >= X) {
            rig.io[0].switch_edges[0] = Some(SwitchEdge {
                switch: SwitchId::Reference,
                position_inc: X,
            });
        }
        last = now;
        rig.cycle();
        if rig.sw(0) & 0x1400 == 0x1400 {
            done = true;
            break;
        }
    }
    assert!(done, "homing done: {:#06x}", rig.sw(0));
    rig.controlword(0, 0x0F);
    rig.run(50);
    // the switch edge X (motor increments) reads, in 6064h:
    i64::from(rig.position(0)) - i64::from(rig.motors[0].position_inc() - X)
}

#[test]
fn c071_homing_takes_the_latched_switch_edge() {
    let level = method_19_edge_error(false);
    let latched = method_19_edge_error(true);
    // creep 6099h:02 = 0.25 rev/s: one cycle is 262 increments
    assert!(
        level.abs() <= 2 * 262,
        "level only: within two creep steps: {level}"
    );
    assert!(latched.abs() <= 2, "latched edge: exact: {latched}");
    assert!(latched.abs() < level.abs(), "{latched} vs {level}");
}
