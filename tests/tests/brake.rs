//! The holding brake's settings through the bus (issue 40; spec cia402.md
//! §5.1 and §14): F00 brake control and F06 release override written by
//! SDO from ethercrab, the brake seen at the simulated motor (its brake
//! input, one cycle after the drive's output) and the rotor's motion.

use drive_tests::{line, motor_rev_s, sw, with_cyclic, REV};
use hil_sim::sim::Simulation;
use std::cell::RefCell;

const F00: u16 = drive_ecat::parameter_index(5, 0);
const F06: u16 = drive_ecat::parameter_index(5, 6);

/// Whether axis A's brake is applied at the motor.
fn applied(sim: &RefCell<Simulation>) -> bool {
    sim.borrow().drives()[0]
        .motor_outputs(0)
        .expect("the motor has run")
        .brake_applied
}

/// C-020 (and E-129's "brake unless F06"): in the de-energised states the
/// brake is applied; F06 = 1 releases it there (Switch on disabled, Ready
/// to switch on), F06 = 0 applies it again; without brake control (F00 = 0)
/// the override does nothing.
#[test]
fn c020_e129_f06_release_override_releases_the_brake_in_the_de_energised_states() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        m.set_mode(9);
        let tx = m.run(5).await;
        assert_eq!(tx.state(), sw::SOD);
        let f00: u8 = sd.sdo_read(F00, 0).await.expect("F00");
        let f06: u8 = sd.sdo_read(F06, 0).await.expect("F06");
        assert_eq!((f00, f06), (1, 0), "defaults: brake control active, no override");
        assert!(applied(&sim), "Switch on disabled: applied");

        sd.sdo_write(F06, 0, 1u8).await.expect("F06 = 1");
        m.run(3).await;
        assert!(!applied(&sim), "F06 = 1 in Switch on disabled: released");
        m.command(0x0006, sw::RTSO, 10).await;
        m.run(3).await;
        assert!(!applied(&sim), "F06 = 1 in Ready to switch on: released");

        sd.sdo_write(F06, 0, 0u8).await.expect("F06 = 0");
        m.run(3).await;
        assert!(applied(&sim), "F06 = 0: applied again");

        sd.sdo_write(F00, 0, 0u8).await.expect("F00 = 0");
        sd.sdo_write(F06, 0, 1u8).await.expect("F06 = 1");
        m.run(3).await;
        assert!(applied(&sim), "F00 = 0: the override does nothing");
        // out of range: refused, nothing changes
        assert!(sd.sdo_write(F06, 0, 2u8).await.is_err(), "F06 = 2 refused");
        let f06: u8 = sd.sdo_read(F06, 0).await.expect("F06");
        assert_eq!(f06, 1);
    });
}

/// C-021 with F00: brake control active (default), the first motion
/// command in csv releases the brake and the rotor turns at the commanded
/// 2 rev/s; F00 = 0 in Operation enabled applies it (the drive no longer
/// controls it): the 2 N·m holding brake outholds the 1.3 N·m motor and
/// the rotor stops; F00 = 1 releases it and the speed comes back.
#[test]
fn c021_f00_brake_control_inactive_keeps_the_brake_applied_while_enabled() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        m.csv_at(2 * REV, 300).await;
        assert!(!applied(&sim), "F00 = 1, moving: released");
        let v = motor_rev_s(&sim, 0);
        assert!((v - 2.0).abs() < 0.1, "2 rev/s: {v}");

        sd.sdo_write(F00, 0, 0u8).await.expect("F00 = 0");
        let tx = m.run(300).await;
        assert_eq!(tx.state(), sw::OE, "still enabled");
        assert!(applied(&sim), "F00 = 0: applied");
        let v = motor_rev_s(&sim, 0);
        assert!(v.abs() < 0.05, "held by the brake: {v} rev/s");

        sd.sdo_write(F00, 0, 1u8).await.expect("F00 = 1");
        m.run(300).await;
        assert!(!applied(&sim), "F00 = 1 again: released");
        let v = motor_rev_s(&sim, 0);
        assert!((v - 2.0).abs() < 0.1, "2 rev/s again: {v}");
    });
}
