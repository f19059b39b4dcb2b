//! The DC link as a state of the plant against the energy balance (issue 34,
//! E-090's brake chopper): a flywheel braked by the current loop charges the
//! capacitor by what the mechanics lose less the copper's losses.
#![allow(clippy::unwrap_used)] // a test helper that fails is a failed test

use foc::chopper::{BrakeChopper, ChopperParams};
use foc::{Dq, FocAxis, PowerStage, Trip};
use plant::{Plant, PlantParams, Shaft};

/// A flywheel of J = 0.01 kg·m² (100 × the servo's rotor), frictionless,
/// turning at `speed` rad/s, brake resistor `r_brake` Ω.
fn flywheel(speed: f64, r_brake: f64) -> (Plant, FocAxis) {
    let mut p = PlantParams::default_servo();
    p.mech.inertia_kg_m2 = 0.01;
    p.mech.viscous_nm_s_per_rad = 0.0;
    p.mech.coulomb_nm = 0.0;
    p.mech.shaft = Shaft::Driven { speed_rad_s: speed };
    if let Some(dc) = p.dc_link.as_mut() {
        dc.brake_resistor_ohm = r_brake;
    }
    let mut pl = Plant::new(p);
    pl.set_shaft(Shaft::Free);
    let mut a = FocAxis::default_servo(p.scaling()).unwrap();
    a.enable(true);
    (pl, a)
}

/// Copper losses of one PWM period (the plant's true currents at its start
/// and end, trapezoid), J.
fn copper_j(pl: &Plant, before: (f64, f64), dt: f64) -> f64 {
    let r = pl.params().motor.r_ohm;
    let p = |(id, iq): (f64, f64)| 1.5 * r * (id * id + iq * iq);
    0.5 * (p(before) + p((pl.id(), pl.iq()))) * dt
}

/// E-090 / event 36: braking a flywheel from 3000 rpm at −6 A without a brake
/// resistor (A21 = 0) charges the DC link by ½J(ω1² − ω2²) − copper losses =
/// ½C(V2² − V1²) (within 1 %), until it passes the stage's over-voltage trip
/// (800 V): the gates are off in the period whose sample saw it.
#[test]
fn e090_braking_without_resistor_charges_the_link_by_the_energy_balance_and_trips() {
    let w1 = 3000.0 / 60.0 * std::f64::consts::TAU;
    let (mut pl, mut a) = flywheel(w1, 0.0);
    let (j, c) = (0.01, pl.params().dc_link.unwrap().capacitance_f);
    let v1 = pl.dc_link_v();
    let dt = pl.params().period_s();
    let reference = Dq { d: 0.0, q: -6.0 };
    let mut e_cu = 0.0;
    let mut tripped_at = None;
    for k in 0..16_000u32 {
        let s = pl.sample();
        let out = a.step(&s, reference);
        if a.trip().is_some() {
            assert!(!out.gate_enable, "gates off in the period that saw it");
            tripped_at = Some((k, f64::from(s.dc_link_count) * 0.25));
            break;
        }
        pl.apply(&out);
        let before = (pl.id(), pl.iq());
        pl.advance();
        e_cu += copper_j(&pl, before, dt);
    }
    let (k, seen_v) = tripped_at.expect("the link never reached the trip");
    assert_eq!(a.trip(), Some(Trip::DcOverVoltage));
    assert!(seen_v > 800.0, "tripped at {seen_v} V");
    let w2 = pl.speed_rad_s();
    let v2 = pl.dc_link_v();
    let kinetic = 0.5 * j * (w1 * w1 - w2 * w2);
    let stored = 0.5 * c * (v2 * v2 - v1 * v1);
    let mains = pl.mains_energy_j();
    println!(
        "braked {:.1} ms: ΔE_kin {kinetic:.2} J − copper {e_cu:.2} J = {:.2} J, ½C(V2²−V1²) {stored:.2} J \
         ({v1:.1} → {v2:.1} V), mains {mains:.3} J",
        f64::from(k) * dt * 1e3,
        kinetic - e_cu
    );
    // the rectifier conducts only in the first periods (the current's rise
    // motors for a moment): 0.1 % of the energy at most, and in the balance
    assert!(mains < 1e-3 * kinetic, "the rectifier fed {mains} J");
    let err = (kinetic - e_cu + mains - stored) / stored;
    assert!(err.abs() < 0.01, "energy balance off by {:.2} %", err * 100.0);
}

/// E-090: with the 100 Ω resistor on the chopper (on at 760 V, 20 V
/// hysteresis) the same braking holds the link inside the hysteresis band
/// (give or take 2 V: one period's fall through the resistor,
/// V/(R·C)·T = 1.0 V, and the DC-link ADC's noise, σ = 0.25 V) and trips
/// nothing; the energy
/// the resistor took closes the balance.
#[test]
fn e090_the_chopper_holds_the_link_within_its_hysteresis() {
    let w1 = 3000.0 / 60.0 * std::f64::consts::TAU;
    let (mut pl, mut a) = flywheel(w1, 100.0);
    let (j, c) = (0.01, pl.params().dc_link.unwrap().capacitance_f);
    let v1 = pl.dc_link_v();
    let dt = pl.params().period_s();
    let cp = ChopperParams::default_stage();
    let mut ch = BrakeChopper::new(cp, dt as f32);
    let reference = Dq { d: 0.0, q: -6.0 };
    let mut e_cu = 0.0;
    let (mut hi, mut lo_after_on) = (0.0f64, f64::INFINITY);
    for _ in 0..(16_000 * 3 / 10) {
        let s = pl.sample();
        let out = a.step(&s, reference);
        pl.set_chopper(ch.step(a.measured().vdc));
        pl.apply(&out);
        let before = (pl.id(), pl.iq());
        pl.advance();
        e_cu += copper_j(&pl, before, dt);
        hi = hi.max(pl.dc_link_v());
        if ch.on_periods() > 0 {
            lo_after_on = lo_after_on.min(pl.dc_link_v());
        }
    }
    assert_eq!(a.trip(), None);
    assert!(ch.on_periods() > 0, "the chopper never switched");
    println!(
        "chopper: link {lo_after_on:.1} … {hi:.1} V (band {:.0} … {:.0} V), on {} of {} periods, \
         resistor {:.1} J",
        cp.on_v - cp.hysteresis_v,
        cp.on_v,
        ch.on_periods(),
        16_000 * 3 / 10,
        pl.brake_energy_j()
    );
    assert!(hi < f64::from(cp.on_v) + 2.0, "peak {hi} V");
    assert!(
        lo_after_on > f64::from(cp.on_v - cp.hysteresis_v) - 2.0,
        "low {lo_after_on} V"
    );
    let w2 = pl.speed_rad_s();
    let v2 = pl.dc_link_v();
    let lhs = 0.5 * j * (w1 * w1 - w2 * w2) - e_cu;
    let rhs = 0.5 * c * (v2 * v2 - v1 * v1) + pl.brake_energy_j() - pl.mains_energy_j();
    let err = (lhs - rhs) / rhs;
    assert!(err.abs() < 0.01, "energy balance off by {:.2} %", err * 100.0);
}

/// At rest (no current, the shaft turning) the link stays at the mains' peak
/// (565 V within 0.05 V, as the stiff source before); motoring at some 1.2 kW it sags by about R_source·P/V.
#[test]
fn the_link_stays_at_565_v_at_rest_and_sags_by_the_source_resistance_when_motoring() {
    let (mut pl, mut a) = flywheel(0.0, 100.0);
    pl.set_shaft(Shaft::Driven { speed_rad_s: 300.0 });
    for _ in 0..1600 {
        let s = pl.sample();
        let out = a.step(&s, Dq::default());
        pl.apply(&out);
        pl.advance();
    }
    assert!((pl.dc_link_v() - 565.0).abs() < 0.05, "{}", pl.dc_link_v());
    for _ in 0..16_000 {
        let s = pl.sample();
        let out = a.step(&s, Dq { d: 0.0, q: 6.0 });
        pl.apply(&out);
        pl.advance();
    }
    let p_mech = pl.torque_nm() * 300.0;
    let p_cu = 1.5 * pl.params().motor.r_ohm * pl.iq() * pl.iq();
    let v = pl.dc_link_v();
    let i = (p_mech + p_cu) / v;
    let expected = 565.0 - 1.0 * i;
    println!(
        "motoring {:.0} W: link {v:.2} V, closed form {expected:.2} V",
        p_mech + p_cu
    );
    assert!(
        (v - expected).abs() < 0.05 * (565.0 - expected),
        "{v} vs {expected}"
    );
}
