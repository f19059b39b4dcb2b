//! The motor data and the motor protection in the one declaration (issue 34):
//! group B "Motor" at `parameter_index(1, line)` = 2200h + line (axis B at
//! A200h + line) and the i²t settings U10/U11 of group U (4800h + line).
//! The CiA 402 motor objects 6073h max current, 6075h rated current, 6076h
//! rated torque and 6080h max motor speed are in [`super::cia402`]; together
//! they are all the motor data there is: the axis reads them when the
//! configuration generation moves (`axis/motor.rs`), never per cycle, and the
//! simulated current loop takes its gains from them (Kp = ω_c·L, Ki = ω_c·R).
//!
//! The seeds name only B26, B83 and B101 of group B: the lines here are
//! assumed (each note says so). The rated and the maximum current and speed
//! live once, in the CiA 402 objects: a B copy of them would be a second
//! declaration of one value (B83 "v-max motor" is 6080h here).
//!
//! Merged with the other manufacturer parameters into one sorted list
//! ([`super::MANUFACTURER_A`]).

use super::{Object, Value};
use crate::params::{
    B05, B10, B17, B300, B301, B40, B41, B42, B43, B44, B45, B46, B47, B48, B52, B53, B62, B64, B73, U10, U11,
};
use od::DataType::{U16, U32, U8};

use od::{Access, DataType, EntryInfo};

const RW: Access = Access::RW;
const fn e(sub: u8, name: &'static str, t: DataType) -> EntryInfo {
    EntryInfo::new(sub, name, t, RW)
}

/// The motor data of axis A (group B), sorted by index.
pub const PARAMS: [Object; 19] = [
    Object::var(
        B05,
        Value::Ram,
        entries![e(0, "Commutation offset", U32)
            .range(0, (1 << 20) - 1)
            .default_value(0)
            .unit("inc")
            .saved()],
    )
    .axis()
    .level(1)
    .note("B05 (line assumed): the encoder position (2^20 increments per revolution) at which the rotor's d axis points along phase a: the current loop's electrical angle is p·(position − B05); found by B41 \"calibrate motor\" (alignment), saved with the parameter set; default 0"),
    Object::var(
        B10,
        Value::Ram,
        entries![e(0, "Pole pair number", U8).range(1, 64).default_value(4).saved()],
    )
    .axis()
    .level(1)
    .note("B10 (line assumed): pole pairs p of the motor; electrical angle = p × mechanical; 0 is refused (0609 0032h: the current loop cannot commutate); default 4 (the simulated servo)"),
    Object::var(
        B17,
        Value::Ram,
        entries![e(0, "Torque constant", U32)
            .range(1, 100_000)
            .default_value(650)
            .unit("mNm/A")
            .saved()],
    )
    .axis()
    .level(1)
    .note("B17 (line assumed): kt = 1.5·p·ψ per A of the dq amplitude (the phase current's peak); the torque command becomes iq = T/kt; 6076h = kt × 6075h; default 0.65 N·m/A"),
    param_array!(B40, "Test phase", Record, Value::Ram, [
        EntryInfo::new(0, "Result", U8, Access::RO),
        EntryInfo::new(1, "Increments per electrical turn", od::DataType::I32, Access::RO).unit("inc"),
        EntryInfo::new(2, "Pole pairs seen", U8, Access::RO),
    ])
    .axis()
    .level(1)
    .note("B40 (line assumed): the action \"test phase\", started through A75 in Ready to switch on, run after the enable (brake released, the rotor turns one electrical revolution): each phase must carry current (else result 2), a field turned forward must make the encoder count up (else 7: phase order and encoder direction do not match) by 2^20/B10 per electrical turn (else 8); [0] the result (0 passed, 1 aborted), [1] the increments the encoder counted over the turn, [2] 2^20 divided by them"),
    param_array!(B41, "Calibrate motor", Record, Value::Ram, [
        EntryInfo::new(0, "Result", U8, Access::RO),
        EntryInfo::new(1, "Alignment spread", U32, Access::RO).unit("inc"),
    ])
    .axis()
    .level(1)
    .note("B41 (line assumed): the action \"calibrate motor\", started through A75 (E-140), progress in A69: the rotor (brake released, free to turn) aligned by a d current along phase a, approached from both sides; the mean of the two positions is the commutation offset, written to B05. [0] its result (0 written, 1 aborted: the enable went away, 2 the rotor did not come to rest, 5 the current loop reports no measurement), [1] the two alignments' difference (friction's share)"),
    param_array!(B42, "Optimize current controller", Record, Value::Ram, [
        EntryInfo::new(0, "Result", U8, Access::RO),
        EntryInfo::new(1, "Identified R", U32, Access::RO).unit("mΩ"),
        EntryInfo::new(2, "Identified Ld", U32, Access::RO).unit("µH"),
    ])
    .axis()
    .level(1)
    .note("B42 (line assumed): the action \"optimise current controller\" (and B49, at standstill: the same measurement with the brake applied), started through A75 (E-140), progress in A69: [0] its result (0 identified and written, 1 aborted: the enable went away, 2 no current: an open winding, 3 the current did not settle, 4 implausible figures, 5 the current loop measures no d axis), [1] the identified phase resistance and [2] d-axis inductance of the last run; identified, they are written to B53 and B52/B62 (the current gains follow by pole-zero cancellation); not saved themselves (B52/B53/B62 are)"),
    param_array!(B43, "Test winding", Record, Value::Ram, [
        EntryInfo::new(0, "Result", U8, Access::RO),
        EntryInfo::new(1, "Resistance U", U32, Access::RO).unit("mΩ"),
        EntryInfo::new(2, "Resistance V", U32, Access::RO).unit("mΩ"),
        EntryInfo::new(3, "Resistance W", U32, Access::RO).unit("mΩ"),
    ])
    .axis()
    .level(1)
    .note("B43 (line assumed): the action \"test winding\", started through A75 in Ready to switch on (no enable: the drive switches the power stage on itself, brake applied), progress in A69: the resistance measured along each phase's axis ((R_x + R_y‖R_z)/1.5, R when balanced) in [1]..[3]; [0] the result: 0 the three agree within 3 % of their mean, 6 unbalanced (A69: failed), 1 aborted (the state changed), 2 no current (an open phase), 3 not settled"),
    param_array!(B44, "Identify mechanics", Record, Value::Ram, [
        EntryInfo::new(0, "Result", U8, Access::RO),
        EntryInfo::new(1, "Largest excursion", U32, Access::RO).unit("inc"),
        EntryInfo::new(2, "Constant load torque", od::DataType::I32, Access::RO).unit("µNm"),
    ])
    .axis()
    .level(1)
    .note("B44 (line assumed; A75 selector 1111b, ours): the action \"identify mechanics\", started through A75 in Ready to switch on, run after the enable: a bounded test move (brake released; at most 12 revolutions forward of where the axis stands, back to it at the end) at four constant speeds in both directions between acceleration ramps identifies the total inertia (B45), the Coulomb (B46) and viscous (B47) friction, and the speed and position controllers' gains for the bandwidth B48 are written to C31, C32 and I20. Refused before it moves (A69 refused, [0] = 12) when the travel would pass a software limit 607Dh or a limit switch is active. [0] the result (0 identified and written, 1 aborted: the enable went away, 3 a speed did not settle, 4 implausible figures, 12 the travel would pass a limit, 13 the move left the stated travel), [1] the largest excursion from the start, [2] the constant load torque seen (gravity, not fed forward)"),
    Object::var(
        B45,
        Value::Ram,
        entries![e(0, "Total inertia", U32)
            .range(0, 10_000_000)
            .default_value(0)
            .unit("g·cm²")
            .saved()],
    )
    .axis()
    .level(1)
    .note("B45 (line assumed): the total inertia on the motor shaft (rotor + load), 10⁻⁷ kg·m²; B44 identifies it. Non-zero: the cascade's acceleration feedforward J·a uses it (in csp/ip with linear interpolation from the change of the set-points' speed), with the friction feedforward of B46/B47; 0 (default): not identified, the built-in 1e-4 kg·m² for the profile modes' acceleration feedforward, no friction feedforward"),
    Object::var(
        B46,
        Value::Ram,
        entries![e(0, "Coulomb friction", U32)
            .range(0, 10_000_000)
            .default_value(0)
            .unit("µNm")
            .saved()],
    )
    .axis()
    .level(1)
    .note("B46 (line assumed): Coulomb (sliding) friction torque; B44 identifies it; with B45 ≠ 0 fed forward as Fc·sign(v_ref), the sign smoothed linearly over ±0.02 rev/s"),
    Object::var(
        B47,
        Value::Ram,
        entries![e(0, "Viscous friction", U32)
            .range(0, 10_000_000)
            .default_value(0)
            .unit("nNm·s/rad")
            .saved()],
    )
    .axis()
    .level(1)
    .note("B47 (line assumed): viscous friction, torque per speed; B44 identifies it; with B45 ≠ 0 fed forward as B·v_ref"),
    Object::var(
        B48,
        Value::Ram,
        entries![e(0, "Speed loop bandwidth", U16)
            .range(1, 3_200)
            .default_value(60)
            .unit("Hz")
            .saved()],
    )
    .axis()
    .level(1)
    .note("B48 (line assumed): the bandwidth f_v the gains B44 writes are chosen for, ω_v = 2π·f_v: C31 Kp = J·ω_v, C32 Ti = 4/ω_v, I20 Kv = ω_v/4, each written for the 250 µs reference cycle of the gains (so that the scaling to A150 gives these values); default 60 Hz (30 Hz leaves the PROFINET demo's positioning moves at 730 inc, 60 Hz at 415; 80 Hz is not stable on the simulated servo)"),
    Object::var(
        B52,
        Value::Ram,
        entries![e(0, "Inductance Ld", U32)
            .range(1, 10_000_000)
            .default_value(12_000)
            .unit("µH")
            .saved()],
    )
    .axis()
    .level(1)
    .note("B52 (line assumed): d-axis inductance per phase (star equivalent); the d controller's Kp = ω_c·Ld; 0 refused (0609 0032h); default 12 mH"),
    Object::var(
        B53,
        Value::Ram,
        entries![e(0, "Winding resistance", U32)
            .range(1, 1_000_000)
            .default_value(3_600)
            .unit("mΩ")
            .saved()],
    )
    .axis()
    .level(1)
    .note("B53 (line assumed): phase resistance (star equivalent); the controllers' Ki = ω_c·R; 0 refused (0609 0032h); default 3.6 Ω"),
    Object::var(
        B62,
        Value::Ram,
        entries![e(0, "Inductance Lq", U32)
            .range(1, 10_000_000)
            .default_value(12_000)
            .unit("µH")
            .saved()],
    )
    .axis()
    .level(1)
    .note("B62 (line assumed): q-axis inductance per phase; the q controller's Kp = ω_c·Lq; default 12 mH"),
    Object::var(
        B64,
        Value::Ram,
        entries![e(0, "Current controller bandwidth", U16)
            .range(1, 3_200)
            .default_value(1_000)
            .unit("Hz")
            .saved()],
    )
    .axis()
    .level(1)
    .note("B64 (line assumed): ω_c/2π of both current controllers (pole-zero cancellation: first order with ω_c); at most a fifth of the 16 kHz PWM (0609 0031h above)"),
    Object::var(
        B73,
        Value::Ram,
        entries![e(0, "Thermal time constant", U32)
            .range(100, 36_000_000)
            .default_value(600_000)
            .unit("ms")
            .saved()],
    )
    .axis()
    .level(1)
    .note("B73 (line assumed): τ of the winding's first-order thermal model (motor i²t, U10): the rated current 6075h held forever gives 100 %; default 600 s"),
    param_array!(B300, "Test brake", Record, Value::Ram, [
        EntryInfo::new(0, "Result", U8, Access::RO),
        EntryInfo::new(1, "Largest movement", U32, Access::RO).unit("inc"),
        EntryInfo::new(2, "Test torque", U32, Access::RO).unit("mNm"),
    ])
    .axis()
    .level(1)
    .note("B300 (spec §14): the action \"test brake\", started through A75 in Ready to switch on, run after the enable: the brake stays applied while the drive commands the rated torque 6076h forward, then backward (a 0.1 s ramp and 0.5 s hold each, at 1 ms); the shaft must not move more than 1/360 rev from where it stood. [0] the result (0 held, 9 slipped: the torque dropped at once, 1 aborted: the enable went away), [1] the largest movement seen, [2] the test torque"),
    param_array!(B301, "Grind brake", Record, Value::Ram, [
        EntryInfo::new(0, "Result", U8, Access::RO),
        EntryInfo::new(1, "Grinding travel", U32, Access::RO).unit("inc"),
        EntryInfo::new(2, "Released travel", U32, Access::RO).unit("inc"),
        EntryInfo::new(3, "Grinding torque", U32, Access::RO).unit("mNm"),
    ])
    .axis()
    .level(1)
    .note("B301 (spec §14; the sequence is ours, the manual gives none): the action \"grind brake\", started through A75 in Ready to switch on, run after the enable: 4 rounds of 0.5 s grinding (the brake applied, the motor turning the shaft at 60 rpm against it with up to the peak torque 6076h × 6072h) and 0.25 s released (the brake released, the same speed with at most a quarter of 6076h), then 0.1 s stop on the brake; each phase must turn the shaft by a quarter of what 60 rpm gives. [0] the result (0 ground in, 10 stalled: the peak torque did not turn the shaft against the brake, 11 not released: the shaft did not turn with the brake commanded open, 1 aborted: the enable went away), [1] the smallest travel of a grind phase, [2] of a released phase, [3] the largest grinding torque (the brake's sliding torque)"),
];

/// The motor protection settings of axis A (group U, after the records of
/// group J in the table), sorted by index.
pub const PROTECTION: [Object; 2] = [
    Object::var(
        U10,
        Value::Ram,
        entries![e(0, "i2t level", U8).range(0, 3).default_value(2).saved()],
    )
    .axis()
    .level(1)
    .note("U10 (spec §14): what the motor's i²t model does at 100 %: 0 inactive, 1 message (statusword bit 7 and the current limited to 6075h), 2 warning (as 1, and event 45 after U11 at or above 100 %), 3 fault (event 45 at once); default 2, the manual's recommendation (its preset differs: this model has no motor temperature sensor)"),
    Object::var(
        U11,
        Value::Ram,
        entries![e(0, "i2t warning time", U16)
            .range(0, 60_000)
            .default_value(1000)
            .unit("ms")
            .saved()],
    )
    .axis()
    .level(1)
    .note("U11 (spec §14): with U10 = 2, how long the i²t model may stay at or above 100 % (the current held at 6075h) before event 45 \"Overtemp.motor i2t\" (4380h) faults the axis; default 1.00 s"),
];
