//! B44 "identify mechanics" (issue 35, `drive_core::tuning::mechanics`) on
//! the electrical plant (the 16 kHz current loop on the PMSM, the rigid
//! mechanics of `hil_sim::motor` behind it) whose inertia and friction the
//! drive does not know: the demo's csp profile (10 rev out and back, 1.5 s
//! each) before the action, with the dictionary's hand-set gains, and after
//! it, with the gains for B48's bandwidth and the feedforward from the
//! identified J, Fc and B; and the identified figures beside the plant's.
//! Two plants: the simulated servo, and the same with 5× its inertia and 3×
//! its friction (goal of issue 35: following error max ≤ 500 inc, rms ≤
//! 100 inc; J within 5 %, the friction within 10 %).
//!
//! The same on PROFINET: the demo's sequence (`hil_sim::fb::sequence`, the
//! Example Function block's telegrams against the simulated PROFINET drive,
//! `demo --fieldbus profinet`) on both plants, without and with its
//! self-tuning phase (B44 started and read through the telegram's PKW
//! channel, `--self-tune`): the positioning moves' following error (the
//! appended chain T1…T3 and the relative move; goal of issue 35: max ≤ 500
//! inc per move).
//!
//! `cargo bench -p hil-sim --bench selftune`
//!
//! No master: the set-points and A75 are written into the dictionary as a
//! decoded RxPDO would (A75 mapped in 1600h: action activation, E-142), the
//! drive polls an ESC without a master (the actions' pass) and runs its
//! control cycle every 1 ms; `hil-sim/tests/soem/mechanics.py` runs the
//! action through SOEM.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drive_ecat::axis::AxisIo;
use drive_ecat::params::{B44, B45, B46, B47, C31, C32, I20};
use hil_sim::electrical::{ElectricalAxis, PlantModel};
use hil_sim::esc::{Esc, EscConfig};
use hil_sim::fb::sequence::{self, MoveFe, Observer, Options, Report};
use hil_sim::motor::Motor;
use hil_sim::sim::{SimFlash, CONTROL_CYCLE};
use nanos::Nanos;

mod common;
use common::{enable_csp, follow_profile, SimDrive};

/// A75 (axis A).
const A75: u16 = drive_ecat::actions::A75;
/// A69 (axis A).
const A69: u16 = drive_ecat::actions::A69;

/// The plant and the bus side of the drive: all but the drive.
struct World {
    esc: Esc,
    motors: [Motor; 2],
    el: [ElectricalAxis; 2],
    pos: [i32; 2],
    now: Nanos,
}

impl World {
    /// The servo with `j_factor` × its inertia and `friction_factor` × its
    /// friction (Coulomb, breakaway, viscous).
    fn new(j_factor: f64, friction_factor: f64) -> Self {
        let mut motors = [Motor::default_servo(), Motor::default_servo()];
        for m in &mut motors {
            let p = m.params_mut();
            p.inertia_kg_m2 *= j_factor;
            p.coulomb_friction_nm *= friction_factor;
            p.static_friction_nm *= friction_factor;
            p.viscous_friction_nm_s_per_rad *= friction_factor;
        }
        Self {
            esc: Esc::new(EscConfig::default(), &[]),
            motors,
            el: [
                ElectricalAxis::default_servo(0).unwrap(),
                ElectricalAxis::default_servo(1).unwrap(),
            ],
            pos: [0; 2],
            now: Nanos::ZERO,
        }
    }

    /// One control cycle: the drive's poll (the actions' pass), its control
    /// cycle, both axes' current loops and motors.
    fn step(&mut self, drive: &mut SimDrive) {
        self.now += CONTROL_CYCLE;
        let _ = drive.poll(&mut self.esc, self.now);
        let io = [AxisIo::ready(self.pos[0]), AxisIo::ready(self.pos[1])];
        let cmd = drive.control_cycle_with(self.now, &io, [true, true]);
        for ((c, el), (motor, pos)) in cmd
            .iter()
            .zip(&mut self.el)
            .zip(self.motors.iter_mut().zip(&mut self.pos))
        {
            let torque = if c.power_stage {
                f64::from(c.torque_nm)
            } else {
                0.0
            };
            *pos = el
                .step(motor, torque, c.power_stage, !c.brake_release, CONTROL_CYCLE)
                .position_inc;
        }
    }

    fn controlword(&mut self, drive: &mut SimDrive, cw: i64, cycles: usize) {
        for axis in 0..2u16 {
            drive.objects_mut().set(0x6040 + 0x800 * axis, 0, cw).unwrap();
        }
        for _ in 0..cycles {
            self.step(drive);
        }
    }

    /// The demo's profile on both axes from rest at 0, then disabled:
    /// axis A's following error max and rms, inc.
    fn demo(&mut self, drive: &mut SimDrive) -> (f64, f64) {
        enable_csp(drive, |d| self.step(d));
        let (max, sq, total) = follow_profile(drive, 1500, |d| self.step(d));
        self.controlword(drive, 0x06, 20);
        (max, (sq / total as f64).sqrt())
    }

    /// B44 on axis A through A75 (started in Ready to switch on, run after
    /// the enable, Execute low at its end, disabled); A69 at the end and the
    /// simulated seconds it took.
    fn identify(&mut self, drive: &mut SimDrive) -> (u16, f64) {
        let od = drive.objects_mut();
        let n = od.get(0x1600, 0).unwrap() as u8;
        od.set(0x1600, 0, 0).unwrap();
        od.set(0x1600, n + 1, i64::from(u32::from(A75) << 16 | 8))
            .unwrap();
        od.set(0x1600, 0, i64::from(n + 1)).unwrap();
        for axis in 0..2u16 {
            od.set(0x607A + 0x800 * axis, 0, 0).unwrap();
        }
        self.controlword(drive, 0x06, 10);
        drive.objects_mut().set(A75, 0, 0b1111 << 1 | 1).unwrap();
        self.step(drive);
        let t0 = self.now;
        drive.objects_mut().set(0x6040, 0, 0x0F).unwrap();
        let mut a69 = 0u16;
        for _ in 0..30_000 {
            self.step(drive);
            a69 = drive.objects().get(A69, 0).unwrap() as u16;
            if a69 >> 12 != 1 {
                break;
            }
        }
        let secs = (self.now.as_ns() - t0.as_ns()) as f64 * 1e-9;
        drive.objects_mut().set(A75, 0, 0b1111 << 1).unwrap();
        self.controlword(drive, 0x06, 20);
        (a69, secs)
    }
}

/// Hears nothing: the figures are in the report.
struct Quiet;

impl Observer for Quiet {
    fn line(&mut self, _t: Nanos, _text: &str) {}
}

/// The PROFINET demo's sequence on the servo with `mechanics` (J, friction
/// factors), with or without self-tuning.
fn pn_run(mechanics: (f64, f64), self_tune: bool, bandwidth_hz: Option<u16>) -> Report {
    let options = Options {
        plant: PlantModel::Electrical,
        self_tune,
        mechanics,
        bandwidth_hz,
    };
    let (r, _) = sequence::run_with(&mut Quiet, None, options).unwrap();
    assert_eq!(r.moves.len(), 2, "{:?}", r.deviations);
    r
}

fn moves(m: &[MoveFe]) -> String {
    m.iter()
        .map(|m| format!("{:>6} {:>6.1}", m.max_inc, m.rms_inc))
        .collect::<Vec<_>>()
        .join(" | ")
}

fn profinet() {
    println!();
    println!("PROFINET: the demo's sequence (Example FB telegrams, 1 ms), its positioning moves (the chain T1…T3 to 8 rev, the relative move -2 rev): FE max / rms inc, before and after B44 through PKW (B48 as the drive has it, 60 Hz, or written first)");
    println!(
        "{:<26} | {:>13} | {:>13} | {:>8} {:>8} {:>8} | {:>13} | {:>13}",
        "plant", "chain before", "rel. before", "J err %", "Fc err %", "B err %", "chain after", "rel. after"
    );
    for (name, jf, ff, bw) in [
        ("servo", 1.0, 1.0, None),
        ("servo, 5× J, 3× friction", 5.0, 3.0, None),
        ("servo, B48 30 Hz", 1.0, 1.0, Some(30)),
        ("5× J, 3× fr., B48 30 Hz", 5.0, 3.0, Some(30)),
    ] {
        let before = pn_run((jf, ff), false, None);
        let after = pn_run((jf, ff), true, bw);
        let t = after.self_tune.unwrap();
        assert_eq!(
            (t.a69 >> 12, t.code),
            (2, 0),
            "{name}: {t:?} {:?}",
            after.deviations
        );
        let p = *Motor::default_servo().params();
        let err = |v: u32, scale: f64, truth: f64| (f64::from(v) * scale - truth) / truth * 100.0;
        let ej = err(t.inertia, 1e-7, p.inertia_kg_m2 * jf);
        let ec = err(t.coulomb, 1e-6, p.coulomb_friction_nm * ff);
        let eb = err(t.viscous, 1e-9, p.viscous_friction_nm_s_per_rad * ff);
        println!(
            "{name:<26} | {} | {ej:>+8.2} {ec:>+8.2} {eb:>+8.2} | {}   (B44 {} ms; deviations {})",
            moves(&before.moves),
            moves(&after.moves),
            t.ms,
            after.deviations.len()
        );
    }
}

fn main() {
    println!("B44 identify mechanics on the electrical plant; the demo's csp profile (10 rev out and back, 1.5 s each), 1 ms, before and after");
    println!(
        "{:<26} | {:>9} {:>8} | {:>8} {:>8} {:>8} {:>7} | {:>9} {:>8}",
        "plant", "FE max", "FE rms", "J err %", "Fc err %", "B err %", "time s", "FE max", "FE rms"
    );
    for (name, jf, ff) in [("servo", 1.0, 1.0), ("servo, 5× J, 3× friction", 5.0, 3.0)] {
        let mut world = World::new(jf, ff);
        let mut drive = drive_ecat::runtime::Drive::new(SimFlash::new());
        let (max0, rms0) = world.demo(&mut drive);
        let (a69, secs) = world.identify(&mut drive);
        let od = drive.objects();
        let code = od.get(B44, 1).unwrap();
        assert_eq!(a69 >> 12, 2, "{name}: A69 {a69:04x}, B44[0] {code}");
        let p = *world.motors[0].params();
        let err = |v: i64, scale: f64, truth: f64| (v as f64 * scale - truth) / truth * 100.0;
        let ej = err(od.get(B45, 0).unwrap(), 1e-7, p.inertia_kg_m2);
        let ec = err(od.get(B46, 0).unwrap(), 1e-6, p.coulomb_friction_nm);
        let eb = err(od.get(B47, 0).unwrap(), 1e-9, p.viscous_friction_nm_s_per_rad);
        let gains = [C31, C32, I20].map(|i| od.get(i, 0).unwrap());
        let (max1, rms1) = world.demo(&mut drive);
        assert!(
            world.el[0].foc().trip().is_none(),
            "{name}: {:?}",
            world.el[0].foc().trip()
        );
        println!(
            "{name:<26} | {max0:>9.0} {rms0:>8.1} | {ej:>+8.2} {ec:>+8.2} {eb:>+8.2} {secs:>7.2} | {max1:>9.0} {rms1:>8.1}   (C31 {} µN·m·s/rad, C32 {} µs, I20 {} × 0.1/s)",
            gains[0], gains[1], gains[2]
        );
    }
    profinet();
}
