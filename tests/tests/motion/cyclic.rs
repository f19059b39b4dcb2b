//! Cyclic modes (C-035 … C-039): csp following a minimum-jerk profile from the master, its
//! following-error bit 13, csv and cst.

use super::*;

/// Minimum-jerk profile 0 → `d` over `t_s`: d·(10s³ − 15s⁴ + 6s⁵).
fn min_jerk(d: f64, t_s: f64, t: f64) -> f64 {
    let s = (t / t_s).clamp(0.0, 1.0);
    d * s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)
}

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
