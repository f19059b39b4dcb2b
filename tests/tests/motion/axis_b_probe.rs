//! Axis B (C-134), moved by SDO independently of axis A, and the touch probe (C-121 … C-123)
//! latching the edges of input 1.

use super::*;

/// Axis B's CiA 402 objects (C-134).
const B: u16 = 0x800;

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
