//! Faults of the power stage on the electrical plant (issue 34): the current
//! loop's protection (`foc::protect`) trips on what its samples show, the
//! gates go off in the PWM period after the fault appeared, and the axis
//! faults with the manual's event (`drive_core::axis::trip_event`).
//! The faults are the plant's (`plant::FaultOptions`, the DC link): a test
//! changes the motor, its wiring or the supply, never the drive.

use super::{end_then_reset, ethercrab, reset_and_enable};
use drive_tests::axis::with_drive;
use drive_tests::matrix::cia402_state;
use drive_tests::{fault_row, line, with_cyclic, REV};
use hil_sim::electrical::{ElectricalAxis, PlantModel};
use hil_sim::sim::SimDrive;
use plant::{FaultOptions, Phase};

fn axis_a(d: &mut SimDrive) -> &mut ElectricalAxis {
    d.electrical_mut(0).expect("axis A runs the electrical plant")
}

fn enabled_periods(d: &mut SimDrive) -> u64 {
    axis_a(d).stats().enabled_periods
}

/// [`during_loaded_motion`] with the DC link at `volts` (565 V again after)
/// and the motor's own friction.
fn during_dc_link(volts: f64) -> String {
    during_loaded_motion(
        None,
        |el| el.plant_mut().set_dc_link(volts),
        |el| el.plant_mut().set_dc_link(565.0),
    )
}

/// [`during_loaded_motion`] with the faults `fault` sets in axis A's plant
/// (cleared after).
fn during_plant_fault(friction_nm: Option<f64>, fault: fn(&mut FaultOptions)) -> String {
    let mut faults = FaultOptions::NONE;
    fault(&mut faults);
    during_loaded_motion(
        friction_nm,
        |el| el.plant_mut().set_faults(faults),
        |el| el.plant_mut().set_faults(FaultOptions::NONE),
    )
}

/// Axis A on the electrical plant at 2 rev/s in csv against `friction_nm`
/// of sliding friction on the motor's shaft (a load the current must
/// carry), else the motor's own; `cause` happens to its plant; after 100 ms
/// the end is read (state, the PWM periods with the gates on after the
/// fault, EMCY, 603Fh, E47, the history, AL); then a fault reset while the
/// cause lasts, and after `clear` ended it a reset and the enable sequence
/// again.
fn during_loaded_motion(
    friction_nm: Option<f64>,
    cause: impl Fn(&mut ElectricalAxis),
    clear: fn(&mut ElectricalAxis),
) -> String {
    let sim = line(1);
    with_drive(&sim, |d| {
        d.set_plant(PlantModel::Electrical, 34)
            .expect("the default servo");
        if let Some(f) = friction_nm {
            d.motors[0].params_mut().coulomb_friction_nm = f;
        }
    });
    with_cyclic(&sim, async |m, sd| {
        m.set_mode(9);
        m.run(3).await;
        m.enable().await;
        m.set_target_velocity(2 * REV);
        m.run(300).await;
        let mut before = 0;
        with_drive(&sim, |d| {
            before = enabled_periods(d);
            cause(axis_a(d));
        });
        let tx = m.run(100).await;
        let mut gated = 0;
        let mut stage = "";
        with_drive(&sim, |d| {
            gated = enabled_periods(d) - before;
            let phases = axis_a(d).plant().phase_currents();
            let out = d.motor_outputs(0).unwrap();
            let no_current = phases.iter().all(|i| i.abs() < 1e-6);
            stage = if out.torque_applied_nm == 0.0 && out.brake_applied && no_current {
                "power stage off, brake engaged"
            } else {
                "power stage on"
            };
        });
        // a fault reset while the cause lasts, and the enable into it
        let (state, end, mut lasting, tx) = end_then_reset(m, sd, &sim, tx).await;
        if cia402_state(tx.statusword) != "Fault" {
            m.set_controlword(0);
            m.run(2).await;
            // 60 cycles after the enable: an open phase is judged per
            // window of 16 ms, the enable's step of the reference (its
            // healthy transient) taken off the first (`foc`'s step allowance)
            for (cw, cycles) in [(0x0006, 20), (0x0007, 20), (0x000F, 60)] {
                m.set_controlword(cw);
                m.run(cycles).await;
            }
            lasting += &format!(", the enable into it: {}", cia402_state(m.tx.statusword));
        }
        // the cause ends: reset, enable
        with_drive(&sim, |d| clear(axis_a(d)));
        let after = reset_and_enable(m).await;
        format!(
            "{state}, {stage}, the gates on for {gated} PWM period(s) after the fault; {end}; \
             while the cause lasts a reset gives {lasting}; after it: {after}"
        )
    })
}

#[test]
fn e089_over_current_of_a_shorted_leg_on_the_electrical_plant_is_event_33() {
    let row = ethercrab(
        "45",
        "electrical plant: leg a shorted to the DC link's negative rail (1 Ω) while axis A turns \
         at 2 rev/s (csv)",
        "E-089",
        "Fault, power stage off, brake engaged, the gates on for 1 PWM period(s) after the \
         fault; EMCY 2310h/02h event 33 cause 2; 603Fh 2310h; E47 0; history: error 2310h axis \
         A event 33/2; Op, AL 0000h; while the cause lasts a reset gives Switch on disabled \
         (E47 4), the enable into it: Fault; after it: Operation enabled",
    );
    let seen = during_plant_fault(None, |f| f.leg_to_dc_minus = Some((Phase::A, 1.0)));
    fault_row!(row, seen);
}

#[test]
fn e089_an_earth_fault_on_the_electrical_plant_is_the_phase_sum_event_31() {
    let row = ethercrab(
        "46",
        "electrical plant: an earth fault of leg a (100 Ω to the DC link's negative rail: the three \
         measured currents no longer sum to zero) while axis A turns at 2 rev/s (csv)",
        "E-089",
        "Fault, power stage off, brake engaged, the gates on for 1 PWM period(s) after the fault; EMCY \
         2110h/02h event 31 cause 2; 603Fh 2110h; E47 0; history: error 2110h axis A event 31/2; Op, AL \
         0000h; while the cause lasts a reset gives Switch on disabled (E47 4), the enable into it: \
         Fault; after it: Operation enabled",
    );
    let seen = during_plant_fault(None, |f| f.leg_to_dc_minus = Some((Phase::A, 100.0)));
    fault_row!(row, seen);
}

#[test]
fn e089_a_dc_link_drop_on_the_electrical_plant_is_event_46() {
    let row = ethercrab(
        "47",
        "electrical plant: the DC link drops from 565 V to 300 V (below 400 V) while axis A turns \
         at 2 rev/s (csv)",
        "E-089",
        "Fault, power stage off, brake engaged, the gates on for 1 PWM period(s) after the fault; EMCY \
         3120h/04h event 46 cause 2; 603Fh 3120h; E47 0; history: error 3120h axis A event 46/2; Op, AL \
         0000h; while the cause lasts a reset gives Switch on disabled (E47 4), the enable into it: \
         Fault; after it: Operation enabled",
    );
    let seen = during_dc_link(300.0);
    fault_row!(row, seen);
}

#[test]
fn e089_a_dc_link_over_voltage_on_the_electrical_plant_is_event_36() {
    let row = ethercrab(
        "48",
        "electrical plant: the DC link rises from 565 V to 850 V (above 800 V) while axis A turns \
         at 2 rev/s (csv)",
        "E-089",
        "Fault, power stage off, brake engaged, the gates on for 1 PWM period(s) after the fault; EMCY \
         3110h/04h event 36 cause 2; 603Fh 3110h; E47 0; history: error 3110h axis A event 36/2; Op, AL \
         0000h; while the cause lasts a reset gives Fault (E47 0); after it: Operation enabled",
    );
    let seen = during_dc_link(850.0);
    fault_row!(row, seen);
}

#[test]
fn e089_c017_the_current_loops_encoder_lost_mid_move_is_event_37() {
    let row = ethercrab(
        "49",
        "electrical plant: the encoder the current loop commutates with fails while axis A turns \
         at 2 rev/s (csv)",
        "E-089, C-017",
        "Fault, power stage off, brake engaged, the gates on for 1 PWM period(s) after the fault; EMCY \
         7303h/01h event 37 cause 2; 603Fh 7303h; E47 0; history: error 7303h axis A event 37/2; Op, AL \
         0000h; while the cause lasts a reset gives Fault (E47 0); after it: Operation enabled",
    );
    let seen = during_plant_fault(None, |f| f.encoder_lost = true);
    fault_row!(row, seen);
}

/// The load of rows 49a/49b: half the default servo's rated torque (1.3
/// N·m) as sliding friction, so the current (about 1 A) is far above the
/// ADC's noise: a broken sensor or an open phase at no load shows in no
/// measurement (and harms nothing). The broken sensor shows at once (the
/// three currents no longer sum to zero); the open phase only as a current
/// that does not follow its reference, judged per i²t window of 256 PWM
/// periods (`foc::protect::CurrentDeviation`): the gates go off in the
/// period of the verdict, here the second window after the wire broke.
const HALF_RATED_NM: f64 = 0.65;

#[test]
fn e089_a_broken_current_sensor_under_load_on_the_electrical_plant_is_the_phase_sum_event_31() {
    let row = ethercrab(
        "49a",
        "electrical plant: leg b's current sensor breaks (reads zero whatever flows) while axis A \
         turns at 2 rev/s (csv) against 0.65 N·m of friction (50 % of the rated torque)",
        "E-089",
        "Fault, power stage off, brake engaged, the gates on for 1 PWM period(s) after the fault; EMCY \
         2110h/02h event 31 cause 2; 603Fh 2110h; E47 0; history: error 2110h axis A event 31/2; Op, AL \
         0000h; while the cause lasts a reset gives Switch on disabled (E47 4), the enable into it: \
         Fault; after it: Operation enabled",
    );
    let seen = during_plant_fault(Some(HALF_RATED_NM), |f| f.broken_sensor = Some(Phase::B));
    fault_row!(row, seen);
}

#[test]
fn e089_an_open_motor_phase_under_load_on_the_electrical_plant_is_event_69() {
    let row = ethercrab(
        "49b",
        "electrical plant: motor phase a opens (its wire broken) while axis A turns at 2 rev/s (csv) \
         against 0.65 N·m of friction (50 % of the rated torque)",
        "E-089",
        "Fault, power stage off, brake engaged, the gates on for 470 PWM period(s) after the fault; \
         EMCY 7120h/01h event 69 cause 2; 603Fh 7120h; E47 0; history: error 7120h axis A event 69/2; \
         Op, AL 0000h; while the cause lasts a reset gives Switch on disabled (E47 4), the enable into \
         it: Fault; after it: Operation enabled",
    );
    let seen = during_plant_fault(Some(HALF_RATED_NM), |f| f.open_phase = Some(Phase::A));
    fault_row!(row, seen);
}
