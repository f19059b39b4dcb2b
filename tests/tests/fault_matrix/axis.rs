//! Faults at the axis: encoder fault, STO and supply undervoltage during
//! motion, a limit switch against the travel during homing.

use super::{emcys, end_then_reset, ethercrab, reset_and_enable};
use drive_tests::axis::{limit_switches_from_inputs, line_with_switches, with_drive, CW_BIT4, CW_ENABLED};
use drive_tests::matrix::{al, cia402_state, emcys as show_emcys};
use drive_tests::{al_status, fault_row, init, line, with_cyclic, with_master, Cyclic, REV};
use hil_sim::motor::{PositionInput, Switches};
use hil_sim::sim::AxisConditions;

/// Axis A at 2 rev/s in csv; `cause` happens to it; after 100 ms the end
/// is read (state, power stage, EMCY, 603Fh, E47, the history, AL); then
/// a fault reset while the cause lasts, and after `clear` ended it a reset
/// and the enable sequence again.
fn during_motion(cause: fn(&mut AxisConditions), clear: fn(&mut AxisConditions)) -> String {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        m.csv_at(2 * REV, 300).await;
        with_drive(&sim, |d| cause(&mut d.conditions[0]));
        let tx = m.run(100).await;
        let stage = {
            let s = sim.borrow();
            let out = s.drives()[0].motor_outputs(0).unwrap();
            if out.torque_applied_nm == 0.0 && out.brake_applied {
                "power stage off, brake engaged"
            } else {
                "power stage on"
            }
        };
        // a fault reset while the cause lasts
        let (state, end, lasting, _) = end_then_reset(m, sd, &sim, tx).await;
        // the cause ends: reset, enable
        with_drive(&sim, |d| clear(&mut d.conditions[0]));
        let after = reset_and_enable(m).await;
        format!(
            "{state}, {stage}; {end}; \
             while the cause lasts a reset gives {lasting}; after it: {after}"
        )
    })
}

#[test]
fn e089_c017_encoder_fault_during_motion_is_event_37_and_holds_the_fault() {
    let row = ethercrab(
        "41",
        "motor encoder fails while axis A turns at 2 rev/s (csv)",
        "E-089, C-017",
        "Fault, power stage off, brake engaged; EMCY 7303h/01h event 37 cause 1; 603Fh 7303h; \
         E47 0; history: error 7303h axis A event 37/1; Op, AL 0000h; while the cause lasts a \
         reset gives Fault (E47 0); after it: Operation enabled",
    );
    let seen = during_motion(|c| c.encoder_ok = false, |c| c.encoder_ok = true);
    fault_row!(row, seen);
}

#[test]
fn c015_sto_during_motion_switches_the_power_stage_off_without_a_fault() {
    let row = ethercrab(
        "42",
        "STO while axis A turns at 2 rev/s (csv)",
        "C-015",
        "Switch on disabled, power stage off, brake engaged; no EMCY; 603Fh 0000h; E47 1; \
         history empty; Op, AL 0000h; while the cause lasts a reset gives Switch on disabled \
         (E47 1); after it: Operation enabled",
    );
    let seen = during_motion(|c| c.sto_active = true, |c| c.sto_active = false);
    fault_row!(row, seen);
}

#[test]
fn e089_c015_supply_undervoltage_during_motion_is_event_46() {
    let row = ethercrab(
        "43",
        "supply drops while axis A turns at 2 rev/s (csv)",
        "E-089, C-015",
        "Fault, power stage off, brake engaged; EMCY 3120h/04h event 46 cause 1; 603Fh 3120h; \
         E47 0; history: error 3120h axis A event 46/1; Op, AL 0000h; while the cause lasts a \
         reset gives Switch on disabled (E47 2); after it: Operation enabled",
    );
    let seen = during_motion(|c| c.supply_ok = false, |c| c.supply_ok = true);
    fault_row!(row, seen);
}

#[test]
fn c084_limit_switch_against_the_travel_during_homing_is_a_homing_error() {
    let row = ethercrab(
        "44",
        "homing method 1 (negative limit switch) runs into a limit switch wired as the positive one",
        "C-084",
        "Operation enabled, homing error, velocity 0 (bits 13, 12 set, 10 clear); no EMCY; \
         603Fh 0000h; Op, AL 0000h",
    );
    const R: i64 = REV as i64;
    // the switch the axis meets moving negative reads as the positive one
    let sim = line_with_switches(Switches {
        positive_limit: PositionInput::below(-2 * R).active_low(),
        negative_limit: PositionInput::never().active_low(),
        ..Switches::linear_axis(-10 * R, 10 * R, PositionInput::never())
    });
    let seen = with_master(&sim, async |md, clock| {
        let group = init(md, clock).await.into_op(md).await.expect("OP");
        // I101/I102 = 1: the limit switches from the inputs, by SDO (issue 40)
        let sd = group.subdevice(md, 0).unwrap();
        limit_switches_from_inputs(&sd).await;
        sd.sdo_write(0x6098, 0, 1i8).await.unwrap();
        let mut m = Cyclic::new(md, &group, &sim, 0);
        m.enable_in(6).await;
        m.set_controlword(CW_ENABLED | CW_BIT4);
        let ended = m
            .run_until(20_000, |t| t.bit(13) && t.bit(12) || t.state() != 0x27)
            .await;
        let p = sim.borrow().drives()[0].motors[0].position_inc_i64();
        assert!(ended.is_some(), "homing ends: {:#06x} at {p}", m.tx.statusword);
        let tx = m.run(20).await;
        let bits = match (tx.bit(13), tx.bit(12), tx.bit(10)) {
            (true, true, false) => "homing error, velocity 0 (bits 13, 12 set, 10 clear)".to_string(),
            (e, h, r) => format!("bits 13 {e}, 12 {h}, 10 {r}"),
        };
        let em = show_emcys(&emcys(&sd).await);
        let code: u16 = sd.sdo_read(0x603F, 0).await.unwrap();
        format!(
            "{}, {bits}; {em}; 603Fh {code:04X}h; {}",
            cia402_state(tx.statusword),
            al(al_status(&sd).await)
        )
    });
    fault_row!(row, seen);
}
