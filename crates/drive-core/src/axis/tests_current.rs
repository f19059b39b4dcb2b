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
            torque_nm: KT * self.iq as f32,
            current_a: self.iq as f32,
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
    assert_eq!(r.get(0x6078), 250);
    assert_eq!(r.get(0x6077), 250);
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
    assert_eq!(r.get(0x6077), 500);
    assert_eq!(r.get(0x6078), 500);
}

/// Without a measurement (the rigid torque-in model) 6077h and 6078h show
/// the demand in the cycle that commands it, as before the seam.
#[test]
fn c038_without_a_measurement_the_demand_is_shown() {
    let mut r = Rig::new(5.0e-3, false, 0);
    r.od.set(0x6071, 0, 500).unwrap();
    r.cycle();
    assert_eq!(r.get(0x6077), 500);
    assert_eq!(r.get(0x6078), 500);
}
