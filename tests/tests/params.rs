//! The axis settings as a master sets them (issue 40): the cascade's gains
//! and the torque modes' speed limits by SDO through ethercrab, their
//! effect on the plant, their refusal out of range, and their place in the
//! saved parameter set.

use drive_ecat::params::{C31, C32, G472, G475, I04, I20, I25, I28, I29, I30, I423, I425, I43, I53, I87};
use drive_tests::axis::{with_drive, CW_ENABLED};
use drive_tests::{line, sdo_is, with_cyclic, with_sdo, PreOpSubDevice};
use ethercrab::error::CoeAbortCode::{ValueOutOfRange, ValueTooLarge};
use hil_sim::sim::Simulation;
use std::cell::RefCell;

const REV: f64 = (1u64 << 20) as f64;
const RAD_PER_INC: f64 = 2.0 * std::f64::consts::PI / REV;
const SAVE: u32 = u32::from_le_bytes(*b"save");

/// The SDO abort code of an ethercrab error.
fn abort_code(e: ethercrab::error::Error) -> ethercrab::error::CoeAbortCode {
    match e {
        ethercrab::error::Error::Mailbox(ethercrab::error::MailboxError::Aborted { code, .. }) => code,
        other => panic!("not an SDO abort: {other:?}"),
    }
}

/// Writes each `(index, value)` (sub-index 0) by SDO.
async fn write_all<T>(sd: &PreOpSubDevice<'_>, settings: &[(u16, T)])
where
    T: ethercrab::EtherCrabWireWrite + Copy,
{
    for &(index, v) in settings {
        sd.sdo_write(index, 0, v)
            .await
            .unwrap_or_else(|e| panic!("write {index:04X}h: {e}"));
    }
}

/// Each `(index, value)` (sub-index 0) reads back by SDO.
async fn read_back<T>(sd: &PreOpSubDevice<'_>, settings: &[(u16, T)])
where
    T: ethercrab::EtherCrabWireReadSized + PartialEq + std::fmt::Debug + Copy,
{
    for &(index, v) in settings {
        sdo_is(sd, index, 0, v, &format!("{index:04X}h read back")).await;
    }
}

/// csv at standstill with 60FFh = 0, C32 = 0 (a P velocity controller) and
/// C31 = `kp` (µN·m·s/rad) by SDO, then a step of the velocity offset 60B1h
/// to `step` inc/s (no acceleration feedforward: the offset is added to
/// the interpolated set-point); the rotor's velocity (the plant's, rad/s)
/// every 1 ms cycle after the step.
fn velocity_step(kp: u32, step: i32, cycles: usize) -> Vec<f64> {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        sd.sdo_write(C32, 0, 0u32).await.unwrap();
        sd.sdo_write(C31, 0, kp).await.unwrap();
        assert_eq!(sd.sdo_read::<u32>(C31, 0).await.unwrap(), kp);
        m.enable_in(9).await;
        m.set_controlword(CW_ENABLED);
        m.run(20).await;
        m.set_velocity_offset(step);
        let mut out = Vec::with_capacity(cycles);
        for _ in 0..cycles {
            m.cycle().await;
            let mut v = 0.0;
            with_drive(&sim, |d| v = d.motors[0].velocity_rad_s());
            out.push(v);
        }
        out
    })
}

/// A first-order response's time constant from samples 1 ms apart: the
/// time at which it passes 63.2 % of the way to its end value (the mean of
/// the last tenth), interpolated between samples, s.
fn time_constant(w: &[f64]) -> (f64, f64) {
    let tail = &w[w.len() * 9 / 10..];
    let end = tail.iter().sum::<f64>() / tail.len() as f64;
    let target = (1.0 - (-1.0f64).exp()) * end;
    let k = w.iter().position(|&v| v >= target).expect("passes 63 %");
    let (a, b) = (if k == 0 { 0.0 } else { w[k - 1] }, w[k]);
    let t = k as f64 + (target - a) / (b - a);
    (t * 1e-3, end)
}

/// C31 changed by SDO changes the velocity loop's step response as the
/// closed-form first-order loop says. With a P controller (C32 = 0) on the
/// plant J·dω/dt = Kp·(ω_r − ω) − T_c − b·ω (hil-sim's default servo:
/// J = 1e-4 kg·m², Coulomb friction T_c = 0.02 N·m, viscous b = 2e-5
/// N·m·s/rad) the rotor's speed rises as ω∞·(1 − e^(−t/τ)) with
/// τ = J / (Kp + b) and ω∞ = (Kp·ω_r − T_c) / (Kp + b). Kp is C31 scaled to
/// the control cycle A150 = 1 ms as documented (C31 holds the gain of
/// A150 ≤ 250 µs: × 250/1000). Two gains a factor 2 apart: each τ and ω∞
/// within 12 % / 4 % of the formula (the 1 ms sampling, the measured
/// velocity's filter and the one-cycle delay of the torque make the rest).
#[test]
fn issue40_c31_by_sdo_changes_the_velocity_step_response_as_the_first_order_loop() {
    const J: f64 = 1.0e-4;
    const TC: f64 = 0.02;
    const B: f64 = 2.0e-5;
    let step = (8.0 * REV) as i32; // 8 rev/s
    let w_r = f64::from(step) * RAD_PER_INC;
    let mut taus = Vec::new();
    for kp_set in [8_000u32, 16_000] {
        let kp = f64::from(kp_set) * 1e-6 * 0.25;
        let tau = J / (kp + B);
        let w_end = (kp * w_r - TC) / (kp + B);
        let w = velocity_step(kp_set, step, 400);
        let (tau_seen, end_seen) = time_constant(&w);
        println!(
            "C31 = {kp_set} µNm·s/rad (Kp {kp} at 1 ms): τ {:.1} ms (formula {:.1} ms), ω∞ {end_seen:.2} rad/s (formula {w_end:.2})",
            tau_seen * 1e3,
            tau * 1e3
        );
        assert!(
            (tau_seen - tau).abs() < 0.12 * tau,
            "τ {tau_seen} s, formula {tau} s"
        );
        assert!(
            (end_seen - w_end).abs() < 0.04 * w_end,
            "ω∞ {end_seen}, formula {w_end}"
        );
        taus.push(tau_seen);
    }
    assert!(
        taus[0] > 1.6 * taus[1],
        "twice the gain, about half the time constant: {taus:?}"
    );
}

fn power_cycle(sim: &RefCell<Simulation>) {
    sim.borrow_mut().drives_mut()[0].power_cycle();
}

/// The settings by SDO (E-018 with issue 40's parameters): out of range
/// refused with 0609 0031h / 0609 0032h and unchanged; written values stay
/// in RAM until 1010h:01 = "save"; after a power cycle the saved values are
/// read back (G472, G475, C31, C32, I20, axis B's G472 at ADD8h), the
/// unsaved ones are gone.
#[test]
fn e018_issue40_settings_saved_with_the_parameter_set_and_restored() {
    let words = [(G472, 250u16), (G475, 120), (I20, 800)];
    let dwords = [(C31, 45_000u32), (C32, 12_000)];
    let axis_b_g472 = [(G472 + drive_ecat::AXIS_B_MANUFACTURER, 330u16)];
    let sim = line(1);
    let axis_b = drive_tests::has_axis_b("e018_issue40_settings_saved");
    with_sdo(&sim, async |sd, _| {
        let e = sd.sdo_write(G472, 0, 1001u16).await.unwrap_err();
        assert_eq!(abort_code(e), ValueTooLarge, "G472 above 100 % (0609 0031h)");
        let e = sd.sdo_write(C31, 0, 10_000_001u32).await.unwrap_err();
        assert_eq!(abort_code(e), ValueTooLarge, "C31 above its range (0609 0031h)");
        assert_eq!(sd.sdo_read::<u16>(G472, 0).await.unwrap(), 0, "unchanged");
        assert_eq!(sd.sdo_read::<u32>(C31, 0).await.unwrap(), 60_000, "unchanged");
        write_all(sd, &words).await;
        write_all(sd, &dwords).await;
        if axis_b {
            write_all(sd, &axis_b_g472).await;
        }
        sd.sdo_write(0x1010, 1, SAVE).await.unwrap();
        // written after the save: RAM only
        sd.sdo_write(G475, 0, 999u16).await.unwrap();
    });
    power_cycle(&sim);
    with_sdo(&sim, async |sd, _| {
        // G475: the saved value, not 999
        read_back(sd, &words).await;
        read_back(sd, &dwords).await;
        if axis_b {
            read_back(sd, &axis_b_g472).await;
        }
    });
}

/// E-018 with the homing, interpolation and window settings of issue 40
/// (I28, I29, I30, I43, I53, I04, I25, I425, I423, I87): out of range
/// refused (0609 0031h, I425 = 2 with 0609 0030h) and unchanged; saved with
/// 1010h:01 and read back after a power cycle.
#[test]
fn e018_issue40_homing_and_interpolation_settings_saved_and_restored() {
    let bytes = [(I30, 2u8), (I43, 1), (I04, 2), (I25, 80), (I425, 4)];
    let words = [(I28, 400u16), (I29, 50), (I423, 20), (I87, 5)];
    let dwords = [(I53, 12_345u32)];
    let sim = line(1);
    with_sdo(&sim, async |sd, _| {
        let e = sd.sdo_write(I28, 0, 3001u16).await.unwrap_err();
        assert_eq!(abort_code(e), ValueTooLarge, "I28 above 300 % (0609 0031h)");
        let e = sd.sdo_write(I25, 0, 101u8).await.unwrap_err();
        assert_eq!(abort_code(e), ValueTooLarge, "I25 above 100 % (0609 0031h)");
        let e = sd.sdo_write(I425, 0, 2u8).await.unwrap_err();
        assert_eq!(abort_code(e), ValueOutOfRange, "I425 = 2 (0609 0030h)");
        assert_eq!(sd.sdo_read::<u16>(I28, 0).await.unwrap(), 1000, "unchanged");
        assert_eq!(sd.sdo_read::<u8>(I25, 0).await.unwrap(), 100, "unchanged");
        assert_eq!(sd.sdo_read::<u8>(I425, 0).await.unwrap(), 0, "unchanged");
        write_all(sd, &bytes).await;
        write_all(sd, &words).await;
        write_all(sd, &dwords).await;
        sd.sdo_write(0x1010, 1, SAVE).await.unwrap();
        // written after the save: RAM only
        sd.sdo_write(I29, 0, 999u16).await.unwrap();
    });
    power_cycle(&sim);
    with_sdo(&sim, async |sd, _| {
        // I29: the saved value, not 999
        read_back(sd, &bytes).await;
        read_back(sd, &words).await;
        read_back(sd, &dwords).await;
    });
}
