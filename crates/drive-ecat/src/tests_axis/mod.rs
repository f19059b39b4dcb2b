//! The axis runtime against a rigid-body motor model: J = 1e-4 kg·m², viscous
//! friction, one control cycle of actuation delay. Objects are written with
//! `DriveObjects::set`, as the PDO/SDO side would.
//!
//! Here: the motor model, the rig and `home_here`; the tests, by topic, in the submodules.

use crate::axis::*;
use crate::params::E48;
use crate::runtime::Drive;
use cia402::{State, SW_INTERNAL_LIMIT, SW_MODE_BIT12, SW_MODE_BIT13, SW_TARGET_REACHED};
use motion::{Event, INCREMENTS_PER_REVOLUTION};
use nanos::Nanos;

use store::RamFlash;

mod config;
mod device_control;
mod homing_probe;
mod modes;

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
