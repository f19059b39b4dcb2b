//! One motion, two fieldbuses (issue 17): the same positioning move,
//! commanded once over EtherCAT (ethercrab, profile position mode pp) and
//! once over PROFINET (the Example Function block's record 266 through
//! telegram 0), runs the same trajectory on the same simulated motor: the
//! two personalities feed one core.
//!
//! The move: from the reference (0) to 3 rev at 10 rev/s with 100 rev/s²,
//! no jerk limit. The values are exact in both unit systems (600 rpm =
//! 10 · 2^20 inc/s, 6000 rpm/s = 100 · 2^20 inc/s², 3000/1000 rev = 3 · 2^20
//! inc), so both sides hand the profile generator the same numbers.

use drive_tests::axis::*;
use drive_tests::{line, with_cyclic, REV};
use hil_sim::fb::controller::PnController;
use hil_sim::fb::rig::FbRig;

/// Cycles recorded after the start command (1 ms each).
const CYCLES: usize = 700;
/// Target, 1/1000 rev and increments.
const TARGET_MILLI: i32 = 3000;
const TARGET_INC: i32 = 3 * REV;
/// Profile velocity: rpm and increments/s.
const RPM: i32 = 600;
const INC_PER_S: u32 = 10 * REV as u32;
/// Accelerations: rpm/s and increments/s².
const RPM_PER_S: u32 = 6000;
const INC_PER_S2: u32 = 100 * REV as u32;

/// The motor's positions from the first cycle it moves, relative to where
/// it stood (the plant's encoder, increments).
fn from_first_motion(trace: &[i64]) -> Vec<i64> {
    let rest = trace.first().copied().unwrap_or(0);
    let start = trace.iter().position(|&p| p != rest).unwrap_or(trace.len());
    trace[start.saturating_sub(1)..]
        .iter()
        .map(|p| p - rest)
        .collect()
}

/// The move over EtherCAT: pp with 6081h/6083h/6084h and no jerk (60A4h =
/// 0), homed by method 37 at the motor's position first.
fn over_ethercat() -> Vec<i64> {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        set_profile(sd, Some(INC_PER_S), INC_PER_S2).await;
        sd.sdo_write(0x60A4, 1, 0u32).await.unwrap();
        m.enable_in(1).await;
        home_here(m).await;
        m.set_mode(1);
        m.run(50).await;
        m.set_target_position(TARGET_INC);
        m.set_controlword(CW_ENABLED);
        m.run(1).await;
        m.set_controlword(CW_ENABLED | CW_BIT4);
        let mut trace = vec![motor_position(&sim, 0)];
        for _ in 0..CYCLES {
            m.cycle().await;
            trace.push(motor_position(&sim, 0));
        }
        assert!(m.tx.bit(10), "pp: target reached: {:#06x}", m.tx.statusword);
        trace
    })
}

/// The move over PROFINET: record 266 from telegram 0 (target, profile
/// velocity, end velocity 0, all accelerations), started by CW1 bit 6,
/// homed by PROFIdrive method 34 (the core's 37) first.
fn over_profinet() -> Vec<i64> {
    let mut p = FbRig::connect(PnController::drive()).expect("connect");
    assert!(p.enable().unwrap(), "enabled");
    p.i.homing_method = 34;
    p.i.start_homing = true;
    assert!(p.until(500, |o| o.home_valid).unwrap(), "homed");
    p.i.start_homing = false;
    p.i.target_position = TARGET_MILLI;
    p.i.profile_velocity = RPM;
    p.i.end_velocity = 0;
    p.i.all_accelerations_positioning = RPM_PER_S;
    for _ in 0..50 {
        p.cycle().unwrap();
    }
    p.i.start_pos = true;
    let mut trace = vec![p.encoder()];
    for _ in 0..CYCLES {
        p.cycle().unwrap();
        trace.push(p.encoder());
    }
    assert!(p.o.target_reached, "record: target reached: {:#06x}", p.o.zsw1);
    trace
}

/// Walks two samplings of one trajectory side by side: equal values pair
/// up; a value one side has and the other skipped (the master's cycle and
/// the drive's control cycle slip against each other now and then, so a
/// cycle is sampled twice or not at all) is counted. `None`: a pair that
/// differs in value, i.e. two trajectories.
fn merge(a: &[i64], b: &[i64]) -> Option<(usize, usize)> {
    let (mut i, mut j, mut skipped, mut compared) = (0, 0, 0, 0);
    while i < a.len() && j < b.len() {
        if a[i] == b[j] {
            i += 1;
            j += 1;
            compared += 1;
        } else if b.get(j + 1) == Some(&a[i]) {
            j += 1;
            skipped += 1;
        } else if a.get(i + 1) == Some(&b[j]) {
            i += 1;
            skipped += 1;
        } else {
            println!("differ at {i} / {j}: {} vs {}", a[i], b[j]);
            return None;
        }
    }
    Some((compared, skipped))
}

#[test]
fn p134_c041_the_same_move_over_ethercat_and_profinet_runs_the_same_trajectory() {
    let ecat = from_first_motion(&over_ethercat());
    let pn = from_first_motion(&over_profinet());
    let end = (ecat.last().copied(), pn.last().copied());
    let merged = merge(&ecat, &pn);
    println!(
        "one move, two fieldbuses: {} and {} samples, end {:?} / {:?} inc (target {TARGET_INC}); paired sample by sample: {merged:?} (equal, sampled by one side only)",
        ecat.len(),
        pn.len(),
        end.0,
        end.1
    );
    let (compared, skipped) = merged.expect("the same trajectory to the increment");
    assert!(compared > 600, "compared {compared}");
    assert!(
        skipped * 50 < compared,
        "at most one sample in 50 unpaired: {skipped}"
    );
    assert_eq!(end.0, end.1, "the same end position");
}
