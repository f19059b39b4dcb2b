//! The motor actions through a real master on the electrical plant (spec
//! §14; E-140, E-141; issue 35): A75 and A69 in axis A's process data, the
//! action started in Ready to switch on, the axis enabled for it, its result
//! in A69 and its objects, read back by SDO. The plant's motor is one the
//! drive does not know.

use drive_ecat::actions::state;
use drive_ecat::params::{B05, B40, B41, B42, B43, B52, B53, B62, E48};
use drive_tests::step::{a69_of, cycles, follow_a69, op_with_actions};
use drive_tests::{line, with_master, with_sdo};
use hil_sim::electrical::PlantModel;

/// A line of one drive whose axis A runs the electrical plant with a motor of
/// `r_ohm` and `l_h` (the drive's dictionary keeps its defaults: 3.6 Ω, 12 mH).
fn electrical_line(r_ohm: f64, l_h: f64) -> std::cell::RefCell<hil_sim::sim::Simulation> {
    let sim = line(1);
    {
        let mut s = sim.borrow_mut();
        let d = &mut s.drives_mut()[0];
        d.set_plant(PlantModel::Electrical, 0x35).unwrap();
        let plant = d.electrical_mut(0).unwrap().plant_mut();
        let mut m = plant.params().motor;
        (m.r_ohm, m.ld_h, m.lq_h) = (r_ohm, l_h, l_h);
        plant.set_motor(m);
    }
    sim
}

/// E-140, E-141 (B42 and B49): against plants with R and L the drive does
/// not know, "optimise current controller" started by A75 in Ready to switch
/// on waits (running, 0 %) for the enable, then identifies R and L within
/// 5 % of the plant's, writes them to B53 and B52/B62 and ends at 100 %;
/// Execute low and the enable removed, A69 is idle again.
#[test]
fn e140_b42_b49_optimise_current_controller_identifies_the_plants_r_and_l() {
    for (selector, r, l) in [(0b1100u8, 2.2, 0.0065), (0b1110, 6.0, 0.021)] {
        let sim = electrical_line(r, l);
        with_master(&sim, async |md, clock| {
            let (group, (a75, a69)) = op_with_actions(md, clock).await;
            let sd = group.subdevice(md, 0).unwrap();
            ready_to_switch_on(md, &group, &sim).await;
            sd.outputs_raw_mut()[a75] = selector << 1 | 1;
            cycles(md, &group, &sim, 5).await;
            let s = a69_of(sd.io_raw().inputs(), a69);
            assert_eq!(
                s,
                u16::from(selector) << 8 | state::RUNNING << 12,
                "waits for the enable: {s:04X}h"
            );
            // the enable: switch on, enable operation
            for cw in [7u16, 0xF] {
                sd.outputs_raw_mut()[0..2].copy_from_slice(&cw.to_le_bytes());
                cycles(md, &group, &sim, 5).await;
            }
            let seen = follow_a69(md, &group, &sim, a69, 3000, |s| s >> 12 == state::RUNNING).await;
            let done = 100 | u16::from(selector) << 8 | state::DONE << 12;
            assert_eq!(seen.last(), Some(&done), "A69 over the cycles: {seen:04X?}");
            assert!(
                seen.windows(2).all(|w| w[0] & 0xFF <= w[1] & 0xFF),
                "progress rises: {seen:04X?}"
            );
            assert_eq!(
                sd.sdo_read::<u8>(B42, 1).await.unwrap(),
                0,
                "B42[0] result: identified"
            );
            let r_id = f64::from(sd.sdo_read::<u32>(B53, 0).await.unwrap()) * 1e-3;
            let l_id = f64::from(sd.sdo_read::<u32>(B52, 0).await.unwrap()) * 1e-6;
            let lq = f64::from(sd.sdo_read::<u32>(B62, 0).await.unwrap()) * 1e-6;
            assert_eq!(
                sd.sdo_read::<u32>(B42, 2).await.unwrap(),
                (r_id * 1e3).round() as u32
            );
            let (er, el) = ((r_id - r) / r, (l_id - l) / l);
            println!("B42/B49 sel {selector:04b}: plant R {r} Ω L {l} H; identified {r_id:.3} Ω ({:+.2} %), {:.3} mH ({:+.2} %)", er * 100.0, l_id * 1e3, el * 100.0);
            assert!(er.abs() < 0.05, "R {r_id} Ω vs the plant's {r} Ω");
            assert!(el.abs() < 0.05, "L {l_id} H vs the plant's {l} H");
            assert_eq!(lq, l_id, "Lq = Ld");
            // the master ends it: Execute low, the enable removed
            sd.outputs_raw_mut()[a75] = 0;
            sd.outputs_raw_mut()[0..2].copy_from_slice(&6u16.to_le_bytes());
            cycles(md, &group, &sim, 10).await;
            assert_eq!(a69_of(sd.io_raw().inputs(), a69), 0);
            assert_eq!(sd.sdo_read::<u8>(E48, 0).await.unwrap(), 2);
        });
    }
}

/// Shutdown (6040h = 6) for 20 cycles: axis A in Ready to switch on (E48 = 2).
async fn ready_to_switch_on<S: ethercrab::subdevice_group::HasPdi>(
    md: &ethercrab::MainDevice<'_>,
    group: &ethercrab::SubDeviceGroup<8, 512, ethercrab::DefaultLock, S>,
    sim: &std::cell::RefCell<hil_sim::sim::Simulation>,
) {
    let sd = group.subdevice(md, 0).unwrap();
    sd.outputs_raw_mut()[0..2].copy_from_slice(&6u16.to_le_bytes());
    cycles(md, group, sim, 20).await;
    assert_eq!(sd.sdo_read::<u8>(E48, 0).await.unwrap(), 2, "ready to switch on");
}

/// Starts action `selector` in Ready to switch on, enables the axis and
/// runs until A69 leaves "running"; A69 over the run.
async fn run_action<S: ethercrab::subdevice_group::HasPdi>(
    sim: &std::cell::RefCell<hil_sim::sim::Simulation>,
    group: &ethercrab::SubDeviceGroup<8, 512, ethercrab::DefaultLock, S>,
    md: &ethercrab::MainDevice<'_>,
    (a75, a69): (usize, usize),
    selector: u8,
    max_cycles: usize,
) -> Vec<u16> {
    ready_to_switch_on(md, group, sim).await;
    let sd = group.subdevice(md, 0).unwrap();
    sd.outputs_raw_mut()[a75] = selector << 1 | 1;
    cycles(md, group, sim, 5).await;
    for cw in [7u16, 0xF] {
        sd.outputs_raw_mut()[0..2].copy_from_slice(&cw.to_le_bytes());
        cycles(md, group, sim, 5).await;
    }
    follow_a69(md, group, sim, a69, max_cycles, |s| s >> 12 == state::RUNNING).await
}

/// E-140 (B41): "calibrate motor" on a plant whose commutation offset the
/// drive does not know (B05 = 0, the plant's d axis at 0.3 rad mechanical =
/// 50,066 increments): after the alignment B05 holds the plant's offset
/// within 0.5° electrical (modulo an electrical revolution, 2^20/4 inc);
/// saved (1010h:01) it is there again after a power cycle.
#[test]
fn e140_b41_calibrate_motor_finds_the_plants_commutation_offset() {
    let offset_rad = 0.3;
    let sim = electrical_line(3.6, 0.012);
    {
        let mut s = sim.borrow_mut();
        let plant = s.drives_mut()[0].electrical_mut(0).unwrap().plant_mut();
        let mut m = plant.params().motor;
        m.commutation_offset_rad = offset_rad;
        plant.set_motor(m);
    }
    let per_el = (1u32 << 20) / 4;
    let truth = (offset_rad / std::f64::consts::TAU * f64::from(1u32 << 20)).round() as i64;
    let b05 = with_master(&sim, async |md, clock| {
        let (group, (a75, a69)) = op_with_actions(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(sd.sdo_read::<u32>(B05, 0).await.unwrap(), 0);
        let seen = run_action(&sim, &group, md, (a75, a69), 0b1011, 20_000).await;
        let done = 100 | 0b1011 << 8 | state::DONE << 12;
        assert_eq!(seen.last(), Some(&done), "A69 over the cycles: {seen:04X?}");
        assert_eq!(sd.sdo_read::<u8>(B41, 1).await.unwrap(), 0, "B41[0] result");
        let b05 = i64::from(sd.sdo_read::<u32>(B05, 0).await.unwrap());
        let spread = sd.sdo_read::<u32>(B41, 2).await.unwrap();
        let err = (b05 - truth).rem_euclid(i64::from(per_el));
        let err = err.min(i64::from(per_el) - err);
        let err_deg = err as f64 / f64::from(per_el) * 360.0;
        println!("B41: plant offset {truth} inc, B05 {b05} inc: {err_deg:.3}° electrical off, alignments {spread} inc apart");
        assert!(
            err_deg < 0.5,
            "B05 {b05} vs the plant's {truth} (mod {per_el}): {err_deg}° el"
        );
        sd.outputs_raw_mut()[a75] = 0;
        sd.outputs_raw_mut()[0..2].copy_from_slice(&6u16.to_le_bytes());
        cycles(md, &group, &sim, 10).await;
        sd.sdo_write(0x1010, 1, u32::from_le_bytes(*b"save"))
            .await
            .expect("save");
        cycles(md, &group, &sim, 200).await;
        b05
    });
    sim.borrow_mut().drives_mut()[0].power_cycle();
    let again = with_sdo(&sim, async |sd, _| sd.sdo_read::<u32>(B05, 0).await.unwrap());
    assert_eq!(i64::from(again), b05, "B05 saved with the parameter set");
}

/// E-141, E-140: B42 started outside Ready to switch on (switch-on disabled)
/// is refused and changes nothing (B53, B52 stay); started, then the enable
/// never given but the axis shut off (disable voltage): failed, result 1
/// (aborted), the motor data as they were.
#[test]
fn e141_b42_refused_in_the_wrong_state_and_aborted_without_its_enable() {
    let sim = electrical_line(2.2, 0.0065);
    with_master(&sim, async |md, clock| {
        let (group, (a75, a69)) = op_with_actions(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        let before = (
            sd.sdo_read::<u32>(B53, 0).await.unwrap(),
            sd.sdo_read::<u32>(B52, 0).await.unwrap(),
        );
        assert_ne!(sd.sdo_read::<u8>(E48, 0).await.unwrap(), 2);
        sd.outputs_raw_mut()[a75] = 0b1100 << 1 | 1;
        cycles(md, &group, &sim, 5).await;
        let s = a69_of(sd.io_raw().inputs(), a69);
        assert_eq!(s, 0b1100 << 8 | state::REFUSED << 12, "{s:04X}h");
        sd.outputs_raw_mut()[a75] = 0;
        sd.outputs_raw_mut()[0..2].copy_from_slice(&6u16.to_le_bytes());
        cycles(md, &group, &sim, 20).await;
        sd.outputs_raw_mut()[a75] = 0b1100 << 1 | 1;
        cycles(md, &group, &sim, 5).await;
        // disable voltage instead of the enable: back to switch-on disabled
        sd.outputs_raw_mut()[0..2].copy_from_slice(&0u16.to_le_bytes());
        cycles(md, &group, &sim, 10).await;
        let s = a69_of(sd.io_raw().inputs(), a69);
        assert_eq!(s, 0b1100 << 8 | state::FAILED << 12, "{s:04X}h");
        assert_eq!(sd.sdo_read::<u8>(B42, 1).await.unwrap(), 1, "B42[0]: aborted");
        let after = (
            sd.sdo_read::<u32>(B53, 0).await.unwrap(),
            sd.sdo_read::<u32>(B52, 0).await.unwrap(),
        );
        assert_eq!(after, before, "nothing changed");
    });
}

/// E-140, E-141 (B43): "test winding" started in Ready to switch on runs
/// without an enable (the axis stays in E48 = 2); a balanced winding passes
/// (the three resistances within 3 % of the plant's R, result 0, done); one
/// phase's resistance 10 % high (the plant's unbalanced winding) fails with
/// result 6 and A69 "failed", its resistances those of the closed form
/// (R_x + R_y‖R_z)/1.5 within 1 %; an open phase fails
/// with result 2 (no current).
#[test]
fn e140_b43_test_winding_passes_a_balanced_and_fails_an_unbalanced_or_open_winding() {
    use plant::{FaultOptions, Phase};
    let r = 3.6;
    let cases: [(Option<FaultOptions>, u8, u16); 3] = [
        (None, 0, state::DONE),
        (
            Some(FaultOptions {
                r_scale: [1.0, 1.1, 1.0],
                ..FaultOptions::NONE
            }),
            6,
            state::FAILED,
        ),
        (
            Some(FaultOptions {
                open_phase: Some(Phase::C),
                ..FaultOptions::NONE
            }),
            2,
            state::FAILED,
        ),
    ];
    for (fault, code, end) in cases {
        let sim = electrical_line(r, 0.012);
        if let Some(f) = fault {
            let mut s = sim.borrow_mut();
            s.drives_mut()[0]
                .electrical_mut(0)
                .unwrap()
                .plant_mut()
                .set_faults(f);
        }
        with_master(&sim, async |md, clock| {
            let (group, (a75, a69)) = op_with_actions(md, clock).await;
            let sd = group.subdevice(md, 0).unwrap();
            ready_to_switch_on(md, &group, &sim).await;
            sd.outputs_raw_mut()[a75] = 0b1101 << 1 | 1;
            let seen = follow_a69(md, &group, &sim, a69, 5000, |s| {
                s >> 12 == state::RUNNING || s >> 12 == state::IDLE
            })
            .await;
            assert_eq!(
                sd.sdo_read::<u8>(E48, 0).await.unwrap(),
                2,
                "no enable: still ready to switch on"
            );
            let last = *seen.last().unwrap();
            assert_eq!(last >> 12, end, "{fault:?}: A69 {seen:04X?}");
            assert_eq!(
                sd.sdo_read::<u8>(B43, 1).await.unwrap(),
                code,
                "{fault:?}: B43[0]"
            );
            if code != 2 {
                let mut rs = [0.0; 3];
                for (k, x) in rs.iter_mut().enumerate() {
                    *x = f64::from(sd.sdo_read::<u32>(B43, k as u8 + 2).await.unwrap()) * 1e-3;
                }
                println!("B43 {fault:?}: U {:.3} V {:.3} W {:.3} Ω", rs[0], rs[1], rs[2]);
                if code == 0 {
                    assert!(rs.iter().all(|x| (x - r).abs() < 0.03 * r), "{rs:?} vs {r} Ω");
                } else {
                    // 10 % on V: (1.1 R + R/2)/1.5 = 1.067 R along V,
                    // (R + 1.1 R‖R)/1.5 = 1.016 R along U and W
                    assert!((rs[1] - 1.0667 * r).abs() < 0.01 * r, "{rs:?}");
                    for x in [rs[0], rs[2]] {
                        assert!((x - 1.0159 * r).abs() < 0.01 * r, "{rs:?}");
                    }
                }
            }
        });
    }
}

/// E-140, E-141 (B40): "test phase" started in Ready to switch on runs after
/// the enable: on the plant as wired it passes (the encoder counts
/// 2^20/4 = 262,144 increments, within 1 %, for one electrical turn of the
/// field: 4 pole pairs, B10); phases V and W swapped make the rotor turn
/// backwards (result 7), an encoder counting the other way (the plant's
/// `encoder_reversed`: the rotor turns forward, the count goes down) fails
/// the same (7, the count about −2^20/4), an open phase carries no current
/// (result 2), a motor of 5 pole pairs where B10 says 4 counts 2^20/5
/// (result 8). A69 says done or failed.
#[test]
fn e140_b40_test_phase_passes_the_wiring_and_fails_swapped_or_open_phases_and_wrong_pole_pairs() {
    use plant::{FaultOptions, Phase};
    let none = FaultOptions::NONE;
    let cases: [(&str, FaultOptions, u32, u8); 5] = [
        ("as wired", none, 4, 0),
        (
            "encoder reversed",
            FaultOptions {
                encoder_reversed: true,
                ..none
            },
            4,
            7,
        ),
        (
            "V and W swapped",
            FaultOptions {
                swapped_bc: true,
                ..none
            },
            4,
            7,
        ),
        (
            "W open",
            FaultOptions {
                open_phase: Some(Phase::C),
                ..none
            },
            4,
            2,
        ),
        ("5 pole pairs", none, 5, 8),
    ];
    for (what, fault, pole_pairs, code) in cases {
        let sim = electrical_line(3.6, 0.012);
        {
            let mut s = sim.borrow_mut();
            let plant = s.drives_mut()[0].electrical_mut(0).unwrap().plant_mut();
            plant.set_faults(fault);
            let mut m = plant.params().motor;
            m.pole_pairs = pole_pairs;
            plant.set_motor(m);
        }
        with_master(&sim, async |md, clock| {
            let (group, (a75, a69)) = op_with_actions(md, clock).await;
            let sd = group.subdevice(md, 0).unwrap();
            // cst (10): the rotor turns, no position is held
            sd.outputs_raw_mut()[2] = 10;
            let seen = run_action(&sim, &group, md, (a75, a69), 0b1010, 10_000).await;
            let last = *seen.last().unwrap();
            let want = if code == 0 { state::DONE } else { state::FAILED };
            let b40 = sd.sdo_read::<u8>(B40, 1).await.unwrap();
            assert_eq!(
                last >> 12,
                want,
                "{what}: A69 {seen:04X?}, B40[0] {b40} {}",
                sd.sdo_read::<i32>(B40, 2).await.unwrap()
            );
            assert_eq!(sd.sdo_read::<u8>(B40, 1).await.unwrap(), code, "{what}: B40[0]");
            let per_turn = sd.sdo_read::<i32>(B40, 2).await.unwrap();
            println!("B40 {what}: result {code}, {per_turn} inc per electrical turn");
            match code {
                0 | 8 => {
                    let expected = f64::from(1u32 << 20) / f64::from(pole_pairs);
                    assert!(
                        (f64::from(per_turn) - expected).abs() < 0.01 * expected,
                        "{what}: {per_turn} vs {expected}"
                    );
                }
                7 => {
                    assert!(per_turn < 0, "{what}: {per_turn}");
                    if fault.encoder_reversed {
                        // the rotor did its electrical turn, counted backwards
                        let expected = -f64::from(1u32 << 20) / 4.0;
                        assert!(
                            (f64::from(per_turn) - expected).abs() < 0.01 * -expected,
                            "{what}: {per_turn} vs {expected}"
                        );
                    }
                }
                _ => {}
            }
        });
    }
}

/// E-140, E-141 (B300): "test brake" started in Ready to switch on runs after
/// the enable: the brake applied, the rated torque 6076h (1.3 N·m) forward
/// then backward. The plant's brake holds 2 N·m: the shaft stays within
/// 1/360 rev (result 0, done, B300[1] the play seen, B300[2] 1300 mN·m); a
/// worn brake holding 1.0 N·m slips under the test torque: result 9, failed,
/// the movement beyond 1/360 rev, and the axis back under its own control
/// (Operation enabled, the brake released). A stuck brake (the plant's
/// `brake_stuck`) holds as a good one does: B300 keeps the brake applied
/// throughout, so it passes (result 0); B301's released phases find it.
#[test]
fn e140_b300_test_brake_holds_the_rated_torque_or_fails_on_a_worn_brake() {
    use drive_ecat::params::B300;
    const TOLERANCE_INC: u32 = (1 << 20) / 360;
    for (holding_nm, stuck, code, end) in [
        (2.0, false, 0u8, state::DONE),
        (1.0, false, 9, state::FAILED),
        (2.0, true, 0, state::DONE),
    ] {
        let sim = electrical_line(3.6, 0.012);
        {
            let mut s = sim.borrow_mut();
            let p = s.drives_mut()[0].motors[0].params_mut();
            p.brake_holding_torque_nm = holding_nm;
            p.brake_stuck = stuck;
        }
        with_master(&sim, async |md, clock| {
            let (group, io) = op_with_actions(md, clock).await;
            let sd = group.subdevice(md, 0).unwrap();
            let seen = run_action(&sim, &group, md, io, 0b0100, 3000).await;
            let last = *seen.last().unwrap();
            assert_eq!(last >> 12, end, "brake {holding_nm} N·m: A69 {seen:04X?}");
            assert_eq!(last >> 8 & 0xF, 0b0100, "the selector shown");
            assert_eq!(sd.sdo_read::<u8>(B300, 1).await.unwrap(), code, "B300[0]");
            let moved = sd.sdo_read::<u32>(B300, 2).await.unwrap();
            assert_eq!(
                sd.sdo_read::<u32>(B300, 3).await.unwrap(),
                1300,
                "the test torque, mN·m"
            );
            println!("B300 brake holding {holding_nm} N·m (stuck: {stuck}): result {code}, largest movement {moved} inc");
            if code == 0 {
                assert!(moved <= TOLERANCE_INC, "held: {moved} inc");
            } else {
                assert!(moved > TOLERANCE_INC, "slipped: {moved} inc");
            }
            // the axis' own control again: enabled
            assert_eq!(sd.sdo_read::<u8>(E48, 0).await.unwrap(), 4, "Operation enabled");
        });
    }
}

/// E-140, E-141 (B301): "grind brake" started in Ready to switch on runs
/// after the enable: 4 rounds of 0.5 s grinding (the brake applied, 60 rpm
/// against it) and 0.25 s released, then 0.1 s stopped on the brake. The
/// plant's brake slides at 2 N·m (a figure the drive does not know): done,
/// every grind phase turning the shaft at least 0.8 of 60 rpm × 0.5 s
/// (2^19 inc), every released one 0.8 of its 2^18, the grinding torque
/// B301[3] the brake's 2 N·m plus the friction (within 2.0…2.3 N·m), and the
/// rotor's own travel (the mechanics, not the encoder) at least
/// 0.8 × 3 revolutions. A brake holding 5 N·m, beyond the 3.9 N·m peak
/// torque, stalls the first grind phase: result 10, the shaft not turned,
/// the grinding torque the peak. A stuck brake (the plant's `brake_stuck`:
/// closed whatever is commanded) is ground but fails the first released
/// phase: result 11, its travel below a tenth of what the healthy brake's
/// was. A69 says done or failed; the axis is back under its own control.
#[test]
fn e140_b301_grind_brake_grinds_a_healthy_brake_and_fails_a_stalled_or_stuck_one() {
    use drive_ecat::params::B301;
    let full_grind = f64::from(1u32 << 19);
    let full_released = f64::from(1u32 << 18);
    let cases: [(&str, f64, bool, u8); 3] = [
        ("healthy", 2.0, false, 0),
        ("holding 5 N·m", 5.0, false, 10),
        ("stuck", 2.0, true, 11),
    ];
    for (what, holding_nm, stuck, code) in cases {
        let sim = electrical_line(3.6, 0.012);
        {
            let mut s = sim.borrow_mut();
            let p = s.drives_mut()[0].motors[0].params_mut();
            p.brake_holding_torque_nm = holding_nm;
            p.brake_stuck = stuck;
        }
        let rotor_before = sim.borrow().drives()[0].motors[0].position_inc_i64();
        with_master(&sim, async |md, clock| {
            let (group, io) = op_with_actions(md, clock).await;
            let sd = group.subdevice(md, 0).unwrap();
            // cst (10): the rotor turns, no position is held
            sd.outputs_raw_mut()[2] = 10;
            let seen = run_action(&sim, &group, md, io, 0b0101, 5000).await;
            let last = *seen.last().unwrap();
            let want = if code == 0 { state::DONE } else { state::FAILED };
            let b301: Vec<u32> = {
                let mut v = Vec::new();
                for k in 2..=4 {
                    v.push(sd.sdo_read::<u32>(B301, k).await.unwrap());
                }
                v
            };
            let (grind, released, torque_mnm) = (b301[0], b301[1], b301[2]);
            let rotor = sim.borrow().drives()[0].motors[0].position_inc_i64() - rotor_before;
            println!(
                "B301 {what}: result {code}, smallest grind travel {grind} inc, released {released} inc, grinding torque {torque_mnm} mN·m, rotor travel {rotor} inc"
            );
            assert_eq!(last >> 12, want, "{what}: A69 {seen:04X?}");
            assert_eq!(last >> 8 & 0xF, 0b0101, "the selector shown");
            assert_eq!(sd.sdo_read::<u8>(B301, 1).await.unwrap(), code, "{what}: B301[0]");
            match code {
                0 => {
                    assert!(f64::from(grind) >= 0.8 * full_grind, "{what}: {grind}");
                    assert!(f64::from(released) >= 0.8 * full_released, "{what}: {released}");
                    assert!((2000..=2300).contains(&torque_mnm), "{what}: {torque_mnm} mN·m");
                    assert!(
                        rotor as f64 >= 0.8 * 3.0 * f64::from(1u32 << 20),
                        "{what}: the rotor turned {rotor} inc"
                    );
                }
                10 => {
                    assert!(f64::from(grind) < 0.25 * full_grind, "{what}: {grind}");
                    assert!(rotor.abs() < 1 << 12, "{what}: the rotor turned {rotor} inc");
                    assert!((3800..=3900).contains(&torque_mnm), "{what}: {torque_mnm} mN·m");
                }
                _ => {
                    assert!(f64::from(grind) >= 0.8 * full_grind, "{what}: ground: {grind}");
                    assert!(
                        f64::from(released) < 0.1 * full_released,
                        "{what}: not released: {released}"
                    );
                }
            }
            // the axis' own control again: enabled
            assert_eq!(sd.sdo_read::<u8>(E48, 0).await.unwrap(), 4, "Operation enabled");
        });
    }
}

/// E-140, E-141 (B301, the hand-back): in profile position mode (6060h = 1,
/// the drive's own set-point) with no move commanded, "grind brake" turns
/// the shaft by some three revolutions; afterwards, the enable and Execute
/// still on, the axis' own control holds the shaft where the action left
/// it: no drive back to where it stood before (the set-point followed the
/// shaft while the action ran, `Axis::overridden`), no fault, for 0.5 s;
/// while the action ran, 60F4h read 0 (not the shaft's travel per cycle).
#[test]
fn e140_b301_hands_the_axis_back_where_it_left_the_shaft() {
    let sim = electrical_line(3.6, 0.012);
    with_master(&sim, async |md, clock| {
        let (group, io) = op_with_actions(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        sd.outputs_raw_mut()[2] = 1;
        let rotor = || sim.borrow().drives()[0].motors[0].position_inc_i64();
        let before = rotor();
        // a second into it (a released phase at 60 rpm, 1,049 inc a cycle):
        // the axis' following error reads 0, its set-point is the shaft's
        let seen = run_action(&sim, &group, md, io, 0b0101, 1000).await;
        assert_eq!(*seen.last().unwrap() >> 12, state::RUNNING, "A69 {seen:04X?}");
        let fe = sd.sdo_read::<i32>(0x60F4, 0).await.unwrap();
        println!("B301 running: 60F4h {fe} inc");
        assert!(fe.abs() <= 16, "60F4h while B301 moves the shaft: {fe} inc");
        let seen = follow_a69(md, &group, &sim, io.1, 5000, |s| s >> 12 == state::RUNNING).await;
        assert_eq!(*seen.last().unwrap() >> 12, state::DONE, "A69 {seen:04X?}");
        let left = rotor();
        assert!(
            left - before >= 2 << 20,
            "B301 turned the shaft {} inc",
            left - before
        );
        cycles(md, &group, &sim, 500).await;
        let moved = rotor() - left;
        println!("B301 handed back in pp: the rotor moved {moved} inc in 500 cycles");
        assert!(
            moved.abs() <= 1 << 11,
            "the axis holds where B301 left it: moved {moved} inc"
        );
        assert_eq!(
            sd.sdo_read::<u8>(E48, 0).await.unwrap(),
            4,
            "Operation enabled, no fault"
        );
    });
}
