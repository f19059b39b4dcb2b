//! The axis' control settings in the one declaration (issue 40): the
//! manufacturer parameters of the motion functions and the cascade that a
//! master sets (groups A, C, F, G and I at `parameter_index(group, line)`, axis B
//! at +8000h). The axis reads them when the configuration generation moves
//! (`axis/settings.rs`), never per cycle. The motor data (group B) and the
//! motor protection (U10/U11) are in [`super::motor`].
//!
//! Merged with [`super::manufacturer::PARAMS`] into one sorted list
//! ([`super::MANUFACTURER_A`]).

use super::shorthand::{a, c, e, f, g, i_};
use super::{Object, Value};
use od::Access;
use od::DataType::{U16, U32, U8};

const RW: Access = Access::RW;
const RW_PREOP: Access = Access::RW_PREOP;

/// One revolution, increments (the native user unit).
const REV_INC: i64 = 1 << 20;

/// The control settings of axis A, sorted by index.
pub const PARAMS: [Object; 29] = [
    Object::var(
        a(44),
        Value::Ram,
        entries![e(0, "Quick stop", U8, RW).range(0, 1).saved()],
    )
    .axis()
    .level(1)
    .note("A44: 1 = active: losing the additional enable A60 in Operation enabled gives a quick stop (transition 11) instead of switching the power stage off (transition 9); default 0; effective at once"),
    Object::var(
        c(31),
        Value::Ram,
        entries![e(0, "Speed controller Kp", U32, RW)
            .range(0, 10_000_000)
            .default_value(60_000)
            .unit("µNm·s/rad")
            .saved()],
    )
    .axis()
    .level(1)
    .note("C31 (line assumed; the seeds name no cascade parameter): proportional gain of the velocity controller, torque per speed error; default 0.06 N·m per rad/s (about 100 Hz bandwidth on the simulated 1e-4 kg·m² servo); effective at once; the gains are for A150 ≤ 250 µs and scaled down for longer cycles"),
    Object::var(
        c(32),
        Value::Ram,
        entries![e(0, "Speed controller Ti", U32, RW)
            .range(0, 10_000_000)
            .default_value(8_000)
            .unit("µs")
            .saved()],
    )
    .axis()
    .level(1)
    .note("C32 (line assumed): integral time of the velocity controller; 0 = no integral part; effective at once"),
    Object::var(
        c(40),
        Value::Ram,
        entries![e(0, "Velocity window", U32, RW)
            .default_value(REV_INC / 10)
            .unit("inc/s")
            .saved()],
    )
    .axis()
    .level(1)
    .note("C40 (C-061 area): velocity window in user units/s (decimals A310): standstill I199 below it, the pv velocity-reached window; default 0.1 rev/s; effective at once"),
    Object::var(
        f(0),
        Value::Ram,
        entries![e(0, "Brake", U8, RW)
            .range(0, 1)
            .default_value(1)
            .saved()],
    )
    .axis()
    .level(1)
    .note("F00 (spec cia402.md §14, C-020…C-022): 1 = active: the drive releases and applies the holding brake by the device state (released in Operation enabled on the first motion command, applied in the de-energised states, per fault reaction); 0 = inactive: the brake output stays off, the brake stays applied in every state and F06 has no effect; default 1 (ours: the manual gives none and every simulated motor carries a brake, docs/conformance.md); effective at once"),
    Object::var(
        f(6),
        Value::Ram,
        entries![e(0, "Release override", U8, RW).range(0, 1).saved()],
    )
    .axis()
    .level(1)
    .note("F06 (C-020, E-129): 1 = active: the brake is released in every state, also in Switch on disabled, Ready to switch on, Switched on, Fault and after a fault reaction (to move the axis by hand); only with brake control F00 = 1; default 0; effective at once"),
    Object::var(
        g(472),
        Value::Ram,
        entries![e(0, "Positive velocity limit torque mode", U16, RW)
            .range(0, 1000)
            .unit("0.1 %")
            .saved()],
    )
    .axis()
    .level(1)
    .note("G472 (C-039); cst and pt: the speed up to which the torque set-point drives the axis in the positive direction, in 0.1 % of the maximum speed I10; default 0 %: the axis does not move until it is raised; effective at once; not mappable (a configuration value)"),
    Object::var(
        g(475),
        Value::Ram,
        entries![e(0, "Negative velocity limit torque mode", U16, RW)
            .range(0, 1000)
            .unit("0.1 %")
            .saved()],
    )
    .axis()
    .level(1)
    .note("G475 (C-039); as G472 in the negative direction (magnitude)"),
    Object::var(
        i_(0),
        Value::Ram,
        entries![e(0, "Position range", U8, RW_PREOP).range(0, 1).saved()],
    )
    .axis()
    .level(1)
    .note("I00 (C-099, C-111): 0 limited (software limits act), 1 endless (positions wrap at 607Bh:02); default 0; writable in Pre-Op only (0800 0022h in Safe-Op and Op: the coordinate system must not change under a running axis)"),
    Object::var(
        i_(4),
        Value::Ram,
        entries![e(0, "Permitted direction", U8, RW).range(0, 2).saved()],
    )
    .axis()
    .level(1)
    .note("I04 (C-105, C-107): endless axes only: 0 both directions (default), 1 positive only, 2 negative only; a move the other way is refused and shown in E80 = 15; effective at once"),
    Object::var(
        i_(10),
        Value::Ram,
        entries![e(0, "Maximal speed", U32, RW)
            .default_value(50 * REV_INC)
            .unit("inc/s")
            .saved()],
    )
    .axis()
    .level(1)
    .note("I10: the highest speed of the axis in user units/s (decimals A310): the cascade's speed command is limited to it and G472/G475 are per mille of it; default 50 rev/s; effective at once; the cascade's speed limit is the lower of I10 and the motor's 6080h (the manual's B83)"),
    Object::var(
        i_(12),
        Value::Ram,
        entries![e(0, "Jog velocity", U32, RW)
            .default_value(REV_INC)
            .unit("inc/s")
            .saved()],
    )
    .axis()
    .level(1)
    .note("I12 (C-089): jog speed in user units/s (6091h/6092h, decimals A310 as 6081h); default 1 rev/s; effective at the next jog command"),
    Object::var(
        i_(13),
        Value::Ram,
        entries![e(0, "Jog acceleration", U32, RW)
            .default_value(10 * REV_INC)
            .unit("inc/s²")
            .saved()],
    )
    .axis()
    .level(1)
    .note("I13: jog acceleration in user units/s² (decimals A311); default 10 rev/s²"),
    Object::var(
        i_(18),
        Value::Ram,
        entries![e(0, "Jog jerk", U32, RW).unit("inc/s³").saved()],
    )
    .axis()
    .level(1)
    .note("I18: jog jerk in user units/s³ (decimals A311); 0 = no jerk limit (default)"),
    Object::var(
        i_(20),
        Value::Ram,
        entries![e(0, "Position controller Kv", U16, RW)
            .range(0, 10_000)
            .default_value(1_000)
            .unit("0.1 /s")
            .saved()],
    )
    .axis()
    .level(1)
    .note("I20 (line assumed): gain of the position controller, velocity command per following error; default 100 /s; effective at once"),
    Object::var(
        i_(25),
        Value::Ram,
        entries![e(0, "Speed feedforward", U8, RW)
            .range(0, 100)
            .default_value(100)
            .unit("%")
            .saved()],
    )
    .axis()
    .level(1)
    .note("I25 (C-117 area, ip/csp): weight of the speed feedforward the interpolator derives or takes (I425), %; 0 = none; default 100 %; effective at once (the interpolator restarts from the present set-point)"),
    Object::var(
        i_(26),
        Value::Ram,
        entries![e(0, "Jog control type", U8, RW)
            .range(0, 1)
            .default_value(1)
            .saved()],
    )
    .axis()
    .level(1)
    .note("I26 (C-091, C-092): 0 velocity control (past a software limit a quick stop), 1 position control (stops before it, default)"),
    Object::var(
        i_(28),
        Value::Ram,
        entries![e(0, "Torque/force limit homing", U16, RW)
            .range(0, 3000)
            .default_value(1000)
            .unit("0.1 %")
            .saved()],
    )
    .axis()
    .level(1)
    .note("I28 (C-083 torque methods): torque limit while referencing, 0.1 % of the rated torque 6076h (6072h caps it), also the threshold the torque methods look for; default 100 %; effective at the next homing start"),
    Object::var(
        i_(29),
        Value::Ram,
        entries![e(0, "Time torque/force limit homing", U16, RW)
            .default_value(100)
            .unit("ms")
            .saved()],
    )
    .axis()
    .level(1)
    .note("I29: how long the torque must stay at I28 continuously before a torque method takes the reference; default 100 ms"),
    Object::var(
        i_(30),
        Value::Ram,
        entries![e(0, "Reference switch type", U8, RW).range(0, 2).saved()],
    )
    .axis()
    .level(1)
    .note("I30 (C-086): 0 reference switch (I103), 2 the limit switches act as reference switch (methods 17-20 on ±LS without a limit-switch fault); 1 is the manual's 'other' and is taken as 0 (docs/conformance.md); effective at the next homing start"),
    Object::var(
        i_(43),
        Value::Ram,
        entries![e(0, "Move to reference position", U8, RW).range(0, 1).saved()],
    )
    .axis()
    .level(1)
    .note("I43: 1 = after referencing the axis positions on the reference position 607Ch (A569); default 0: it stops with 609Ah"),
    Object::var(
        i_(44),
        Value::Ram,
        entries![e(0, "Referencing jerk", U32, RW).unit("inc/s³").saved()],
    )
    .axis()
    .level(1)
    .note("I44: jerk of the homing moves in user units/s³ (decimals A311); 0 = no jerk limit (default); effective at the next homing start"),
    Object::var(
        i_(45),
        Value::Ram,
        entries![e(0, "Jog deceleration", U32, RW)
            .default_value(10 * REV_INC)
            .unit("inc/s²")
            .saved()],
    )
    .axis()
    .level(1)
    .note("I45: jog deceleration in user units/s² (decimals A311); default 10 rev/s²"),
    Object::var(
        i_(53),
        Value::Ram,
        entries![e(0, "Index search offset", U32, RW).unit("inc").saved()],
    )
    .axis()
    .level(1)
    .note("I53: after the switch edge the zero-pulse search starts this far on, in user position units (6091h/6092h); default 0"),
    Object::var(
        i_(87),
        Value::Ram,
        entries![e(0, "Actual position in window time", U16, RW)
            .unit("ms")
            .saved()],
    )
    .axis()
    .level(1)
    .note("I87 (C-048): how long the actual position must stay in the target window I22 before target reached (statusword bit 10) and in position; default 0 ms; effective at once"),
    Object::var(
        i_(423),
        Value::Ram,
        entries![e(0, "Max extrapolation period", U16, RW)
            .range(0, 10_000)
            .default_value(10)
            .unit("ms")
            .saved()],
    )
    .axis()
    .level(1)
    .note("I423 (C-117): the longest the cyclic modes extrapolate a missing set value before event 78 cause 3; default 10 ms; effective at once"),
    Object::var(
        i_(425),
        Value::Ram,
        entries![e(0, "Speed feed forward interpolation", U8, RW).range(0, 5).saved()],
    )
    .axis()
    .level(1)
    .note("I425: 0 linear, 4 quadratic, 5 cubic (internal: the drive derives the speed feedforward), 1 and 3 external (60B1h); 2 is refused (0609 0030h); default 0; effective at once"),
    Object::var(
        i_(470),
        Value::Ram,
        entries![e(0, "Following error reaction", U8, RW).range(0, 1).saved()],
    )
    .axis()
    .level(1)
    .note("I470 (line ours: the spec names the configurable reaction of the following error window, P-159, not its parameter): what a following error beyond 6065h for 6066h does: 0 = a message, statusword bit 13 (PROFINET ZSW1 bit 8) only (default); 1 = a fault, event 54 cause 1 (603Fh 8611h) with the fault reaction 605Eh; I21 (event 54 cause 2) faults regardless; effective at once"),
    Object::var(
        i_(471),
        Value::Ram,
        entries![e(0, "Set value monitoring", U8, RW)
            .range(0, 1)
            .default_value(1)
            .saved()],
    )
    .axis()
    .level(1)
    .note("I471 (line ours: the spec gives the function, on by default, not its parameter; C-148): 1 = on (default): a cyclic position set-point further from the previous one than twice 607Fh over the time between them trips event 78 cause 4 'excessive set value jump'; 0 = off; effective at once"),
];
