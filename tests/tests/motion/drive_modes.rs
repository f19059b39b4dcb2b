//! Drive-based modes (C-041 … C-056) and homing (C-058 … C-078): pp and its set-point
//! handshake, pv, free run at every A150 (E-125, C-144), homing methods 37 and 19, and the
//! change between pv and csv only at standstill (C-027).

use super::*;

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
