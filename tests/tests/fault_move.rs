//! A pp move after a drive fault, its reset (bit 7) and the enable
//! sequence through ethercrab (C-017, C-021, C-041): the same move before
//! and after the fault, the same following error, the holding brake open
//! through both. The PROFINET twin (record tasks, where the brake stayed
//! engaged after a fault) is hil-sim/tests/pn_fault_move.rs; on EtherCAT pp
//! the first set-point (bit 4) after the enable opens the brake.

use drive_tests::axis::*;
use drive_tests::{line, sw, with_cyclic, Cyclic};
use drive_tests::{REV, REV_F};
use std::cell::RefCell;

/// A pp move to `target` (bit 4 edge): the largest |60F4h| until bit 10,
/// and whether the brake acted in any cycle after the set-point.
async fn pp_move(m: &mut Cyclic<'_>, sim: &RefCell<hil_sim::sim::Simulation>, target: i32) -> (i32, bool) {
    m.set_target_position(target);
    m.set_controlword(CW_ENABLED);
    m.run(1).await;
    m.set_controlword(CW_ENABLED | CW_BIT4);
    m.run_until(5, |t| t.bit(12))
        .await
        .expect("set-point acknowledged");
    m.set_controlword(CW_ENABLED);
    let (mut worst, mut braked) = (0i32, false);
    let mut reached = false;
    for _ in 0..3000 {
        let tx = m.cycle().await;
        worst = worst.max(tx.following_error.abs());
        braked |= sim.borrow().drives()[0]
            .motor_outputs(0)
            .is_some_and(|o| o.brake_applied);
        if tx.bit(10) && !tx.bit(12) {
            reached = true;
            break;
        }
    }
    assert!(reached, "target {target} reached: {:#06x}", m.tx.statusword);
    assert!(
        (target - m.tx.position).abs() <= REV / 360,
        "at {target}: {}",
        m.tx.position
    );
    (worst, braked)
}

#[test]
fn c017_c021_c041_pp_after_fault_reset_and_enable_follows_as_before() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        set_profile(sd, Some(5 * REV as u32), 50 * REV as u32).await;
        m.enable_in(1).await;
        home_here(m).await;
        m.set_mode(1);
        m.run(3).await;

        let (before, braked_before) = pp_move(m, &sim, 3 * REV).await;
        // event 44 on axis A (as the power stage would raise it)
        sim.borrow_mut().drives_mut()[0].drive.axes_mut()[0]
            .raise_event(motion::Event { number: 44, cause: 1 });
        let hit = m.run_until(500, |t| t.state() == sw::FAULT).await;
        assert!(hit.is_some(), "fault: {:#06x}", m.tx.statusword);
        m.reset_and_enable().await;
        let (after, braked_after) = pp_move(m, &sim, 6 * REV).await;
        println!(
            "figure: pp 3 rev at 5 rev/s: max |60F4h| {before} inc before the fault, {after} inc after \
             reset and enable ({:.4} / {:.4} rev)",
            f64::from(before) / REV_F,
            f64::from(after) / REV_F
        );
        assert!(
            !braked_before && !braked_after,
            "the brake stays open during the moves"
        );
        assert!(
            after <= before + before / 10 + 100,
            "after the fault {after} inc, before {before} inc"
        );
    });
}
