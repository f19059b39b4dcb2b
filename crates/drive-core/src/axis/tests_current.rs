//! The current seam ([`CurrentControl`]): 6077h and 6078h show the current
//! loop's measurement, not the demand. The loop below the axis is modelled by
//! its closed-loop design (pole-zero cancellation: a first-order lag of time
//! constant τ = 1/ω_c from iq_ref to iq), the rotor locked: after n control
//! cycles of a constant reference iq = iq_ref·(1 − e^(−n·dt/τ)).

use super::*;

const DT_NS: u64 = 1_000_000;
/// kt of the default axis: 1.3 N·m at 2 A.
const KT: f32 = 0.65;

/// A first-order current loop (τ, exact per control cycle), locked rotor.
struct LagLoop {
    tau_s: f64,
    iq: f64,
    iq_ref: f64,
    trip: Option<CurrentTrip>,
    /// The power stage's limit and i²t warning the loop reports.
    stage_limit_a: f32,
    stage_warning: bool,
}

impl CurrentControl for LagLoop {
    fn command(&mut self, c: &AxisCommand) {
        self.iq_ref = if c.power_stage {
            f64::from(c.torque_nm / KT)
        } else {
            0.0
        };
    }
    fn actual(&self) -> Option<CurrentActual> {
        Some(CurrentActual {
            trip: self.trip,
            stage_limit_a: self.stage_limit_a,
            stage_warning: self.stage_warning,
            ..CurrentActual::measured(KT * self.iq as f32, self.iq as f32)
        })
    }
}

impl LagLoop {
    /// One control cycle of the loop under the reference it holds.
    fn advance(&mut self) {
        let k = (-(DT_NS as f64) * 1e-9 / self.tau_s).exp();
        self.iq = self.iq_ref + (self.iq - self.iq_ref) * k;
    }
}

struct Rig {
    od: DriveObjects,
    axis: Axis,
    seam: LagLoop,
    /// Pass the measurement to the axis (else: a shell without one).
    measure: bool,
    now: Nanos,
}

impl Rig {
    /// Axis A enabled in cst (6060h = 10), 6071h = 0, 607Eh = `polarity`,
    /// the rotor locked (position 0).
    fn new(tau_s: f64, measure: bool, polarity: i64) -> Self {
        let mut r = Rig {
            od: DriveObjects::new(),
            axis: Axis::new(0),
            seam: LagLoop {
                tau_s,
                iq: 0.0,
                iq_ref: 0.0,
                trip: None,
                stage_limit_a: f32::INFINITY,
                stage_warning: false,
            },
            measure,
            now: Nanos::ZERO,
        };
        r.od.set(0x607E, 0, polarity).unwrap();
        // G472/G475: the torque modes' speed limit at 40 % of I10 (the
        // default 0 holds the axis still by cutting the torque)
        r.od.set(crate::params::G472, 0, 400).unwrap();
        r.od.set(crate::params::G475, 0, 400).unwrap();
        r.od.set(0x6060, 0, 10).unwrap();
        for cw in [0x06, 0x07, 0x0F] {
            r.od.set(0x6040, 0, cw).unwrap();
            for _ in 0..5 {
                r.cycle();
            }
        }
        assert_eq!(r.axis.state(), State::OperationEnabled);
        assert_eq!(r.axis.mode(), Mode::CyclicTorque);
        r
    }

    /// One control cycle: the measurement in, the axis, the command to the
    /// loop, the loop over the cycle.
    fn cycle(&mut self) -> AxisCommand {
        let mut io = AxisIo::ready(0);
        if self.measure {
            io.current = self.seam.actual();
        }
        let report = self.axis.cycle(&mut self.od, &io, self.now, true);
        self.seam.command(&report.command);
        self.seam.advance();
        self.now = self.now.saturating_add(Nanos::from_ns(DT_NS));
        report.command
    }

    fn get(&self, index: u16) -> i64 {
        self.od.get(index, 0).unwrap()
    }

    /// What 6077h (torque actual) and 6078h (current actual) show, ‰.
    fn shown(&self) -> (i64, i64) {
        (self.get(0x6077), self.get(0x6078))
    }
}

/// C-038, P-187: a 6071h step of 50 % in cst: 6077h follows the current
/// loop's first-order response (τ = 5 ms: 1 − e^(−n·dt/τ), one cycle behind
/// the command since the measurement enters the next cycle), not the step of
/// the demand; it settles at 500 ‰.
#[test]
fn c038_p187_cst_torque_actual_is_the_measured_current_not_the_demand() {
    let tau = 5.0e-3;
    let mut r = Rig::new(tau, true, 0);
    r.od.set(0x6071, 0, 500).unwrap();
    // cycle 1 commands the step; the loop has run 0 cycles under it when
    // the axis reads it, so 6077h shows 0; after cycle n it shows n−1 cycles
    for n in 1..=40u32 {
        let c = r.cycle();
        assert!((c.torque_nm - 0.65).abs() < 1e-4, "demand {}", c.torque_nm);
        let expect = 500.0 * (1.0 - (-(f64::from(n - 1)) * 1e-3 / tau).exp());
        let shown = r.get(0x6077) as f64;
        assert!(
            (shown - expect).abs() <= 1.0,
            "cycle {n}: 6077h {shown}, closed form {expect:.1}"
        );
    }
    assert_eq!(r.get(0x6077), 500, "settled after 8 τ");
}

/// P-186, C-038: 6078h is the measured iq in 0.1 % of the rated current
/// (2 A): 0.5 A measured show 250 ‰ while the demand is 500 ‰; 6077h is
/// kt·iq in 0.1 % of the rated torque (1.3 N·m): 250 ‰ as well.
#[test]
fn p186_current_actual_is_the_measured_iq_in_per_mille_of_rated_current() {
    let mut r = Rig::new(1.0, true, 0);
    r.od.set(0x6071, 0, 500).unwrap();
    r.cycle();
    // hold the loop at 0.5 A whatever the reference (a loop at its limit)
    r.seam.iq = 0.5;
    r.seam.tau_s = 1.0e9;
    r.cycle();
    assert_eq!(r.shown(), (250, 250));
}

/// C-038 with 607Eh bit 7 (negative polarity): the command is turned into
/// motor coordinates and the measurement back: +500 ‰ demanded, the motor
/// gets −0.65 N·m, and 6077h/6078h show +500 ‰ once settled.
#[test]
fn c038_polarity_turns_the_measurement_back_into_user_coordinates() {
    let mut r = Rig::new(1.0e-3, true, 0x80);
    r.od.set(0x6071, 0, 500).unwrap();
    let mut c = AxisCommand::OFF;
    for _ in 0..30 {
        c = r.cycle();
    }
    assert!((c.torque_nm + 0.65).abs() < 1e-4, "motor torque {}", c.torque_nm);
    assert!(r.seam.iq < -0.99, "iq {}", r.seam.iq);
    assert_eq!(r.shown(), (500, 500));
}

/// Without a measurement (the rigid torque-in model) 6077h and 6078h show
/// the demand in the cycle that commands it, as before the seam.
#[test]
fn c038_without_a_measurement_the_demand_is_shown() {
    let mut r = Rig::new(5.0e-3, false, 0);
    r.od.set(0x6071, 0, 500).unwrap();
    r.cycle();
    assert_eq!(r.shown(), (500, 500));
}

/// Statusword bit 7 (warning) and bit 11 (internal limit active).
const SW_WARNING: i64 = 1 << 7;
const SW_LIMIT: i64 = 1 << 11;

/// C-038 with 6073h (issue 34): max current lowered to 50 % of 6075h limits
/// a 100 % cst demand to 50 %: the loop's measured current (6078h) and 6077h
/// settle at 500 ‰, statusword bit 11 (internal limit) is set.
#[test]
fn c038_max_current_6073h_limits_cst_torque_with_bit_11() {
    let mut r = Rig::new(1.0e-3, true, 0);
    r.od.set(0x6073, 0, 500).unwrap();
    r.od.set(0x6071, 0, 1000).unwrap();
    for _ in 0..30 {
        r.cycle();
    }
    assert_eq!(r.shown(), (500, 500));
    assert_ne!(r.get(0x6041) & SW_LIMIT, 0, "bit 11");
    // raised again: the demand passes
    r.od.set(0x6073, 0, 3000).unwrap();
    for _ in 0..30 {
        r.cycle();
    }
    assert_eq!(r.get(0x6077), 1000);
    assert_eq!(r.get(0x6041) & SW_LIMIT, 0);
}

/// The rig of the motor i²t tests: the current loop's 0.2 ms lag, B73 =
/// 1000 ms (the winding's thermal time constant τ = 1 s), and the torque modes' speed limiter at I10 (at 40 % it allows
/// 1.9 N·m at standstill: below the 2.6 N·m asked for).
fn i2t_rig() -> Rig {
    let mut r = Rig::new(0.2e-3, true, 0);
    r.od.set(crate::params::B73, 0, 1000).unwrap();
    r.od.set(crate::params::G472, 0, 1000).unwrap();
    r.od.set(crate::params::G475, 0, 1000).unwrap();
    r
}

/// E-089 (event 45 → 4380h), the motor i²t of issue 34 against the closed
/// form of the first-order thermal model: 200 % of the rated current from
/// cold reaches 100 % at t = −τ·ln(1 − (I_r/I)²) = −τ·ln(3/4) = 287.7 ms
/// for τ = 1 s. Then the warning (bit 7), the current held at the rated
/// current (6078h 1000 ‰, bit 11), and after U11 = 200 ms the fault 4380h.
#[test]
fn e089_motor_i2t_warning_limit_then_fault_4380h_at_the_closed_form_time() {
    let mut r = i2t_rig();
    r.od.set(crate::params::U11, 0, 200).unwrap();
    // the parameters take effect; the model is cold (no current so far)
    r.cycle();
    r.od.set(0x6071, 0, 2000).unwrap();
    let t100_ms = -1000.0 * (1.0f64 - 0.25).ln();
    let mut warned = None;
    for n in 1..=400u32 {
        r.cycle();
        if warned.is_none() && r.get(0x6041) & SW_WARNING != 0 {
            warned = Some(n);
        }
    }
    let n = f64::from(warned.expect("i²t warning"));
    // the model steps every 4 ms: the warning comes at the first step at or
    // after 100 %; the measurement enters one cycle late (and the lag's
    // 0.2 ms): from −1 to +6 cycles
    assert!(
        (-1.0..=6.0).contains(&(n - t100_ms)),
        "warning after {n} ms, closed form {t100_ms:.1} ms"
    );
    assert_eq!(r.axis.state(), State::OperationEnabled);
    assert!(
        (r.get(0x6078) - 1000).abs() <= 2,
        "limited to 6075h: {}",
        r.get(0x6078)
    );
    assert_ne!(r.get(0x6041) & SW_LIMIT, 0, "bit 11");
    // U11 = 200 ms after the warning: the fault
    let mut fault_at = None;
    for k in 1..=300u32 {
        r.cycle();
        if r.axis.state() == State::Fault {
            fault_at = Some(k);
            break;
        }
    }
    let k = fault_at.expect("i²t fault");
    let since_warning = f64::from(k) + 400.0 - n;
    assert!(
        (since_warning - 200.0).abs() <= 5.0,
        "fault {since_warning} ms after the warning (4 ms model steps)"
    );
    assert_eq!(r.get(0x603F), 0x4380);
}

/// U10 = 0: the model runs (the closed form of the cold start) but neither
/// warns, limits nor faults.
#[test]
fn e089_motor_i2t_inactive_with_u10_0() {
    let mut r = i2t_rig();
    r.od.set(crate::params::U10, 0, 0).unwrap();
    r.od.set(0x6071, 0, 2000).unwrap();
    for _ in 0..1500 {
        r.cycle();
    }
    // x(t) = (I/I_r)²·(1 − e^(−t/τ)) = 4·(1 − e^(−1.5)) after 1.5 s (the
    // current steps one cycle late and rises with the 0.2 ms lag: 0.1 %)
    let closed = 4.0 * (1.0 - (-1.5f64).exp());
    let x = f64::from(r.axis.motor_i2t());
    assert!((x / closed - 1.0).abs() < 0.005, "x {x}, closed form {closed:.4}");
    assert_eq!(r.axis.state(), State::OperationEnabled);
    assert_eq!(r.get(0x6078), 2000);
    assert_eq!(r.get(0x6041) & SW_WARNING, 0);
}

/// E-089: an over-current trip of the current loop faults the axis with
/// event 33 "Overcurrent": 603Fh = 2310h, error register bit 1 (current);
/// the power stage is off in the same cycle.
#[test]
fn e089_current_loop_over_current_trip_faults_2310h() {
    let mut r = Rig::new(1.0e-3, true, 0);
    r.od.set(0x6071, 0, 500).unwrap();
    for _ in 0..5 {
        r.cycle();
    }
    r.seam.trip = Some(CurrentTrip::OverCurrent);
    let mut off = false;
    for _ in 0..3 {
        off |= !r.cycle().power_stage;
    }
    assert!(off, "power stage off");
    assert_eq!(r.axis.state(), State::Fault);
    assert_eq!(r.get(0x603F), 0x2310);
    assert_ne!(r.axis.error_register() & 0x02, 0, "current bit");
}

/// Issue 34: 6076h = kt (B17) × 6075h; the motor data refuse zero with
/// 0609 0032h (value too low) and change nothing.
#[test]
fn rated_torque_6076h_is_kt_times_6075h_and_zero_motor_data_is_refused() {
    let mut r = Rig::new(1.0e-3, true, 0);
    assert_eq!(r.get(0x6076), 1300);
    r.od.set(crate::params::B17, 0, 800).unwrap();
    r.od.set(0x6075, 0, 3000).unwrap();
    r.cycle();
    assert_eq!(r.get(0x6076), 2400);
    for (index, v) in [
        (0x6075, 0),
        (crate::params::B10, 0),
        (crate::params::B53, 0),
        (crate::params::B52, 0),
    ] {
        let before = r.get(index);
        let width = if index == crate::params::B10 { 1 } else { 4 };
        let data = (v as u32).to_le_bytes();
        let e = od::Dictionary::write(&mut r.od, index, 0, &data[..width], od::CommState::PreOp).unwrap_err();
        assert_eq!(e.0, 0x0609_0032, "{index:04X}h");
        assert_eq!(r.get(index), before);
    }
}

/// The i²t model alone at the default τ = 600 s in 1 ms cycles (α ≈ 7·10⁻⁶
/// per 4 ms step, below an f32's resolution at 1): 100 s at twice the
/// rated current give the closed form x = 4·(1 − e^(−100/600)) = 0.6141
/// to 10⁻⁵, and 4·(1 − e^(−2000/600)) = 3.857 after 2000 s.
#[test]
fn motor_i2t_model_meets_the_closed_form_at_a_long_time_constant() {
    let mut m = super::motor::MotorI2t::default();
    let data = MotorData {
        i2t_level: 0,
        ..MotorData::default()
    };
    m.configure(&data, 1_000_000);
    let mut now = Nanos::ZERO;
    for (until_s, closed) in [
        (100u64, 4.0 * (1.0 - (-100.0f64 / 600.0).exp())),
        (2000, 4.0 * (1.0 - (-2000.0f64 / 600.0).exp())),
    ] {
        while now < Nanos::from_ms(until_s * 1000) {
            now = now.saturating_add(Nanos::from_ms(1));
            m.step(4.0, now);
        }
        let x = f64::from(m.level());
        assert!(
            (x - closed).abs() < 1e-5 * closed.max(1.0),
            "after {until_s} s: x {x}, closed form {closed}"
        );
    }
}

/// The current limit is the lowest of 6073h, 2415h, the motor's i²t and the
/// power stage's (issue 34): a 140 % cst demand with 6073h = 300 % goes
/// through until the loop reports its power stage's limit of 2.4 A (1200 ‰ of
/// the 2 A rated current): then 6077h/6078h settle at 1200 ‰ with bit 11;
/// its i²t warning sets bit 7; its rated current 1 A while its i²t limits
/// (500 ‰); 6073h lowered to 40 % is the lowest again (400 ‰); the stage's
/// limit gone, 6073h raised: the demand passes, bits 7 and 11 clear.
#[test]
fn c038_the_current_limit_is_the_lowest_of_6073h_and_the_power_stages() {
    let mut r = Rig::new(1.0e-3, true, 0);
    r.od.set(0x6071, 0, 1400).unwrap();
    let settle = |r: &mut Rig| {
        for _ in 0..30 {
            r.cycle();
        }
        (
            r.get(0x6077),
            r.get(0x6078),
            r.get(0x6041) & (SW_LIMIT | SW_WARNING),
        )
    };
    assert_eq!(settle(&mut r), (1400, 1400, 0));
    r.seam.stage_limit_a = 2.4;
    assert_eq!(settle(&mut r), (1200, 1200, SW_LIMIT), "the stage's maximum");
    r.seam.stage_warning = true;
    assert_eq!(
        settle(&mut r),
        (1200, 1200, SW_LIMIT | SW_WARNING),
        "its i²t warning"
    );
    r.seam.stage_limit_a = 1.0;
    assert_eq!(settle(&mut r), (500, 500, SW_LIMIT | SW_WARNING), "its i²t limit");
    r.od.set(0x6073, 0, 400).unwrap();
    assert_eq!(
        settle(&mut r),
        (400, 400, SW_LIMIT | SW_WARNING),
        "6073h the lowest"
    );
    r.seam.stage_limit_a = f32::INFINITY;
    r.seam.stage_warning = false;
    r.od.set(0x6073, 0, 3000).unwrap();
    assert_eq!(settle(&mut r), (1400, 1400, 0));
}
