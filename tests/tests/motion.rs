//! Motion through a real master (spec cia402.md, features-cia402.md C-items):
//! ethercrab runs the standard process data (RxPDO 23 bytes, TxPDO 29 bytes)
//! every simulated millisecond against the simulated drive and motor; every
//! check reads what the master received in the TxPDO (or by SDO), not the
//! drive's internals.

use drive_tests::axis::*;
use drive_tests::{init, line, motor_rev_s, sw, with_cyclic, with_master, CoeClient, Cyclic, RawMailbox};
use drive_tests::{REV, REV_F};
use hil_sim::motor::PositionInput;
use hil_sim::sim::AxisConditions;

/// Axis B's CiA 402 objects (C-134).
const B: u16 = 0x800;

/// Minimum-jerk profile 0 → `d` over `t_s`: d·(10s³ − 15s⁴ + 6s⁵).
fn min_jerk(d: f64, t_s: f64, t: f64) -> f64 {
    let s = (t / t_s).clamp(0.0, 1.0);
    d * s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)
}

// ---------------------------------------------------------------------------
// Device control (C-002 … C-018)
// ---------------------------------------------------------------------------

#[test]
fn c002_c004_c005_c018_enable_sequence_through_pdo() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await.into_op(md).await.expect("OP");
        let mut m = Cyclic::new(md, &group, &sim, 0);
        m.set_mode(8);
        // controlword 0: Switch on disabled, nothing else
        let tx = m.run(5).await;
        assert_eq!(tx.state(), sw::SOD, "statusword {:#06x}", tx.statusword);
        assert_eq!(tx.mode_display, 8, "6061h shows csp");

        // each command gives exactly the next state, and the state holds
        for (cw, state) in [(0x0006, sw::RTSO), (0x0007, sw::SO), (0x000F, sw::OE)] {
            m.command(cw, state, 10).await;
            // and holds
            let tx = m.run(5).await;
            assert_eq!(
                tx.state(),
                state,
                "controlword {cw:#06x}: statusword {:#06x}",
                tx.statusword
            );
            // bit 9 remote (the master is in control), bit 4 voltage enabled from RTSO on
            assert!(tx.bit(9), "remote bit 9: {:#06x}", tx.statusword);
            assert!(tx.bit(4), "voltage enabled bit 4: {:#06x}", tx.statusword);
        }
        // E48 agrees (C-019)
        let sd = group.subdevice(md, 0).unwrap();
        let e48_index = drive_ecat::parameter_index(4, 48);
        let e48: u8 = sd.sdo_read(e48_index, 0).await.expect("E48");
        assert_eq!(e48, 4, "E48 = operation enabled");

        // Disable operation (7) → Switched on (T5), shutdown (6) → RTSO (T6),
        // disable voltage (0) → SOD (T7)
        for (cw, state) in [(0x0007, sw::SO), (0x0006, sw::RTSO), (0x0000, sw::SOD)] {
            let tx = m.command(cw, state, 50).await;
            assert_eq!(tx.state(), state);
        }
        // a skipped step: 15 straight from SOD does nothing (no T2 without 6)
        m.set_controlword(0x000F);
        let tx = m.run(10).await;
        assert_eq!(tx.state(), sw::SOD, "15 in SOD: {:#06x}", tx.statusword);
    });
}

#[test]
fn c003_c015_enable_refused_without_a60_supply_or_sto() {
    type Cut = fn(&mut AxisConditions);
    let cuts: [(&str, Cut); 3] = [
        ("A60 off", |c| c.additional_enable = false),
        ("no supply", |c| c.supply_ok = false),
        ("STO active", |c| c.sto_active = true),
    ];
    let sim = line(1);
    with_cyclic(&sim, async |m, _| {
        m.set_mode(8);
        m.run(3).await;
        for (what, cut) in cuts {
            with_drive(&sim, |d| cut(&mut d.conditions[0]));
            // T2, then T3/T4 as a master would try them: all refused
            for cw in [0x0006, 0x0007, 0x000F] {
                m.set_controlword(cw);
                let tx = m.run(10).await;
                assert_eq!(
                    tx.state(),
                    sw::SOD,
                    "{what}: controlword {cw:#06x} gives {:#06x}",
                    tx.statusword
                );
            }
            // restored: the same sequence enables
            with_drive(&sim, |d| d.conditions[0] = AxisConditions::READY);
            m.set_controlword(0);
            m.run(2).await;
            m.enable().await;
            // lost while enabled: forced out of Operation enabled (C-013/C-015);
            // the supply with the power stage on is event 46 (decisions)
            with_drive(&sim, |d| cut(&mut d.conditions[0]));
            let to = if what == "no supply" { sw::FAULT } else { sw::SOD };
            let left = m.run_until(50, |t| t.state() == to).await;
            assert!(left.is_some(), "{what} in OE: {:#06x}", m.tx.statusword);
            with_drive(&sim, |d| d.conditions[0] = AxisConditions::READY);
            m.set_controlword(0);
            m.run(2).await;
            m.set_controlword(0x0080);
            m.run(2).await;
            m.set_controlword(0);
            m.run(2).await;
        }
    });
}

// ---------------------------------------------------------------------------
// Cyclic modes (C-035 … C-039)
// ---------------------------------------------------------------------------

#[test]
fn c035_csp_follows_a_profile_from_the_master() {
    let sim = line(1);
    with_cyclic(&sim, async |m, _| {
        m.set_mode(8);
        let tx = m.run(3).await;
        // CiA practice: the set-point starts at the actual position
        let start = tx.position;
        m.set_target_position(start);
        let tx = m.enable().await;
        assert!(
            tx.bit(12),
            "csp bit 12 'drive follows' in OE: {:#06x}",
            tx.statusword
        );

        let distance = 5.0 * REV_F;
        let t_move = 1.5;
        let n = (t_move * 1000.0) as usize;
        let mut max_fe = 0i32;
        let mut max_lag = 0i64;
        let mut max_velocity = 0i32;
        for k in 1..=n + 300 {
            let target = start + min_jerk(distance, t_move, k as f64 * 1e-3).round() as i32;
            m.set_target_position(target);
            let tx = m.cycle().await;
            assert_eq!(tx.state(), sw::OE, "cycle {k}: {:#06x}", tx.statusword);
            assert!(tx.bit(12), "cycle {k}: bit 12 while following");
            assert!(!tx.bit(13), "cycle {k}: no following error bit");
            max_fe = max_fe.max(tx.following_error.abs());
            max_lag = max_lag.max((i64::from(target) - i64::from(tx.position)).abs());
            max_velocity = max_velocity.max(tx.velocity);
            if k > n - 20 && k % 10 == 0 {
                println!(
                    "k {k} target {target} pos {} fe {} v {} trq {}",
                    tx.position, tx.following_error, tx.velocity, tx.torque
                );
            }
        }
        let end = start + distance as i32;
        let tx = m.tx;
        println!(
            "csp 5 rev in {t_move} s: max |60F4h| {max_fe} inc ({:.2}°), max |607Ah − 6064h| (incl. 2 cycles \
             of bus delay) {max_lag} inc, peak 606Ch {:.2} rev/s, final error {} inc",
            f64::from(max_fe) * 360.0 / REV_F,
            f64::from(max_velocity) / REV_F,
            end - tx.position
        );
        // within the position window I22 (1/360 rev): the default gains at 1 ms
        // against the motor's breakaway friction leave a slow stick-slip
        // hunting of a few hundred increments around the target
        assert!(
            (end - tx.position).abs() <= REV / 360,
            "final position {} vs {end}",
            tx.position
        );
        assert!(tx.velocity.abs() < REV / 100, "at rest: {}", tx.velocity);
        // peak velocity of the minimum-jerk profile: 1.875 · d / T = 6.25 rev/s
        let peak = f64::from(max_velocity) / REV_F;
        assert!((peak - 6.25).abs() < 0.3, "peak velocity {peak} rev/s");
        assert!(max_fe < REV / 100, "following error bounded: {max_fe} inc");
        assert_eq!(i64::from(tx.position), motor_position(&sim, 0), "6064h = encoder");
    });
}

#[test]
fn c037_csv_reaches_target_velocity() {
    let sim = line(1);
    with_cyclic(&sim, async |m, _| {
        let tx = m.enable_in(9).await;
        assert_eq!(tx.mode_display, 9);
        assert!(tx.bit(12), "csv bit 12 'drive follows': {:#06x}", tx.statusword);
        let v = 5 * REV; // 5 rev/s, no ramp from the drive (C-037)
        m.set_target_velocity(v);
        let settle = m
            .run_until(500, |t| (t.velocity - v).abs() < v / 100)
            .await
            .expect("csv reaches 60FFh within 1 %");
        m.run(200).await;
        let tx = m.tx;
        println!(
            "csv 0 → 5 rev/s: within 1 % after {settle} ms; 606Ch {:.4} rev/s, torque {} ‰",
            f64::from(tx.velocity) / REV_F,
            tx.torque
        );
        assert!((tx.velocity - v).abs() < v / 200, "606Ch {} vs {v}", tx.velocity);
        assert!(
            (motor_rev_s(&sim, 0) - 5.0).abs() < 0.05,
            "the motor turns at 5 rev/s"
        );
        assert!(tx.bit(12));
        // friction torque only at constant speed (viscous + Coulomb ≈ 0.024 N·m ≈ 18 ‰)
        assert!((5..60).contains(&tx.torque), "torque {} ‰", tx.torque);
        // reversing: follows without a ramp limit from the drive
        m.set_target_velocity(-v);
        m.run_until(500, |t| (t.velocity + v).abs() < v / 100)
            .await
            .expect("csv reaches −5 rev/s");
        m.set_target_velocity(0);
        m.run_until(500, |t| t.velocity.abs() < REV / 100)
            .await
            .expect("csv stops");
        assert_eq!(m.tx.state(), sw::OE);
    });
}

#[test]
fn c038_c039_cst_torque_with_and_without_speed_limit() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        let tx = m.enable_in(10).await;
        assert_eq!(tx.mode_display, 10);
        assert!(tx.bit(12), "cst bit 12 'drive follows': {:#06x}", tx.statusword);

        // default G472/G475 = 0 %: a torque set-point does not move the axis (C-039)
        m.set_target_torque(200); // 20 % of 1.3 N·m
        let tx = m.run(300).await;
        println!(
            "cst, G472/G475 = 0: 606Ch {} inc/s, moved {} inc, 6077h {} ‰",
            tx.velocity, tx.position, tx.torque
        );
        assert!(tx.velocity.abs() < REV / 20, "stands: {} inc/s", tx.velocity);
        assert!(tx.position.abs() < REV / 10, "stays: {} inc", tx.position);
        assert!(
            tx.bit(11),
            "internal limit bit 11 (speed limiter): {:#06x}",
            tx.statusword
        );

        // G472/G475 = 10 rev/s: the torque accelerates the axis up to the limit
        torque_mode_speed_limit(sd, 10.0).await;
        m.set_target_torque(100); // 0.13 N·m on 1e-4 kg·m² ≈ 207 rev/s²
        let tx = m.run(5).await;
        assert_eq!(tx.torque, 100, "6077h follows 6071h at once (C-038)");
        let start = m.tx.velocity;
        let tx = m.run(20).await;
        let accel = f64::from(tx.velocity - start) / REV_F / 0.020;
        println!("cst 10 %: acceleration {accel:.0} rev/s² (0.13 N·m − friction on 1e-4 kg·m² ≈ 170)");
        assert!((120.0..220.0).contains(&accel), "acceleration {accel} rev/s²");
        let tx = m.run(300).await;
        let v = f64::from(tx.velocity) / REV_F;
        println!(
            "cst 10 % with G472 = 10 rev/s: 606Ch {v:.2} rev/s, 6077h {} ‰",
            tx.torque
        );
        assert!((9.0..10.5).contains(&v), "speed limited at 10 rev/s: {v}");
        assert!(tx.torque < 100, "the limiter reduces the torque: {} ‰", tx.torque);
        // negative torque brakes and reverses, limited by G475
        m.set_target_torque(-100);
        let tx = m.run(400).await;
        let v = f64::from(tx.velocity) / REV_F;
        assert!((-10.5..-9.0).contains(&v), "speed limited at −10 rev/s: {v}");
        assert_eq!(tx.state(), sw::OE);
    });
}

// ---------------------------------------------------------------------------
// Drive-based modes (C-041 … C-056) and homing (C-058 … C-078)
// ---------------------------------------------------------------------------

/// Starts a pp move (bit 4 edge with `bits`) and checks the set-point
/// handshake: bit 12 acknowledges, then clears when bit 4 is taken back.
async fn pp_start(m: &mut Cyclic<'_>, target: i32, bits: u16) {
    m.set_target_position(target);
    m.set_controlword(CW_ENABLED | bits);
    m.run(1).await;
    m.set_controlword(CW_ENABLED | bits | CW_BIT4);
    let ack = m.run_until(5, |t| t.bit(12)).await;
    assert!(
        ack.is_some(),
        "set-point acknowledge (bit 12): {:#06x}",
        m.tx.statusword
    );
    m.set_controlword(CW_ENABLED | bits);
    let off = m.run_until(5, |t| !t.bit(12)).await;
    assert!(
        off.is_some(),
        "bit 12 clears after bit 4 = 0: {:#06x}",
        m.tx.statusword
    );
}

#[test]
fn c041_c048_pp_moves_to_target_and_sets_target_reached() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        // 5 rev/s, 50 rev/s² (6081h, 6083h, 6084h by SDO in Op)
        set_profile(sd, Some(5 * REV as u32), 50 * REV as u32).await;
        let tx = m.enable_in(1).await;
        assert_eq!(tx.mode_display, 1);

        // C-050: an absolute move is refused before the axis is referenced
        m.set_target_position(3 * REV);
        m.set_controlword(CW_ENABLED | CW_BIT4);
        let tx = m.run(50).await;
        assert!(
            !tx.bit(12),
            "no acknowledge while not referenced: {:#06x}",
            tx.statusword
        );
        assert!(tx.position.abs() < REV / 100, "no motion: {}", tx.position);
        m.set_controlword(CW_ENABLED);
        m.run(2).await;

        // reference (method 37 at 607Ch = 0), back to pp
        home_here(m).await;
        m.set_mode(1);
        m.run(3).await;

        // absolute 0 → 3 rev: 0.25 rev ramps at 50 rev/s² (+ jerk), 2.5 rev at 5 rev/s
        let t0 = m.now().as_ns();
        pp_start(m, 3 * REV, 0).await;
        assert!(!m.tx.bit(10), "target reached clears with the new set-point");
        let mut peak = 0i32;
        let mut reached_at = None;
        for k in 0..1500 {
            let tx = m.cycle().await;
            peak = peak.max(tx.velocity);
            if tx.bit(10) {
                reached_at = Some(k);
                break;
            }
        }
        assert!(
            reached_at.is_some(),
            "bit 10 target reached: {:#06x}",
            m.tx.statusword
        );
        let took_ms = (m.now().as_ns() - t0) / 1_000_000;
        let tx = m.tx;
        println!(
            "pp 0 → 3 rev (5 rev/s, 50 rev/s²): target reached after {took_ms} ms, peak 606Ch {:.3} rev/s, \
             error at bit 10 {} inc",
            f64::from(peak) / REV_F,
            3 * REV - tx.position
        );
        assert!((700..1000).contains(&took_ms), "move time {took_ms} ms");
        assert!(f64::from(peak) / REV_F < 5.2, "6081h caps the velocity: {peak}");
        assert!(
            (3 * REV - tx.position).abs() <= REV / 360,
            "in the window I22: {}",
            tx.position
        );
        let tx = m.run(300).await;
        println!(
            "pp: 300 ms after bit 10 the error is {} inc",
            3 * REV - tx.position
        );
        assert!(tx.bit(10), "stays in the window");

        // a move back to 0, replaced after 200 ms by an immediate (bit 5) set-point to 1 rev (C-044)
        pp_start(m, 0, 0).await;
        m.run(200).await;
        assert!(m.tx.velocity < -REV, "moving back: {}", m.tx.velocity);
        pp_start(m, REV, CW_BIT5).await;
        m.run_until(1500, |t| t.bit(10)).await.expect("reached 1 rev");
        let min_pos = m.tx.position;
        assert!((REV - min_pos).abs() <= REV / 360, "at 1 rev: {min_pos}");

        // relative (bit 6, 60F2h = 0: to the last target) +0.5 rev (C-046)
        pp_start(m, REV / 2, CW_BIT6).await;
        m.run_until(1500, |t| t.bit(10)).await.expect("reached 1.5 rev");
        let tx = m.tx;
        assert!(
            (REV + REV / 2 - tx.position).abs() <= REV / 360,
            "relative move to 1.5 rev: {}",
            tx.position
        );
        assert_eq!(tx.state(), sw::OE);
    });
}

#[test]
fn c055_c056_pv_reaches_velocity_and_reports_zero_speed() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        set_profile(sd, None, 40 * REV as u32).await;
        let tx = m.enable_in(3).await;
        assert_eq!(tx.mode_display, 3);
        let tx = m.run(20).await;
        assert!(tx.bit(12), "bit 12 velocity zero at rest: {:#06x}", tx.statusword);

        // 4 rev/s at 40 rev/s² (+ jerk 60A4h): about 0.1 s
        let v = 4 * REV;
        m.set_target_velocity(v);
        let tx = m.run(30).await;
        assert!(!tx.bit(10), "not yet reached: {:#06x}", tx.statusword);
        assert!(!tx.bit(12), "no longer zero speed: {:#06x}", tx.statusword);
        let reached = m
            .run_until(400, |t| t.bit(10))
            .await
            .expect("bit 10 set velocity reached")
            + 30;
        let tx = m.tx;
        println!(
            "pv 0 → 4 rev/s at 40 rev/s²: bit 10 after {reached} ms, 606Ch {:.3} rev/s",
            f64::from(tx.velocity) / REV_F
        );
        assert!((95..250).contains(&reached), "ramp time {reached} ms");
        assert!((tx.velocity - v).abs() < REV / 10, "606Ch {}", tx.velocity);
        let tx = m.run(100).await;
        assert!(tx.bit(10) && !tx.bit(13), "steady: {:#06x}", tx.statusword);
        assert!((tx.velocity - v).abs() < REV / 100, "606Ch {}", tx.velocity);

        // back to 0: bit 12 once the axis stands
        m.set_target_velocity(0);
        m.run_until(400, |t| t.bit(12) && t.velocity.abs() < REV / 10)
            .await
            .expect("zero speed");
        assert_eq!(m.tx.state(), sw::OE);
    });
}

/// A150 (application cycle, U16 µs).
const A150: u16 = drive_ecat::parameter_index(0, 150);

/// E-125 / C-144 in free run (no SYNC0): the control cycle runs at A150,
/// whatever its value, so a ramp takes the time its acceleration says and
/// the axis turns at the commanded speed. (The control timer once stayed at
/// 1 ms while the axis integrated with A150's dt: 4× too fast at 4 ms,
/// 4× too slow at 250 µs.)
#[test]
fn e125_c144_free_run_moves_at_the_commanded_speed_at_every_a150() {
    for a150_us in [4000u16, 250] {
        let sim = line(1);
        with_master(&sim, async |md, clock| {
            let group = init(md, clock).await;
            let sd = group.subdevice(md, 0).unwrap();
            sd.sdo_write(A150, 0, a150_us).await.expect("A150 in Pre-Op");
            let group = group.into_op(md).await.expect("OP");
            let sd = group.subdevice(md, 0).unwrap();
            set_profile(&sd, None, 40 * REV as u32).await;
            let mut m = Cyclic::new(md, &group, &sim, 0);
            m.enable_in(3).await;
            m.run(20).await;
            // 0 → 4 rev/s at 40 rev/s² takes about 0.1 s of (simulated) time
            let v = 4 * REV;
            let t0 = sim.borrow().now().as_ns();
            m.set_target_velocity(v);
            m.run_until(2000, |t| t.bit(10) && t.velocity > v - REV / 20)
                .await
                .expect("velocity reached");
            let ramp_ms = (sim.borrow().now().as_ns() - t0) as f64 / 1e6;
            m.run(100).await;
            // the plant turns at 4 rev/s: over 0.5 s it moves 2 revolutions
            let p0 = sim.borrow().drives()[0].motors[0].position_inc_f64();
            let t0 = sim.borrow().now().as_ns();
            m.run(500).await;
            let dt = (sim.borrow().now().as_ns() - t0) as f64 / 1e9;
            let revs = (sim.borrow().drives()[0].motors[0].position_inc_f64() - p0) / REV_F;
            println!(
                "A150 = {a150_us} µs: ramp {ramp_ms:.1} ms, {revs:.3} rev in {dt:.3} s ({:.3} rev/s), 606Ch {:.3} rev/s",
                revs / dt,
                f64::from(m.tx.velocity) / REV_F
            );
            assert!(
                (95.0..500.0).contains(&ramp_ms),
                "A150 {a150_us}: ramp {ramp_ms} ms"
            );
            assert!(
                (revs / dt - 4.0).abs() < 0.04,
                "A150 {a150_us}: {} rev/s",
                revs / dt
            );
            assert!(
                (m.tx.velocity - v).abs() < REV / 100,
                "A150 {a150_us}: 606Ch {}",
                m.tx.velocity
            );
        });
    }
}

#[test]
fn c058_c061_c078_homing_method_37_through_pdo() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        sd.sdo_write(0x6098, 0, 37i8).await.unwrap();
        sd.sdo_write(0x607C, 0, 123_456i32).await.unwrap();
        let tx = m.enable_in(6).await;
        assert_eq!(tx.mode_display, 6);
        let before = tx.position;
        // a steady bit 4 from enable on is no start: nothing happens (C-058)
        let tx = m.run(10).await;
        assert!(!tx.bit(12), "not referenced yet: {:#06x}", tx.statusword);
        let tx = home_here(m).await;
        println!("method 37: 6064h {before} → {}", tx.position);
        assert!(
            (tx.position - 123_456).abs() < 10,
            "the position reads 607Ch at once (C-061, C-078): {}",
            tx.position
        );
        assert!(
            tx.bit(12) && tx.bit(10) && !tx.bit(13),
            "homing done: {:#06x}",
            tx.statusword
        );
        assert!(motor_position(&sim, 0).abs() < 100, "no motion");
    });
}

#[test]
fn c058_c059_c071_homing_method_19_on_a_reference_switch() {
    let sim = line(1);
    // reference switch on the positive side: actuated at 1 rev + 1000 inc and above
    let edge = i64::from(REV) + 1000;
    with_drive(&sim, |d| {
        d.motors[0].switches_mut().reference = PositionInput::above(edge)
    });
    let home_offset = -5000;
    with_cyclic(&sim, async |m, sd| {
        sd.sdo_write(0x6098, 0, 19i8).await.unwrap();
        sd.sdo_write(0x607C, 0, home_offset).await.unwrap();
        let fast: u32 = sd.sdo_read(0x6099, 1).await.unwrap();
        let slow: u32 = sd.sdo_read(0x6099, 2).await.unwrap();
        m.enable_in(6).await;
        m.set_controlword(CW_ENABLED | CW_BIT4);
        let t0 = m.now().as_ns();
        let mut saw_switch = false;
        let mut peak = 0i32;
        let mut running_bits_ok = true;
        let mut done = false;
        for k in 0..4000 {
            let tx = m.cycle().await;
            saw_switch |= tx.digital_inputs & 0b100 != 0;
            peak = peak.max(tx.velocity);
            if tx.bit(12) && tx.bit(10) {
                done = true;
                break;
            }
            // Tab. 26 while moving: 000 (or 010 once the reference is set)
            // (the first TxPDO still shows 001 "not started": one cycle of bus delay)
            if k > 1 {
                running_bits_ok &= !tx.bit(13) && !tx.bit(10);
            }
        }
        assert!(done, "homing done (bits 12 and 10): {:#06x}", m.tx.statusword);
        assert!(running_bits_ok, "bits 13/10 stay 0 while homing runs");
        assert!(saw_switch, "60FDh bit 2 showed the home switch on the way");
        let took_ms = (m.now().as_ns() - t0) / 1_000_000;
        m.set_controlword(CW_ENABLED);
        let tx = m.run(20).await;
        // the switch edge now reads 607Ch: compare through the plant's encoder
        let enc = motor_position(&sim, 0);
        let edge_reads = i64::from(tx.position) - (enc - edge);
        let err = edge_reads - i64::from(home_offset);
        println!(
            "method 19: done after {took_ms} ms (search {:.2} rev/s, peak 606Ch {:.2} rev/s, creep {:.2} rev/s); \
             the switch edge reads {edge_reads} (607Ch {home_offset}, error {err} inc)",
            f64::from(fast) / REV_F,
            f64::from(peak) / REV_F,
            f64::from(slow) / REV_F,
        );
        // without an edge latch the edge is seen within one creep step (slow / 1 kHz)
        let creep_step = i64::from(slow / 1000);
        assert!(
            err.abs() <= 2 * creep_step,
            "reference error {err} inc, creep step {creep_step}"
        );
        assert!(
            tx.digital_inputs & 0b100 == 0,
            "stopped off the switch (approach negative)"
        );
        assert!(enc < edge, "left the switch on the negative side: {enc}");
        assert!(tx.bit(12) && !tx.bit(13), "referenced: {:#06x}", tx.statusword);
    });
}

// ---------------------------------------------------------------------------
// Quick stop, fault and reset (C-010, C-011, C-016, C-017)
// ---------------------------------------------------------------------------

#[test]
fn c010_c011_quick_stop_through_pdo() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        // 6085h = 100 rev/s²: 5 rev/s stop in 50 ms over 0.125 rev
        sd.sdo_write(0x6085, 0, 100 * REV as u32).await.unwrap();
        let qs_option: i16 = sd.sdo_read(0x605A, 0).await.unwrap();
        assert_eq!(qs_option, 2, "605Ah default: quick stop ramp, then SOD");
        m.csv_reach(5 * REV).await;

        // quick stop: bit 2 = 0 with bits 0, 1, 3 kept (0x000B)
        let t0 = m.now().as_ns();
        let p0 = m.tx.position;
        m.set_controlword(0x000B);
        let qsa = m.run_until(5, |t| t.state() == sw::QSA).await;
        assert!(
            qsa.is_some(),
            "Quick stop active 0x0007: {:#06x}",
            m.tx.statusword
        );
        let mut stopped_at = None;
        let mut left_at = None;
        let mut states = vec![m.tx.state()];
        for _ in 0..300 {
            let tx = m.cycle().await;
            // standstill as the drive sees it: |606Ch| < C40 (0.1 rev/s)
            if stopped_at.is_none() && tx.velocity.abs() < REV / 10 {
                stopped_at = Some((m.now().as_ns() - t0) / 1_000_000);
            }
            if *states.last().unwrap() != tx.state() {
                states.push(tx.state());
            }
            if tx.state() == sw::SOD {
                left_at = Some((m.now().as_ns() - t0) / 1_000_000);
                break;
            }
            // the set velocity of csv is ignored meanwhile (C-024)
            assert!(
                tx.velocity < 5 * REV + REV / 10,
                "no acceleration during the stop"
            );
        }
        let stopped_at = stopped_at.expect("standstill");
        let left_at = left_at.expect("Switch on disabled after the stop (T12)");
        let distance = f64::from(m.tx.position - p0) / REV_F;
        println!(
            "quick stop from 5 rev/s at 6085h = 100 rev/s²: standstill after {stopped_at} ms over {distance:.3} rev, \
             Switch on disabled after {left_at} ms; states {states:04x?}"
        );
        assert_eq!(
            states,
            vec![sw::QSA, sw::SOD],
            "QSA, then SOD: no return to OE (no T16)"
        );
        assert!((45..90).contains(&stopped_at), "ramp of 6085h: {stopped_at} ms");
        assert!(
            (0.11..0.2).contains(&distance),
            "stopping distance {distance} rev"
        );
        assert!(left_at >= stopped_at, "SOD only after standstill");
        // the master still sends 0x000B and then 0x000F: both keep SOD
        for cw in [0x000B, 0x000F] {
            m.set_controlword(cw);
            let tx = m.run(20).await;
            assert_eq!(tx.state(), sw::SOD, "{cw:#06x} in SOD: {:#06x}", tx.statusword);
        }
        assert!(motor_rev_s(&sim, 0).abs() < 0.01, "the motor stands");
    });
}

/// Reads one EMCY (CoE service 1) from SM1: (603Fh-style code, error register).
async fn receive_emcy<S>(mbx: &mut RawMailbox, sd: &ethercrab::SubDeviceRef<'_, S>) -> (u16, u8, Vec<u8>) {
    let (kind, data) = mbx.receive(sd).await.expect("a mailbox message");
    assert_eq!(kind, 3, "CoE");
    assert_eq!(
        u16::from_le_bytes([data[0], data[1]]) >> 12,
        1,
        "CoE service 1 = EMCY"
    );
    (
        u16::from_le_bytes([data[2], data[3]]),
        data[4],
        data[2..].to_vec(),
    )
}

#[test]
fn c016_c017_e007_e087_e088_following_error_fault_emcy_and_reset() {
    let sim = line(1);
    // a rigid end stop at +0.5 rev blocks the motor
    with_drive(&sim, |d| {
        d.motors[0].params_mut().end_stops_inc = Some((-10 * i64::from(REV), i64::from(REV / 2)));
    });
    with_cyclic(&sim, async |m, sd| {
        // I470 = 1: the following error reaction is a fault (event 54)
        sd.sdo_write(drive_ecat::parameter_index(8, 470), 0, 1u8)
            .await
            .unwrap();
        // following error window 0.05 rev, 10 ms (6065h, 6066h)
        sd.sdo_write(0x6065, 0, (REV / 20) as u32).await.unwrap();
        sd.sdo_write(0x6066, 0, 10u16).await.unwrap();
        m.set_mode(8);
        m.run(3).await;
        m.set_target_position(m.tx.position);
        m.enable().await;

        // csp towards 2 rev at 2 rev/s: blocked at 0.5 rev
        let mut fault_at = None;
        let mut states = vec![m.tx.state()];
        for k in 1..1500 {
            let target = (2 * k as i64 * i64::from(REV) / 1000).min(2 * i64::from(REV)) as i32;
            m.set_target_position(target);
            let tx = m.cycle().await;
            if *states.last().unwrap() != tx.state() {
                states.push(tx.state());
            }
            if tx.state() == sw::FAULT {
                fault_at = Some(k);
                break;
            }
        }
        let fault_at = fault_at.expect("a following-error fault");
        let tx = m.tx;
        println!(
            "blocked at {} inc: Fault after {fault_at} ms, states {states:04x?}, statusword {:#06x}",
            tx.position, tx.statusword
        );
        assert!(
            states.contains(&sw::FRA) || states.contains(&sw::FAULT),
            "{states:04x?}"
        );
        assert_eq!(*states.last().unwrap(), sw::FAULT);
        assert!(tx.position <= REV / 2 + 10, "at the end stop: {}", tx.position);

        // the EMCY is in the mailbox, 603Fh and 1001h show the fault
        let mut mbx = RawMailbox::new();
        let (code, register, raw) = receive_emcy(&mut mbx, sd).await;
        println!("EMCY {raw:02x?}");
        assert_eq!(code, 0x8611, "following error (event 54)");
        assert_ne!(register, 0, "error register in the EMCY");
        let mut coe = CoeClient::new();
        let reg = coe.upload(sd, 0x1001, 0).await.unwrap();
        assert_ne!(reg[0], 0, "1001h error register");
        let e603f = coe.upload(sd, 0x603F, 0).await.unwrap();
        assert_eq!(u16::from_le_bytes([e603f[0], e603f[1]]), 0x8611, "603Fh");

        // bit 7 = 0 keeps the fault; its rising edge resets (T15)
        m.set_target_position(m.tx.position);
        m.set_controlword(0x0000);
        let tx = m.run(10).await;
        assert_eq!(
            tx.state(),
            sw::FAULT,
            "no reset without bit 7: {:#06x}",
            tx.statusword
        );
        m.set_controlword(0x0080);
        let reset = m.run_until(3, |t| t.state() == sw::SOD).await;
        assert!(
            reset.is_some(),
            "the rising edge of bit 7 resets: {:#06x}",
            m.tx.statusword
        );
        let tx = m.run(10).await;
        assert_eq!(
            tx.state(),
            sw::SOD,
            "stays SOD with bit 7 steady: {:#06x}",
            tx.statusword
        );
        let (code, register, raw) = receive_emcy(&mut mbx, sd).await;
        println!("EMCY {raw:02x?}");
        assert_eq!((code, register), (0, 0), "fault cleared");
        let reg = coe.upload(sd, 0x1001, 0).await.unwrap();
        assert_eq!(reg[0], 0, "1001h cleared");
        // and the axis can be enabled again (away from the stop)
        m.set_controlword(0);
        m.run(2).await;
        m.enable().await;
        assert!(
            coe.emergencies.is_empty(),
            "no further EMCY: {:02x?}",
            coe.emergencies
        );
    });
}

// ---------------------------------------------------------------------------
// Axis B (C-134) and touch probe (C-121 … C-123)
// ---------------------------------------------------------------------------

#[test]
fn c134_axis_b_moves_independently_by_sdo() {
    if !drive_tests::has_axis_b("c134: axis B moves") {
        return;
    }
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        m.set_mode(9);
        m.run(3).await;

        // axis B in pv at 2 rev/s, everything by SDO at +800h
        sd.sdo_write(0x6060 + B, 0, 3i8).await.unwrap();
        sd.sdo_write(0x6083 + B, 0, 50 * REV as u32).await.unwrap();
        sd.sdo_write(0x6084 + B, 0, 50 * REV as u32).await.unwrap();
        sd.sdo_write(0x60FF + B, 0, 2 * REV).await.unwrap();
        for (cw, state) in [(0x0006u16, sw::RTSO), (0x0007, sw::SO), (0x000F, sw::OE)] {
            sd.sdo_write(0x6040 + B, 0, cw).await.unwrap();
            m.run(3).await;
            let s: u16 = sd.sdo_read(0x6041 + B, 0).await.unwrap();
            assert_eq!(s & 0x6F, state, "axis B after {cw:#06x}: {s:#06x}");
            // axis A's TxPDO: untouched, Switch on disabled
            assert_eq!(m.tx.state(), sw::SOD, "axis A: {:#06x}", m.tx.statusword);
        }
        let mode_b: i8 = sd.sdo_read(0x6061 + B, 0).await.unwrap();
        assert_eq!(mode_b, 3, "6861h");
        m.run(200).await;
        let v_b: i32 = sd.sdo_read(0x606C + B, 0).await.unwrap();
        let p_b: i32 = sd.sdo_read(0x6064 + B, 0).await.unwrap();
        let s_b: u16 = sd.sdo_read(0x6041 + B, 0).await.unwrap();
        println!(
            "axis B pv: 686Ch {:.3} rev/s, 6864h {:.3} rev, 6841h {s_b:#06x}; axis A 6064h {} 606Ch {}",
            f64::from(v_b) / REV_F,
            f64::from(p_b) / REV_F,
            m.tx.position,
            m.tx.velocity
        );
        assert!((v_b - 2 * REV).abs() < REV / 20, "686Ch {v_b}");
        assert!(s_b & (1 << 10) != 0, "axis B velocity reached: {s_b:#06x}");
        assert!(p_b > REV / 4, "6864h follows the motor: {p_b}");
        assert!((motor_rev_s(&sim, 1) - 2.0).abs() < 0.05, "motor B turns");
        assert_eq!(m.tx.state(), sw::SOD);
        assert_eq!((m.tx.position, m.tx.velocity), (0, 0), "axis A stands");
        assert_eq!(motor_position(&sim, 0), 0, "motor A stands");

        // now axis A through the PDO in csv at −1 rev/s: B keeps its 2 rev/s
        m.enable().await;
        m.set_target_velocity(-REV);
        m.run(200).await;
        let v_b: i32 = sd.sdo_read(0x606C + B, 0).await.unwrap();
        assert!(
            (m.tx.velocity + REV).abs() < REV / 50,
            "axis A −1 rev/s: {}",
            m.tx.velocity
        );
        assert!((v_b - 2 * REV).abs() < REV / 20, "axis B unchanged: {v_b}");
        // quick stop on A leaves B running
        m.set_controlword(0x000B);
        m.run_until(300, |t| t.state() == sw::SOD)
            .await
            .expect("A: QS → SOD");
        let s_b: u16 = sd.sdo_read(0x6041 + B, 0).await.unwrap();
        assert_eq!(s_b & 0x6F, sw::OE, "axis B still enabled: {s_b:#06x}");
        assert!((motor_rev_s(&sim, 1) - 2.0).abs() < 0.05, "motor B still turns");
    });
}

#[test]
fn c121_c122_c123_touch_probe_latches_the_edges_of_input_1() {
    let sim = line(1);
    // probe input 1 high between 0.3 rev + 777 and 0.6 rev − 55 (motor A)
    let rise = i64::from(REV) * 3 / 10 + 777;
    let fall = i64::from(REV) * 6 / 10 - 55;
    with_drive(&sim, |d| {
        d.motors[0].switches_mut().probe1 = PositionInput::window(rise, fall)
    });
    with_cyclic(&sim, async |m, sd| {
        // probe 1 on, single shot, rising (bit 4) and falling (bit 5) edges; source 60D0h:01 = input 1
        sd.sdo_write(0x60B8, 0, 0x0031u16).await.unwrap();
        let source: i16 = sd.sdo_read(0x60D0, 1).await.unwrap();
        assert_eq!(source, 1);
        m.set_mode(9);
        m.run(3).await;
        let status: u16 = sd.sdo_read(0x60B9, 0).await.unwrap();
        assert_eq!(status & 0x07, 0x01, "enabled, nothing latched: {status:#06x}");
        m.enable().await;
        m.set_target_velocity(2 * REV);
        m.run_until(1000, |t| i64::from(t.position) > fall + i64::from(REV / 10))
            .await
            .expect("past the probe window");
        m.set_target_velocity(0);
        m.run(50).await;
        let (status, pos, neg) = probe1(sd).await;
        println!("touch probe 1: 60B9h {status:#06x}, 60BAh {pos} (edge {rise}), 60BBh {neg} (edge {fall})");
        assert_eq!(
            status & 0x07,
            0x07,
            "enabled, rising and falling latched: {status:#06x}"
        );
        assert!((i64::from(pos) - rise).abs() <= 1, "60BAh {pos} vs {rise}");
        assert!((i64::from(neg) - fall).abs() <= 1, "60BBh {neg} vs {fall}");
        // C-126: clearing bit 0 resets the status, the values stay
        sd.sdo_write(0x60B8, 0, 0x0030u16).await.unwrap();
        m.run(3).await;
        let status: u16 = sd.sdo_read(0x60B9, 0).await.unwrap();
        let kept: i32 = sd.sdo_read(0x60BA, 0).await.unwrap();
        assert_eq!(status & 0x07, 0, "status cleared: {status:#06x}");
        assert_eq!(kept, pos, "60BAh kept");
    });
}

#[test]
fn c071_homing_method_19_started_on_the_switch() {
    let sim = line(1);
    // the axis starts on the switch (actuated from −0.05 rev on)
    let edge = -i64::from(REV) / 20;
    with_drive(&sim, |d| {
        d.motors[0].switches_mut().reference = PositionInput::above(edge)
    });
    with_cyclic(&sim, async |m, sd| {
        sd.sdo_write(0x6098, 0, 19i8).await.unwrap();
        sd.sdo_write(0x607C, 0, 0i32).await.unwrap();
        let tx = m.enable_in(6).await;
        assert!(
            tx.digital_inputs & 0b100 != 0,
            "on the switch: 60FDh {:#x}",
            tx.digital_inputs
        );
        m.set_controlword(CW_ENABLED | CW_BIT4);
        let mut max_pos = 0;
        m.run_until(3000, |t| {
            max_pos = max_pos.max(t.position);
            t.bit(12) && t.bit(10)
        })
        .await
        .expect("homing done");
        let took = m.cycles;
        let tx = m.run(20).await;
        let edge_reads = i64::from(tx.position) - (motor_position(&sim, 0) - edge);
        println!("method 19 from on the switch: done after ~{took} cycles, edge reads {edge_reads}, max 6064h {max_pos}");
        assert!(
            max_pos < REV / 100,
            "creeps off negative at once, no positive search: {max_pos}"
        );
        assert!(
            edge_reads.abs() <= 2 * i64::from(REV / 4 / 1000),
            "edge reads 607Ch = 0: {edge_reads}"
        );
    });
}

#[test]
fn c036_csp_following_error_bit_13_without_fault() {
    let sim = line(1);
    with_drive(&sim, |d| {
        d.motors[0].params_mut().end_stops_inc = Some((-i64::from(REV), i64::from(REV / 4)));
    });
    with_cyclic(&sim, async |m, sd| {
        sd.sdo_write(0x6065, 0, (REV / 50) as u32).await.unwrap();
        sd.sdo_write(0x6066, 0, 20u16).await.unwrap();
        m.enable_in(8).await;
        // 1 rev/s ramp; blocked at 0.25 rev
        let mut first_bit13 = None;
        for k in 1..=600 {
            m.set_target_position((i64::from(REV) * k / 1000) as i32);
            let tx = m.cycle().await;
            if tx.bit(13) && first_bit13.is_none() {
                first_bit13 = Some((k, tx.following_error));
            }
        }
        let (k, fe) = first_bit13.expect("bit 13 following error");
        println!(
            "csp blocked at 0.25 rev: bit 13 at {k} ms with 60F4h {fe} (window {})",
            REV / 50
        );
        assert!(fe > REV / 50, "bit 13 only beyond 6065h: {fe}");
        // 0.25 rev + 0.02 rev window at 1 rev/s = 270 ms, + 20 ms timeout
        assert!((280..330).contains(&k), "window + timeout: {k} ms");
        assert_eq!(
            m.tx.state(),
            sw::OE,
            "no fault by default: {:#06x}",
            m.tx.statusword
        );
        assert!(m.tx.bit(13));
        // back within the window: bit 13 clears
        m.set_target_position(REV / 4);
        let cleared = m.run_until(100, |t| !t.bit(13)).await;
        assert!(cleared.is_some(), "bit 13 clears: {:#06x}", m.tx.statusword);
    });
}

#[test]
fn c027_mode_change_between_pv_and_csv_only_at_standstill() {
    let sim = line(1);
    with_cyclic(&sim, async |m, _| {
        m.enable_in(3).await;
        m.set_target_velocity(2 * REV);
        m.run_until(500, |t| t.bit(10) && t.velocity > REV)
            .await
            .expect("pv at 2 rev/s");
        // csv requested while moving: refused, pv stays active (6061h = 3)
        m.set_mode(9);
        let tx = m.run(30).await;
        assert_eq!(tx.mode_display, 3, "no change while moving");
        // (the velocity loop overshoots by ~6 % after the 100 rev/s² default ramp)
        assert!(
            (tx.velocity - 2 * REV).abs() < REV / 4,
            "still pv at 2 rev/s: {}",
            tx.velocity
        );
        // stopped in pv (a master cannot stop pv while asking csv: back to pv with 0)
        m.set_mode(3);
        m.set_target_velocity(0);
        m.run_until(500, |t| t.velocity.abs() < REV / 20)
            .await
            .expect("stopped");
        m.run(20).await;
        m.set_mode(9);
        let changed = m.run_until(20, |t| t.mode_display == 9).await;
        assert!(
            changed.is_some(),
            "csv at standstill: 6061h {}",
            m.tx.mode_display
        );
        assert!(m.tx.bit(12) && m.tx.state() == sw::OE);
    });
}
