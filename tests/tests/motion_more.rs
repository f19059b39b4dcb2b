//! More modes through a real master (spec cia402.md §6.5, §8, §11;
//! features-cia402.md C-items): ip and vl with their own PDO maps, pt, jog,
//! hardware and software limit switches, touch-probe examples 2 and 3.
//! Every check reads what the master received (TxPDO or SDO).

use drive_tests::axis::*;
use drive_tests::{
    init, line, map_layout, sw, with_cyclic, with_master, Cyclic, Link, OpSubDevice, PreOpSubDevice,
    RawCyclic,
};
use drive_tests::{REV, REV_F};
use hil_sim::motor::{PositionInput, Switches};
use hil_sim::sim::Simulation;
use std::cell::RefCell;

/// 603Fh of event 53 (limit switch).
fn event_53() -> Option<u16> {
    drive_ecat::faults::fault_code_for_event(53).map(|(c, _)| c)
}

/// `sim`'s first drive with the mode map `layout` (by SDO in Pre-Op, then
/// `prepare` there), brought to Op with `len` bytes of process data each
/// way (`what`: the map and its item); `body` with a [`RawCyclic`] on it
/// and its SubDevice.
fn with_raw_map<T>(
    sim: &RefCell<Simulation>,
    layout: drive_ecat::PdoLayout,
    (len, what): (usize, &str),
    prepare: impl for<'a> AsyncFnOnce(&PreOpSubDevice<'a>),
    body: impl for<'a> AsyncFnOnce(&mut RawCyclic<'a>, &OpSubDevice<'a>) -> T,
) -> T {
    with_master(sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        map_layout(&sd, layout).await;
        prepare(&sd).await;
        let group = group.into_op(md).await.expect("OP with the map");
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(
            (sd.io_raw().outputs().len(), sd.io_raw().inputs().len()),
            (len, len),
            "{what}"
        );
        let mut m = RawCyclic::new(Link {
            md,
            group: &group,
            sim,
            slave: 0,
        });
        body(&mut m, &sd).await
    })
}

// ---------------------------------------------------------------------------
// ip (7) with the ip map (C-031 … C-034)
// ---------------------------------------------------------------------------

#[test]
fn c031_c032_c033_c034_ip_follows_60c1_only_while_bit_4() {
    let sim = line(1);
    with_raw_map(
        &sim,
        drive_ecat::PdoLayout::Ip,
        (7, "ip map: 7 bytes each way (C-034)"),
        async |sd| {
            // profile ramps of 0.1 rev/s² that ip must not apply (C-033)
            set_profile(sd, None, (REV / 10) as u32).await;
        },
        async |m, _| {
            let pos = |m: &RawCyclic<'_>| m.i32_at(3);
            let set = |m: &mut RawCyclic<'_>, p: i32| m.put(3, &p.to_le_bytes());
            m.set_mode(7);
            m.run(3).await;
            assert_eq!(m.mode_display(), 7, "6061h = ip");
            let start = pos(m);
            set(m, start);
            m.enable(0).await;
            m.run(10).await;
            assert!(!m.bit(12), "bit 12 = 0 without bit 4: {:#06x}", m.statusword());

            // bit 4 = 0: 60C1h:01 is not followed (C-031)
            set(m, start + REV);
            m.run(100).await;
            assert!((pos(m) - start).abs() < REV / 100, "holds: 6064h {}", pos(m));
            assert!(!m.bit(12), "bit 12 still 0: {:#06x}", m.statusword());
            assert!(
                motor_position(&sim, 0).abs() < i64::from(REV / 100),
                "the motor stands"
            );

            // bit 4 = 1: a 2 rev/s ramp from standstill, one set-point per cycle
            set(m, start);
            m.set_controlword(CW_ENABLED | CW_BIT4);
            m.run(3).await;
            assert!(m.bit(12), "bit 12 ip active: {:#06x}", m.statusword());
            let per_ms = 2 * i64::from(REV) / 1000;
            let mut at = Vec::new();
            for k in 1..=300i64 {
                set(m, start + (per_ms * k) as i32);
                m.cycle().await;
                assert_eq!(m.state(), sw::OE, "cycle {k}: {:#06x}", m.statusword());
                assert!(m.bit(12), "cycle {k}: bit 12");
                at.push(pos(m));
            }
            // full speed after 50 ms although 6083h would need 20 s (C-033)
            let v_early = f64::from(at[99] - at[49]) / REV_F / 0.050;
            let v_late = f64::from(at[299] - at[199]) / REV_F / 0.100;
            let lag = start + (per_ms * 300) as i32 - at[299];
            println!(
                "ip 2 rev/s ramp: v(50..100 ms) {v_early:.3} rev/s, v(200..300 ms) {v_late:.3}, lag {lag} inc"
            );
            assert!((v_early - 2.0).abs() < 0.1, "no acceleration limit: {v_early}");
            assert!((v_late - 2.0).abs() < 0.02, "follows 2 rev/s: {v_late}");
            assert!(lag.abs() < REV / 50, "lag {lag} inc");

            // hold the last set-point: settles on it
            let end = start + (per_ms * 300) as i32;
            m.run(300).await;
            assert!((pos(m) - end).abs() <= REV / 360, "6064h {} vs {end}", pos(m));

            // bit 4 back to 0: interpolation stops, bit 12 clears, a new 60C1h is ignored
            m.set_controlword(CW_ENABLED);
            set(m, end + REV);
            m.run(100).await;
            assert!(!m.bit(12), "bit 12 = 0: {:#06x}", m.statusword());
            assert_eq!(m.state(), sw::OE);
            assert!((pos(m) - end).abs() <= REV / 360, "holds {}", pos(m));
        },
    );
}

// ---------------------------------------------------------------------------
// vl (2) with the vl map (C-051 … C-054)
// ---------------------------------------------------------------------------

#[test]
fn c051_c052_c053_c054_vl_bits_4_5_6_ramp_and_limit() {
    let sim = line(1);
    with_raw_map(
        &sim,
        drive_ecat::PdoLayout::Vl,
        (5, "vl map: 5 bytes each way (C-054)"),
        async |sd| {
            // 6046h:02 max 600 rpm; 6048h 3000 rpm per 1 s (the default)
            sd.sdo_write(0x6046, 2, 600u32).await.unwrap();
        },
        async |m, sd| {
            let actual = |m: &RawCyclic<'_>| m.i16_at(3);
            let set = |m: &mut RawCyclic<'_>, rpm: i16| m.put(3, &rpm.to_le_bytes());
            let all = CW_ENABLED | CW_BIT4 | CW_BIT5 | CW_BIT6;
            m.set_mode(2);
            set(m, 300);
            m.run(3).await;
            m.enable(0).await;
            assert_eq!(m.mode_display(), 2);
            // bits 4/5/6 = 0: set value 0
            m.run(100).await;
            assert_eq!(actual(m), 0, "bits 4/5/6 = 0: stands");

            // all three: follows 6042h with the 6048h ramp (300 rpm at 3000 rpm/s = 100 ms)
            m.set_controlword(all);
            let t = m
                .run_until(400, |m| actual(m) >= 295)
                .await
                .expect("6044h reaches 300 rpm");
            println!("vl 0 → 300 rpm: 6044h ≥ 295 after {t} ms");
            assert!((90..200).contains(&t), "ramp time {t} ms");
            let mut mode_bits = 0u16;
            for _ in 0..200 {
                m.cycle().await;
                mode_bits |= m.statusword() & ((1 << 12) | (1 << 13));
            }
            assert!((actual(m) - 300).abs() <= 3, "6044h {}", actual(m));
            let demand: i16 = sd.sdo_read(0x6043, 0).await.unwrap();
            assert_eq!(demand, 300, "6043h ramp output (C-053)");
            assert_eq!(mode_bits, 0, "no vl statusword mode bits (C-053)");

            // bit 5 = 0: the last set value is frozen
            m.set_controlword(all & !CW_BIT5);
            set(m, 120);
            m.run(300).await;
            assert!((actual(m) - 300).abs() <= 3, "frozen at 300: {}", actual(m));
            // bit 5 = 1 again: the new set value
            m.set_controlword(all);
            m.run(300).await;
            assert!((actual(m) - 120).abs() <= 3, "120 rpm: {}", actual(m));

            // above 6046h:02: limited to 600 rpm (C-052)
            set(m, 1200);
            m.run(500).await;
            assert!((actual(m) - 600).abs() <= 5, "limited to 600: {}", actual(m));
            let demand: i16 = sd.sdo_read(0x6043, 0).await.unwrap();
            assert_eq!(demand, 600, "6043h limited");

            // bit 6 = 0: set value 0; back on: 600 again; bit 4 = 0: 0
            for (cw, rpm) in [(all & !CW_BIT6, 0i16), (all, 600), (all & !CW_BIT4, 0)] {
                m.set_controlword(cw);
                m.run(500).await;
                assert!(
                    (actual(m) - rpm).abs() <= 5,
                    "controlword {cw:#06x}: 6044h {} vs {rpm}",
                    actual(m)
                );
                assert_eq!(m.state(), sw::OE);
            }
        },
    );
}

// ---------------------------------------------------------------------------
// pt (4) (C-057)
// ---------------------------------------------------------------------------

#[test]
fn c057_pt_ramps_6071_with_6087_limited_by_6072_and_g472() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        sd.sdo_write(0x6087, 0, 1000u32).await.unwrap(); // 100 %/s
        let tx = m.enable_in(4).await;
        assert_eq!(tx.mode_display, 4);

        // default G472/G475 = 0: no motion (spec §6.5.8)
        m.set_target_torque(100);
        let tx = m.run(300).await;
        assert!(tx.velocity.abs() < REV / 20, "stands: {}", tx.velocity);
        assert!(tx.position.abs() < REV / 10, "stays: {}", tx.position);

        // back to 0, then G472 = 20 rev/s: 0 → 10 % along 6087h (100 ms)
        m.set_target_torque(0);
        m.run(200).await;
        torque_mode_speed_limit(sd, 20.0).await;
        m.run(5).await;
        assert!(m.tx.bit(10), "torque 0 reached: {:#06x}", m.tx.statusword);
        m.set_target_torque(100);
        let tx = m.run(50).await;
        println!("pt ramp: 6077h {} ‰ after 50 ms", tx.torque);
        assert!((35..65).contains(&tx.torque), "half way: {} ‰", tx.torque);
        assert!(!tx.bit(10), "not yet reached: {:#06x}", tx.statusword);
        let reached = m.run_until(100, |t| t.bit(10)).await.expect("bit 10") + 50;
        assert!((95..115).contains(&reached), "reached after {reached} ms");
        assert!((95..=100).contains(&m.tx.torque), "6077h {}", m.tx.torque);
        // the speed limit G472 takes over
        let tx = m.run(500).await;
        let v = f64::from(tx.velocity) / REV_F;
        println!(
            "pt 10 % with G472 = 20 rev/s: 606Ch {v:.2} rev/s, 6077h {} ‰",
            tx.torque
        );
        assert!((18.0..21.0).contains(&v), "speed limited: {v}");
        assert!(tx.torque < 100, "limiter reduces the torque: {}", tx.torque);

        // 6072h = 5 %: −10 % is capped at −5 % (C-057)
        sd.sdo_write(0x6072, 0, 50u16).await.unwrap();
        m.set_target_torque(-100);
        let mut min_t = 0i16;
        for _ in 0..250 {
            let tx = m.cycle().await;
            min_t = min_t.min(tx.torque);
        }
        println!(
            "pt −10 % with 6072h = 5 %: min 6077h {min_t} ‰, 606Ch {}",
            m.tx.velocity
        );
        assert!((-52..=-45).contains(&min_t), "capped at −5 %: {min_t}");
        assert!(m.tx.bit(10), "the capped set-point counts as reached");
        assert_eq!(m.tx.state(), sw::OE);
    });
}

// ---------------------------------------------------------------------------
// jog (−1) (C-088 … C-092)
// ---------------------------------------------------------------------------

#[test]
fn c088_c089_c090_jog_bits_4_and_5() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await.into_op(md).await.expect("OP");
        let mut m = Cyclic::new(md, &group, &sim, 0);
        let tx = m.enable_in(-1).await;
        assert_eq!(tx.mode_display, -1, "6061h = jog");
        let tx = m.run(20).await;
        assert!(tx.velocity.abs() < REV / 100);

        // bit 4: +I12 (1 rev/s) with I13 (10 rev/s²): 100 ms
        m.set_controlword(CW_ENABLED | CW_BIT4);
        let t = m
            .run_until(400, |t| t.velocity > REV * 97 / 100)
            .await
            .expect("jog + reaches I12");
        println!("jog +: 97 % of I12 after {t} ms");
        assert!((90..200).contains(&t), "I13 ramp: {t} ms");
        let mut mode_bits = 0;
        for _ in 0..200 {
            let tx = m.cycle().await;
            mode_bits |= tx.statusword & ((1 << 12) | (1 << 13));
        }
        assert!((m.tx.velocity - REV).abs() < REV / 50, "606Ch {}", m.tx.velocity);
        assert_eq!(mode_bits, 0, "no jog statusword mode bits");

        // bit 4 back: brakes with I45 (10 rev/s²) to standstill, about 0.05 rev
        let from = m.tx.position;
        m.set_controlword(CW_ENABLED);
        let t = m
            .run_until(400, |t| t.velocity.abs() < REV / 100)
            .await
            .expect("jog stops");
        m.run(50).await;
        let run_out = f64::from(m.tx.position - from) / REV_F;
        println!("jog stop: {t} ms, {run_out:.3} rev");
        assert!((80..200).contains(&t), "I45 ramp: {t} ms");
        assert!((0.03..0.09).contains(&run_out), "run-out {run_out} rev");

        // bit 5: −I12 with the same ramps (C-089)
        m.set_controlword(CW_ENABLED | CW_BIT5);
        m.run_until(400, |t| t.velocity < -REV * 97 / 100)
            .await
            .expect("jog − reaches −I12");
        m.run(100).await;
        assert!((m.tx.velocity + REV).abs() < REV / 50, "606Ch {}", m.tx.velocity);

        // both bits: brake to standstill (C-090)
        m.set_controlword(CW_ENABLED | CW_BIT4 | CW_BIT5);
        m.run_until(400, |t| t.velocity.abs() < REV / 100)
            .await
            .expect("both bits stop");
        let p = m.tx.position;
        m.run(200).await;
        assert!(
            (m.tx.position - p).abs() < REV / 200,
            "stands: {} vs {p}",
            m.tx.position
        );
        assert_eq!(m.tx.state(), sw::OE);

        // I12/I13 by SDO: 3 rev/s at 60 rev/s² (50 ms)
        group
            .subdevice(md, 0)
            .unwrap()
            .sdo_write(drive_ecat::params::I12, 0, 3 * REV as u32)
            .await
            .unwrap();
        group
            .subdevice(md, 0)
            .unwrap()
            .sdo_write(drive_ecat::params::I13, 0, 60 * REV as u32)
            .await
            .unwrap();
        m.set_controlword(CW_ENABLED | CW_BIT4);
        let t = m
            .run_until(400, |t| t.velocity > 3 * REV * 97 / 100)
            .await
            .expect("new I12");
        assert!((40..120).contains(&t), "I13 = 60 rev/s²: {t} ms");
    });
}

#[test]
fn c091_c092_jog_at_the_software_limits() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        m.enable_in(6).await;
        home_here(m).await;
        let limit = REV / 2;
        sd.sdo_write(0x607D, 1, -limit).await.unwrap();
        sd.sdo_write(0x607D, 2, limit).await.unwrap();

        // I26 = 1 (default): stops just before +0.5 rev, never past it (C-092)
        m.set_mode(-1);
        m.set_controlword(CW_ENABLED | CW_BIT4);
        let mut max_pos = i32::MIN;
        for _ in 0..1500 {
            let tx = m.cycle().await;
            max_pos = max_pos.max(tx.position);
        }
        let tx = m.tx;
        println!(
            "jog I26 = 1 towards +0.5 rev: max 6064h {max_pos} ({:+} inc), 606Ch {}, {:#06x}",
            max_pos - limit,
            tx.velocity,
            tx.statusword
        );
        assert_eq!(tx.mode_display, -1);
        assert_eq!(tx.state(), sw::OE, "no fault: {:#06x}", tx.statusword);
        assert!(max_pos <= limit + REV / 360, "never past the limit: {max_pos}");
        assert!(
            tx.position > limit - REV / 50,
            "stops just before: {}",
            tx.position
        );
        assert!(tx.velocity.abs() < REV / 100);
        // and back
        m.set_controlword(CW_ENABLED | CW_BIT5);
        m.run(300).await;
        assert!(
            m.tx.position < limit - REV / 10,
            "jog − moves away: {}",
            m.tx.position
        );

        // I26 = 0: past −0.5 rev a quick stop, no fault; the negative direction locked (C-091)
        sd.sdo_write(drive_ecat::params::I26, 0, 0u8).await.unwrap();
        m.set_controlword(CW_ENABLED);
        m.run(200).await;
        m.set_controlword(CW_ENABLED | CW_BIT5);
        let mut min_pos = i32::MAX;
        for _ in 0..2000 {
            let tx = m.cycle().await;
            min_pos = min_pos.min(tx.position);
        }
        let tx = m.tx;
        println!(
            "jog I26 = 0 towards −0.5 rev: min 6064h {min_pos} ({:+} inc), 606Ch {}, {:#06x}",
            min_pos + limit,
            tx.velocity,
            tx.statusword
        );
        assert_eq!(
            tx.state(),
            sw::OE,
            "quick stop without a fault: {:#06x}",
            tx.statusword
        );
        assert!(min_pos < -limit, "passes the limit a little: {min_pos}");
        assert!(min_pos > -limit - REV / 20, "quick-stop ramp: {min_pos}");
        assert!(tx.velocity.abs() < REV / 100, "stands: {}", tx.velocity);
        assert!(
            tx.bit(11),
            "internal limit (direction locked): {:#06x}",
            tx.statusword
        );
        // still locked: bit 5 again does not move
        m.set_controlword(CW_ENABLED);
        m.run(50).await;
        let p = m.tx.position;
        m.set_controlword(CW_ENABLED | CW_BIT5);
        m.run(300).await;
        assert!(m.tx.position >= p - REV / 200, "locked: {} vs {p}", m.tx.position);
        // the other way is free
        m.set_controlword(CW_ENABLED | CW_BIT4);
        m.run(300).await;
        assert!(m.tx.position > -limit + REV / 10, "moves away: {}", m.tx.position);
    });
}

// ---------------------------------------------------------------------------
// Limit switches (C-093 … C-106)
// ---------------------------------------------------------------------------

/// Waits for the fault state, reads 603Fh, resets the fault and enables again.
async fn fault_and_reset(m: &mut Cyclic<'_>, what: &str) -> u16 {
    let hit = m.run_until(1500, |t| t.state() == sw::FAULT).await;
    assert!(
        hit.is_some(),
        "{what}: fault, statusword {:#06x}",
        m.tx.statusword
    );
    let sd = m.link.group.subdevice(m.link.md, m.link.slave).unwrap();
    let code: u16 = sd.sdo_read(0x603F, 0).await.unwrap();
    m.reset_and_enable().await;
    code
}

#[test]
fn c093_c094_c095_hardware_limit_switch_faults_and_locks_the_direction() {
    let plus = i64::from(REV); // positive switch from +1 rev on, negative below −10 rev
    let sim = line_with_switches(Switches::linear_axis(
        -10 * i64::from(REV),
        plus,
        PositionInput::never(),
    ));
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await.into_op(md).await.expect("OP");
        let mut m = Cyclic::new(md, &group, &sim, 0);
        m.set_mode(9);
        m.run(3).await;
        // I101/I102 not set: the switch is not evaluated (C-093)
        m.enable().await;
        m.set_target_velocity(2 * REV);
        m.run_until(1500, |t| i64::from(t.position) > plus + i64::from(REV / 4))
            .await
            .expect("passes the unconfigured switch");
        assert_eq!(m.tx.state(), sw::OE);
        assert!(
            m.tx.digital_inputs & 0b10 != 0,
            "60FDh shows the switch: {:#x}",
            m.tx.digital_inputs
        );
        m.set_target_velocity(-2 * REV);
        m.run_until(1500, |t| t.position < 0).await.expect("back");
        m.set_target_velocity(0);
        m.run(200).await;

        // I101/I102 set: hitting +1 rev at 2 rev/s faults at once (event 53 cause 1)
        // (by SDO as a master does, issue 40: 1 = from the inputs)
        let sd = group.subdevice(md, 0).unwrap();
        limit_switches_from_inputs(&sd).await;
        m.run(5).await;
        assert_eq!(m.tx.state(), sw::OE, "inside the range: {:#06x}", m.tx.statusword);
        m.set_target_velocity(2 * REV);
        let code = fault_and_reset(&mut m, "positive switch").await;
        let at = motor_position(&sim, 0);
        println!(
            "HW limit +: 603Fh {code:#06x}, stopped at {:.3} rev",
            at as f64 / REV_F
        );
        assert_ne!(code, 0, "603Fh");
        assert!(
            at >= plus && at < plus + i64::from(REV / 4),
            "stopped just past the switch: {at}"
        );

        // enabled again on the switch: positive direction refused (C-095)
        m.set_target_velocity(REV);
        m.run(300).await;
        let now = motor_position(&sim, 0);
        println!(
            "on the switch, +1 rev/s: moved {} inc, {:#06x}",
            now - at,
            m.tx.statusword
        );
        assert!(now - at < i64::from(REV / 100), "positive refused: {}", now - at);
        assert_eq!(m.tx.state(), sw::OE, "no new fault: {:#06x}", m.tx.statusword);
        assert!(m.tx.bit(11), "internal limit bit 11: {:#06x}", m.tx.statusword);
        // away from the switch: allowed
        m.set_target_velocity(-REV);
        m.run(500).await;
        assert!(motor_position(&sim, 0) < plus - i64::from(REV / 4), "moves away");
        assert_eq!(m.tx.state(), sw::OE);
        m.set_target_velocity(0);
        m.run(200).await;
        // and the switch triggers again once left (C-095)
        m.set_target_velocity(2 * REV);
        fault_and_reset(&mut m, "positive switch again").await;
    });
}

#[test]
fn c099_c101_c102_c103_software_limits_fault_and_lock_the_direction() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        let limit = REV / 2;
        sd.sdo_write(0x607D, 1, -limit).await.unwrap();
        sd.sdo_write(0x607D, 2, limit).await.unwrap();
        m.enable_in(9).await;
        // not referenced: the software limits do not act (C-099)
        m.set_target_velocity(2 * REV);
        m.run_until(1000, |t| t.position > REV)
            .await
            .expect("passes +0.5 rev");
        assert_eq!(m.tx.state(), sw::OE, "{:#06x}", m.tx.statusword);
        m.set_target_velocity(-2 * REV);
        m.run_until(1000, |t| t.position < 0).await.expect("back");
        m.set_target_velocity(0);
        m.run_until(300, |t| t.velocity.abs() < REV / 100)
            .await
            .expect("stop");
        m.run(50).await;

        // referenced here (6064h = 0), then csv towards +0.5 rev: fault beyond limit + I22 (C-101)
        home_here(m).await;
        m.set_mode(9);
        m.run(20).await;
        assert_eq!(m.tx.mode_display, 9);
        m.set_target_velocity(REV);
        let mut max_pos = i32::MIN;
        let hit = m
            .run_until(1500, |t| {
                max_pos = max_pos.max(t.position);
                t.state() == sw::FRA || t.state() == sw::FAULT
            })
            .await
            .expect("software-limit fault");
        println!("SW limit +0.5 rev at 1 rev/s: fault after {hit} ms at {max_pos} inc");
        assert!(
            max_pos > limit + REV / 360 - REV / 100 && max_pos < limit + REV / 20,
            "faults at limit + I22: {max_pos}"
        );
        m.set_target_velocity(0);
        let code = fault_and_reset(m, "software limit").await;
        assert_eq!(Some(code), event_53(), "603Fh of event 53");
        let p = m.tx.position;
        assert!(p > limit, "beyond the limit after the fault reaction: {p}");

        // positive refused, bit 11 (C-102)
        m.set_target_velocity(REV);
        m.run(300).await;
        assert!(m.tx.position - p < REV / 100, "locked: {} vs {p}", m.tx.position);
        assert!(m.tx.bit(11), "internal limit: {:#06x}", m.tx.statusword);
        assert_eq!(m.tx.state(), sw::OE);
        // negative allowed; the lock holds until back inside by I22 (C-103)
        m.set_target_velocity(-REV / 4);
        m.run_until(2000, |t| t.position < limit)
            .await
            .expect("back inside");
        m.set_target_velocity(-REV / 4);
        m.run_until(2000, |t| t.position < limit - REV / 20)
            .await
            .expect("inside by more than I22");
        m.set_target_velocity(0);
        m.run(100).await;
        assert!(!m.tx.bit(11), "lock released: {:#06x}", m.tx.statusword);
        m.set_target_velocity(REV / 4);
        let before = m.tx.position;
        m.run(100).await;
        assert!(m.tx.position > before + REV / 100, "positive free again");
    });
}

// ---------------------------------------------------------------------------
// Touch probe examples 2 and 3 (C-124, C-127)
// ---------------------------------------------------------------------------

/// A stored touch-probe position within 1 inc of the edge `mark`.
#[track_caller]
fn at_mark(value: i32, mark: i64, what: &str) {
    assert!(
        (i64::from(value) - mark).abs() <= 1,
        "{what}: {value} (the edge at {mark})"
    );
}

/// Runs on at the set target velocity until the position has passed `to`
/// (upwards for a positive velocity, downwards for a negative one) within
/// `max` cycles, then stops and waits 100 ms.
async fn pass_and_stop(m: &mut Cyclic<'_>, max: usize, to: i64, what: &str) {
    let up = i64::from(m.tx.position) <= to;
    let past = |p: i64| if up { p > to } else { p < to };
    m.run_until(max, |t| past(i64::from(t.position)))
        .await
        .expect(what);
    m.set_target_velocity(0);
    m.run(100).await;
}

/// A line whose probe input 1 toggles (low first) at `k`/20 rev + `k` ·
/// `extra` inc for each `k` of `ks`; those positions.
fn probe_line(ks: &[i64], extra: i64) -> (RefCell<Simulation>, Vec<i64>) {
    let sim = line(1);
    let marks: Vec<i64> = ks.iter().map(|k| i64::from(REV) * k / 20 + extra * k).collect();
    with_drive(&sim, |d| {
        d.motors[0].switches_mut().probe1 = PositionInput::toggles(false, &marks).unwrap();
    });
    (sim, marks)
}

/// 60B8h = `function` (the probe's function), then enabled in csv at `v`.
async fn probe_in_csv(m: &mut Cyclic<'_>, sd: &OpSubDevice<'_>, function: u16, v: i32) {
    sd.sdo_write(0x60B8, 0, function).await.unwrap();
    m.enable_in(9).await;
    m.set_target_velocity(v);
}

#[test]
fn c124_c127_touch_probe_single_shot_falling_only_and_rearm() {
    // probe input 1 toggles at six positions: ↑p1 ↓p2 ↑p3 ↓p4 ↑p5 ↓p6
    let (sim, marks) = probe_line(&[2, 4, 6, 8, 14, 16], 111);
    with_cyclic(&sim, async |m, sd| {
        // example 2: enabled, first event, falling edge only (bit 5)
        probe_in_csv(m, sd, 0x0021, REV).await;
        pass_and_stop(m, 2000, marks[3] + i64::from(REV / 20), "past p4").await;
        let (status, rising, falling) = probe1(sd).await;
        println!(
            "example 2: 60B9h {status:#06x}, 60BAh {rising}, 60BBh {falling} (p2 {})",
            marks[1]
        );
        assert_eq!(
            status & 0x07,
            0x05,
            "enabled + falling stored only: {status:#06x}"
        );
        at_mark(falling, marks[1], "first falling edge p2");
        assert_eq!(rising, 0, "no rising edge stored");

        // example 3: both edges, first event; re-enabled (bit 0 0→1) between p4 and p5
        sd.sdo_write(0x60B8, 0, 0x0030u16).await.unwrap();
        m.run(3).await;
        let status: u16 = sd.sdo_read(0x60B9, 0).await.unwrap();
        assert_eq!(status & 0x07, 0, "disabled: status cleared");
        sd.sdo_write(0x60B8, 0, 0x0031u16).await.unwrap();
        m.run(3).await;
        let status: u16 = sd.sdo_read(0x60B9, 0).await.unwrap();
        assert_eq!(status & 0x07, 0x01, "re-armed: {status:#06x}");
        let kept: i32 = sd.sdo_read(0x60BB, 0).await.unwrap();
        assert_eq!(kept, falling, "values survive the disable");
        m.set_target_velocity(REV);
        pass_and_stop(m, 2000, marks[5] + i64::from(REV / 20), "past p6").await;
        let (status, rising, falling) = probe1(sd).await;
        println!(
            "example 3: 60B9h {status:#06x}, 60BAh {rising} (p5 {}), 60BBh {falling} (p6 {})",
            marks[4], marks[5]
        );
        assert_eq!(status & 0x07, 0x07, "both stored: {status:#06x}");
        at_mark(rising, marks[4], "next rising edge p5");
        at_mark(falling, marks[5], "next falling edge p6");
    });
}

#[test]
fn c125_c126_touch_probe_example_1_continuous_both_edges() {
    // probe input 1 toggles at four positions: ↑p1 ↓p2 ↑p3 ↓p4
    let (sim, marks) = probe_line(&[2, 4, 6, 8], 97);
    with_cyclic(&sim, async |m, sd| {
        // example 1: enabled (bit 0), continuous (bit 1), rising (bit 4) and falling (bit 5)
        probe_in_csv(m, sd, 0x0033, REV / 2).await;
        // past p2: the first pair is stored, both status bits on
        m.run_until(3000, |t| i64::from(t.position) > marks[1] + i64::from(REV / 40))
            .await
            .expect("past p2");
        let (status, rising, falling) = probe1(sd).await;
        println!("example 1 after p2: 60B9h {status:#06x}, 60BAh {rising}, 60BBh {falling}");
        assert_eq!(
            status & 0x07,
            0x07,
            "enabled, rising and falling stored: {status:#06x}"
        );
        at_mark(rising, marks[0], "p1");
        at_mark(falling, marks[1], "p2");
        // past p4: every edge overwrote its value (continuous, C-125)
        pass_and_stop(m, 3000, marks[3] + i64::from(REV / 40), "past p4").await;
        let (status, rising, falling) = probe1(sd).await;
        println!(
            "example 1 after p4: 60B9h {status:#06x}, 60BAh {rising} (p3 {}), 60BBh {falling} (p4 {})",
            marks[2], marks[3]
        );
        assert_eq!(status & 0x07, 0x07, "still both stored: {status:#06x}");
        at_mark(rising, marks[2], "overwritten by p3");
        at_mark(falling, marks[3], "overwritten by p4");
        // disabling clears the status bits, the values stay (C-126)
        sd.sdo_write(0x60B8, 0, 0x0032u16).await.unwrap();
        m.run(3).await;
        let status: u16 = sd.sdo_read(0x60B9, 0).await.unwrap();
        assert_eq!(status & 0x00FF, 0, "probe 1 status cleared: {status:#06x}");
        let kept_r: i32 = sd.sdo_read(0x60BA, 0).await.unwrap();
        let kept_f: i32 = sd.sdo_read(0x60BB, 0).await.unwrap();
        assert_eq!((kept_r, kept_f), (rising, falling), "60BAh/60BBh kept");
        // disabled: passing the edges again stores nothing
        m.set_target_velocity(-REV / 2);
        pass_and_stop(m, 3000, marks[0] - i64::from(REV / 40), "back below p1").await;
        let status: u16 = sd.sdo_read(0x60B9, 0).await.unwrap();
        let still: i32 = sd.sdo_read(0x60BA, 0).await.unwrap();
        assert_eq!(status & 0x07, 0, "nothing latched while disabled: {status:#06x}");
        assert_eq!(still, rising, "60BAh unchanged while disabled");
    });
}
