//! Event 52 "Communication" end to end (spec §13.4, §8.3.1): the drive's
//! reaction per A540 (605Eh) to a PDO timeout in Op (cause 6, E-128/E-129),
//! the fieldbus identification check (cause 15, E-130), one EMCY per event
//! and the fault reset afterwards.

use drive_tests::al::{ACK, ERR, OP, SAFEOP};
use drive_tests::step::op_via_safe_op;
use drive_tests::{al_status, init, line, request, sw, with_master, with_preop, CoeClient, Cyclic, REV};
use esc::AlStatusCode;
use hil_sim::sim::Simulation;
use std::cell::RefCell;

const A258: u16 = drive_ecat::parameter_index(0, 258);
const E43: u16 = drive_ecat::parameter_index(4, 43);
const E59: u16 = drive_ecat::parameter_index(4, 59);
const E82: u16 = drive_ecat::parameter_index(4, 82);

/// One sample per millisecond while the master is silent.
#[derive(Debug, Clone, Copy)]
struct Sample {
    ms: u64,
    state: u16,
    torque_nm: f64,
    brake: bool,
    velocity_inc_s: f64,
}

fn get(sim: &RefCell<Simulation>, index: u16, sub: u8) -> i64 {
    sim.borrow().drives()[0].drive.objects().get(index, sub).unwrap()
}

/// The 7500h EMCYs the master receives (while it does a few SDO uploads).
async fn event52_emcys<S>(sd: &ethercrab::SubDeviceRef<'_, S>) -> Vec<Vec<u8>>
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    let mut c = CoeClient::new();
    for _ in 0..4 {
        c.upload(sd, 0x1000, 0).await.unwrap();
    }
    c.emergencies
        .iter()
        .filter(|e| u16::from_le_bytes([e[0], e[1]]) == 0x7500)
        .cloned()
        .collect()
}

/// Drives axis A in csv at 5 rev/s, then stops the process data for 400 ms
/// (A258 = 5 ms, shorter than the 10 ms the interpolator may extrapolate
/// before its own fault, event 78) and samples the axis every millisecond; `a540` is written to
/// 605Eh first. Then checks the EMCY, 603Fh/E82/E43/1001h, resets the fault by
/// SDO in Safe-Op and brings the drive back to Op, where it enables again.
fn pdo_timeout_reaction(a540: i16) -> Vec<Sample> {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        sd.sdo_write(A258, 0, 5u16).await.unwrap();
        sd.sdo_write(0x605E, 0, a540).await.unwrap();
        // 6085h = 100 rev/s²: a quick stop from 5 rev/s takes 50 ms
        sd.sdo_write(0x6085, 0, 100 * REV as u32).await.unwrap();
        // with A258 on, S→O needs steady process data (E-033)
        let group = op_via_safe_op(md, group, &sim).await;
        let sd = group.subdevice(md, 0).unwrap();
        let mut m = Cyclic::new(md, &group, &sim, 0);
        m.csv_reach(5 * REV).await;
        assert_eq!(get(&sim, 0x603F, 0), 0);

        // the master stops sending process data
        let t0 = sim.borrow().now().as_ns();
        let mut samples = Vec::new();
        for ms in 1..=400u64 {
            let mut s = sim.borrow_mut();
            s.advance_to(nanos::Nanos::from_ns(t0 + ms * 1_000_000));
            let d = &s.drives()[0];
            let out = d.motor_outputs(0).unwrap();
            samples.push(Sample {
                ms,
                state: d.drive.objects().get(0x6041, 0).unwrap() as u16 & 0x6F,
                torque_nm: out.torque_applied_nm,
                brake: out.brake_applied,
                velocity_inc_s: out.velocity_inc_per_s,
            });
        }
        assert_eq!(
            al_status(&sd).await,
            (SAFEOP | ERR, AlStatusCode::SM_WATCHDOG.0),
            "PDO timeout"
        );
        // the axis ends in Fault, cause visible; one EMCY for the event
        assert_eq!(samples.last().unwrap().state, sw::FAULT);
        assert_eq!(get(&sim, 0x603F, 0), 0x7500, "603Fh");
        assert_eq!((get(&sim, E82, 0), get(&sim, E43, 0)), (52, 6), "E82/E43");
        assert_ne!(get(&sim, 0x1001, 0) & 0x10, 0, "1001h communication bit");
        let emcys = event52_emcys(&sd).await;
        assert_eq!(emcys.len(), 1, "exactly one EMCY 7500h: {emcys:02x?}");
        assert_eq!(&emcys[0][2..5], &[0x10, 52, 6]);

        // fault reset by SDO (the RxPDO is not evaluated below Op): T15
        let mut c = CoeClient::new();
        c.download(&sd, 0x6040, 0, &0u16.to_le_bytes()).await.unwrap();
        c.download(&sd, 0x6040, 0, &0x80u16.to_le_bytes()).await.unwrap();
        {
            let mut s = sim.borrow_mut();
            let t = s.now().as_ns() + 5_000_000;
            s.advance_to(nanos::Nanos::from_ns(t));
        }
        assert_eq!(get(&sim, 0x6041, 0) as u16 & 0x6F, sw::SOD, "fault reset");
        assert_eq!(get(&sim, 0x603F, 0), 0);
        c.upload(&sd, 0x1000, 0).await.unwrap();
        assert!(
            c.emergencies
                .iter()
                .any(|e| e[0..2] == [0, 0] && e[3] == 30 && e[7] == 0),
            "fault cleared EMCY for axis A: {:02x?}",
            c.emergencies
        );
        // the master acknowledges and goes back to Op: the drive enables again
        request(&sd, OP | ACK).await;
        m.set_controlword(0);
        m.set_target_velocity(0);
        m.run(10).await;
        assert_eq!(al_status(&sd).await, (OP, 0));
        m.enable().await;
        samples
    })
}

/// E-129: A540 = 0 "disable drive, motor coasting": at the PDO timeout the
/// power unit is switched off at once and the brake engages (E-128: the
/// event comes from the PDO timeout in Op).
#[test]
fn e129_e128_event52_with_a540_0_disables_the_power_unit_and_brakes() {
    let samples = pdo_timeout_reaction(0);
    let first = samples
        .iter()
        .position(|s| s.state != sw::OE)
        .expect("the axis reacted");
    let t = samples[first].ms;
    println!(
        "A540 = 0: reaction after {t} ms: {:?}",
        &samples[first..first + 4]
    );
    assert!((5..=8).contains(&t), "reaction at the 5 ms timeout: {t} ms");
    // power unit off and brake applied within two cycles (one cycle of actuation delay)
    for s in &samples[first + 2..] {
        assert_eq!(s.torque_nm, 0.0, "{s:?}");
        assert!(s.brake, "{s:?}");
        assert_eq!(s.state, sw::FAULT, "{s:?}");
    }
}

/// E-129: A540 = 2 "slow down on quick-stop ramp": a quick stop with the
/// brake released (Fault reaction active, torque applied), then the power
/// unit off, the brake engaged and Fault.
#[test]
fn e129_event52_with_a540_2_quick_stops_then_disables() {
    let samples = pdo_timeout_reaction(2);
    let first = samples.iter().position(|s| s.state != sw::OE).unwrap();
    let fra: Vec<_> = samples.iter().filter(|s| s.state == sw::FRA).collect();
    let fault = samples.iter().position(|s| s.state == sw::FAULT).unwrap();
    println!(
        "A540 = 2: reaction at {} ms, {} ms in Fault reaction active, Fault at {} ms",
        samples[first].ms,
        fra.len(),
        samples[fault].ms
    );
    assert!((5..=8).contains(&samples[first].ms));
    // 5 rev/s at 100 rev/s²: about 50 ms on the ramp (plus the settle time)
    assert!(fra.len() >= 40, "quick stop on the ramp: {} ms", fra.len());
    let ramp = &samples[first + 2..first + 40];
    assert!(
        ramp.iter().all(|s| !s.brake),
        "brake released during the quick stop"
    );
    assert!(ramp.iter().any(|s| s.torque_nm.abs() > 0.01), "braking torque");
    // decelerating along the ramp, not coasting: -100 rev/s² ± 30 %
    let (a, b) = (samples[first + 5], samples[first + 25]);
    let decel = (a.velocity_inc_s - b.velocity_inc_s) / ((b.ms - a.ms) as f64 * 1e-3) / REV as f64;
    assert!((70.0..130.0).contains(&decel), "deceleration {decel} rev/s²");
    for s in &samples[fault + 2..] {
        assert_eq!(s.state, sw::FAULT);
        assert!(s.brake && s.torque_nm == 0.0, "{s:?}");
    }
}

/// E-130: a projected fieldbus identification (E59[2]) other than the
/// firmware's raises event 52 cause 15: both axes in Fault (603Fh 7500h),
/// one EMCY 7500h / 10h / 52 / 15; once the projection matches again a
/// fault reset clears it.
#[test]
fn e130_projected_fieldbus_mismatch_raises_event52_cause_15() {
    let sim = line(1);
    sim.borrow_mut().drives_mut()[0]
        .drive
        .set_projected_fieldbus(drive_ecat::runtime::FIELDBUS_ID + 7);
    with_preop(&sim, async |sd| {
        let emcys = event52_emcys(&sd).await;
        // the axes' fault reaction (quick stop at standstill, settle time)
        {
            let mut s = sim.borrow_mut();
            let t = s.now().as_ns() + 50_000_000;
            s.advance_to(nanos::Nanos::from_ns(t));
        }
        let e59: u16 = sd.sdo_read(E59, 3).await.unwrap();
        assert_eq!(
            e59,
            drive_ecat::runtime::FIELDBUS_ID + 7,
            "E59[2] shows the projection"
        );
        assert_eq!(emcys.len(), 1, "{emcys:02x?}");
        assert_eq!(&emcys[0][2..5], &[0x10, 52, 15]);
        {
            let s = sim.borrow();
            let d = &s.drives()[0].drive;
            // every axis the device has (axis B stays idle on the single-axis device)
            for axis in d.axes().iter().take(drive_tests::variant().axes()) {
                let sw_index = axis.cia402_index(0x6041);
                let state = d.objects().get(sw_index, 0).unwrap() as u16 & 0x6F;
                assert_eq!(state, sw::FAULT, "axis {}", axis.index());
                assert_eq!(axis.error_code(), 0x7500);
            }
        }
        assert_eq!(get(&sim, E43, 0), 15);
        // still mismatching: no new event (raised once)
        {
            let mut s = sim.borrow_mut();
            let t = s.now().as_ns() + 20_000_000;
            s.advance_to(nanos::Nanos::from_ns(t));
        }
        assert!(event52_emcys(&sd).await.is_empty(), "raised once");
        // the projection fixed: a fault reset works
        sim.borrow_mut().drives_mut()[0]
            .drive
            .set_projected_fieldbus(drive_ecat::runtime::FIELDBUS_ID);
        let mut c = CoeClient::new();
        c.download(&sd, 0x6040, 0, &0x80u16.to_le_bytes()).await.unwrap();
        let mut s = sim.borrow_mut();
        let t = s.now().as_ns() + 5_000_000;
        s.advance_to(nanos::Nanos::from_ns(t));
        assert_eq!(
            s.drives()[0].drive.objects().get(0x6041, 0).unwrap() as u16 & 0x6F,
            sw::SOD
        );
    });
}
