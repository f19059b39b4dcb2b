//! The manufacturer parameters the firmware itself reads or writes, by name
//! (axis-A / global index, `parameter_index(group, line)`; axis B at +8000h
//! through the axis' window). Declared once here; their entries (type,
//! range, default) are in [`crate::objects`].

use crate::parameter_index;

/// A00 "Save values": \[0\] start (sub 1), \[1\] progress (sub 2), \[2\] result (sub 3),
/// in the SDO-Info numbering the runtime always uses.
pub const A00: u16 = parameter_index(0, 0);
/// A268 SDO Info object selection: sub 1 index area (0 standard, 1
/// manufacturer, 2 all), sub 2 manufacturer groups (bit g = group A + g).
pub const A268: u16 = parameter_index(0, 268);
/// A269 UDP parameter writes (0 = the UDP parameter service only reads).
pub const A269: u16 = parameter_index(0, 269);
/// A254 station alias.
pub const A254: u16 = parameter_index(0, 254);
/// A255 device state (ESM state, +16 with an error).
pub const A255: u16 = parameter_index(0, 255);
/// A256 station address.
pub const A256: u16 = parameter_index(0, 256);
/// A257 diagnosis (Er codes and texts).
pub const A257: u16 = parameter_index(0, 257);
/// A149 cycle sequence.
pub const A149: u16 = parameter_index(0, 149);
/// A150 application cycle time, µs (250 … 8000, C-144).
pub const A150: u16 = parameter_index(0, 150);
/// The cycle assumed while A150 holds no allowed value, µs: A150's declared
/// default (`c144_a150_fallback_is_the_declared_default`).
pub const A150_FALLBACK_US: u32 = 1000;
/// A261 sync diagnostics: `[k]` is sub `k + 1`.
pub const A261: u16 = parameter_index(0, 261);
/// A290 PLL control.
pub const A290: u16 = parameter_index(0, 290);
/// A287 DC-Sync optimisation: \[0\] start, \[1\] progress, \[2\] result, \[3\]/\[4\]
/// proposed A292 min/max, \[5\] end of frame → SYNC0, \[6\] frame duration,
/// \[7\] SYNC0 → Rx (µs); `[k]` is sub `k + 1`.
pub const A287: u16 = parameter_index(0, 287);
/// A291 PLC cycle time (µs).
pub const A291: u16 = parameter_index(0, 291);
/// A292 phase offset of the drive task after SYNC0, µs.
pub const A292: u16 = parameter_index(0, 292);
/// A296 measured SYNC0 cycle, µs.
pub const A296: u16 = parameter_index(0, 296);
/// A298 PLL status.
pub const A298: u16 = parameter_index(0, 298);

/// E43 event cause.
pub const E43: u16 = parameter_index(4, 43);
/// E54 firmware update slot: 1 = A, 2 = B, 0 = no firmware slots.
pub const E54: u16 = parameter_index(4, 54);
/// E59 projected fieldbus identification (\[2\]).
pub const E59: u16 = parameter_index(4, 59);
/// E82 event type.
pub const E82: u16 = parameter_index(4, 82);

/// E47 causes of Switch on disabled (per axis).
pub const E47: u16 = parameter_index(4, 47);
/// E49 causes of Switch on disabled, second word (per axis).
pub const E49: u16 = parameter_index(4, 49);
/// E48 device state (per axis).
pub const E48: u16 = parameter_index(4, 48);
/// A66 sources of the user status word (per axis, 16 elements).
pub const A66: u16 = parameter_index(0, 66);
/// A67 user-defined status word (per axis).
pub const A67: u16 = parameter_index(0, 67);
/// A340 velocity override, % (per axis).
pub const A340: u16 = parameter_index(0, 340);
/// E80 operating condition (per axis).
pub const E80: u16 = parameter_index(4, 80);
/// A213 fieldbus scaling (global; 1 native, 0 integer with decimal places):
/// \[0\] (sub 1) the process data and the values the objects hold, \[1\]
/// (sub 2) the parameter channel (SDO, UDP parameter service); see
/// [`crate::objects::scaling`].
pub const A213: u16 = parameter_index(0, 213);
/// A310 decimal places of the velocity objects (per axis).
pub const A310: u16 = parameter_index(0, 310);
/// A311 decimal places of the acceleration, deceleration and jerk objects
/// (per axis).
pub const A311: u16 = parameter_index(0, 311);
/// A44 quick stop on the loss of A60 (per axis).
pub const A44: u16 = parameter_index(0, 44);
/// I00 position range: 0 limited, 1 endless (per axis).
pub const I00: u16 = parameter_index(8, 0);
/// I04 permitted direction of an endless axis: 0 both, 1 positive, 2
/// negative (per axis).
pub const I04: u16 = parameter_index(8, 4);
/// C31 velocity controller Kp, µN·m per rad/s (per axis).
pub const C31: u16 = parameter_index(2, 31);
/// C32 velocity controller Ti, µs; 0 = no integral part (per axis).
pub const C32: u16 = parameter_index(2, 32);
/// I12 jog velocity, user units/s (per axis).
pub const I12: u16 = parameter_index(8, 12);
/// I13 jog acceleration, user units/s² (per axis).
pub const I13: u16 = parameter_index(8, 13);
/// I18 jog jerk, user units/s³, 0 = none (per axis).
pub const I18: u16 = parameter_index(8, 18);
/// I26 jog control type: 0 velocity, 1 position (per axis).
pub const I26: u16 = parameter_index(8, 26);
/// I45 jog deceleration, user units/s² (per axis).
pub const I45: u16 = parameter_index(8, 45);
/// I28 torque limit while homing, 0.1 % of 6076h (per axis).
pub const I28: u16 = parameter_index(8, 28);
/// I29 time at the homing torque limit, ms (per axis).
pub const I29: u16 = parameter_index(8, 29);
/// I30 reference switch type: 2 = the limit switches (per axis).
pub const I30: u16 = parameter_index(8, 30);
/// I43 move to the reference position after homing (per axis).
pub const I43: u16 = parameter_index(8, 43);
/// I53 index search offset, user position units (per axis).
pub const I53: u16 = parameter_index(8, 53);
/// C40 velocity window, user units/s (per axis).
pub const C40: u16 = parameter_index(2, 40);
/// I10 maximal speed, user units/s (per axis).
pub const I10: u16 = parameter_index(8, 10);
/// I44 referencing jerk, user units/s³, 0 = none (per axis).
pub const I44: u16 = parameter_index(8, 44);
/// I25 speed feedforward, % (per axis).
pub const I25: u16 = parameter_index(8, 25);
/// I87 time in the position window, ms (per axis).
pub const I87: u16 = parameter_index(8, 87);
/// I423 maximum extrapolation period, ms (per axis).
pub const I423: u16 = parameter_index(8, 423);
/// I425 speed feedforward interpolation: 0, 1, 3, 4, 5 (per axis).
pub const I425: u16 = parameter_index(8, 425);
/// I20 position controller Kv, 0.1 /s (per axis).
pub const I20: u16 = parameter_index(8, 20);
/// I470 following error reaction: 0 message (statusword bit 13), 1 fault
/// (event 54 cause 1) (per axis; line ours).
pub const I470: u16 = parameter_index(8, 470);
/// I471 set-value monitoring, C-148 (1 = on; per axis; line ours).
pub const I471: u16 = parameter_index(8, 471);
/// F00 brake control (1 = active, per axis).
pub const F00: u16 = parameter_index(5, 0);
/// F06 brake release override (1 = active, per axis).
pub const F06: u16 = parameter_index(5, 6);
/// G472 positive velocity limit of the torque modes, 0.1 % of I10 (per
/// axis, C-039).
pub const G472: u16 = parameter_index(6, 472);
/// G475 negative velocity limit of the torque modes, 0.1 % of I10 (per
/// axis, C-039).
pub const G475: u16 = parameter_index(6, 475);
/// I02 position encoder (per axis).
pub const I02: u16 = parameter_index(8, 2);
/// A279 PROFINET units (the PROFIdrive personality's unit choices).
pub const A279: u16 = parameter_index(0, 279);
/// A280 PROFINET telegrams (the profile's stored telegram configuration).
pub const A280: u16 = parameter_index(0, 280);
/// I21 position error limit (per axis, user position units; `u32::MAX` = off).
pub const I21: u16 = parameter_index(8, 21);
/// I22 target window (per axis, user position units).
pub const I22: u16 = parameter_index(8, 22);
/// I23 position controller dead band (per axis, user position units).
pub const I23: u16 = parameter_index(8, 23);
/// I46 reference retaining (per axis).
pub const I46: u16 = parameter_index(8, 46);
/// I101 / I102 / I103 sources of +LS, −LS and the reference switch.
pub const I101: u16 = parameter_index(8, 101);
/// I210 application control word (switch signals from the fieldbus).
pub const I210: u16 = parameter_index(8, 210);
/// A258 EtherCAT PDO timeout (U16 ms with special values, spec §13.1).
pub const A258: u16 = parameter_index(0, 258);

/// A270 PROFINET active (BOOL; the PROFINET personality's parameters
/// A270…A278, spec §2.4): off takes effect at once, on after save and
/// restart.
pub const A270: u16 = parameter_index(0, 270);
/// A271 name of station (string of up to
/// [`PN_NAME_LEN`](crate::objects::manufacturer::PN_NAME_LEN) bytes, empty = none).
pub const A271: u16 = parameter_index(0, 271);
/// A272 static IP address of the PROFINET interface (UINT32, first octet in
/// the most significant byte; 0 = none).
pub const A272: u16 = parameter_index(0, 272);
/// A273 its subnet mask (as A272).
pub const A273: u16 = parameter_index(0, 273);
/// A274 its default gateway (as A272; 0 = none).
pub const A274: u16 = parameter_index(0, 274);
/// A275 PROFIenergy active (BOOL).
pub const A275: u16 = parameter_index(0, 275);
/// A276 PROFINET protocol: 0 = standard protocol, the only value.
pub const A276: u16 = parameter_index(0, 276);
/// A277 parameterisation interface: 0 automatic, 1 on-board Ethernet, 2 PROFINET.
pub const A277: u16 = parameter_index(0, 277);
/// A278 vendor service port (UINT16, default 8802).
pub const A278: u16 = parameter_index(0, 278);
/// The PROFINET personality's persistent parameters, A270…A278.
pub const PROFINET_PARAMS: [u16; 9] = [A270, A271, A272, A273, A274, A275, A276, A277, A278];
/// B05 commutation offset, increments (per axis, motor data; B41 finds it).
pub const B05: u16 = parameter_index(1, 5);
/// B40 test phase: the action's result and what it saw (per axis; started
/// through A75, `crate::tuning::phase`).
pub const B40: u16 = parameter_index(1, 40);
/// B41 calibrate motor: the action's result (per axis; started through A75).
pub const B41: u16 = parameter_index(1, 41);
/// B10 pole pair number (per axis, motor data; issue 34).
pub const B10: u16 = parameter_index(1, 10);
/// B17 torque constant, mN·m/A (per axis, motor data).
pub const B17: u16 = parameter_index(1, 17);
/// B42 optimise current controller: the action's result and figures (per
/// axis; started through A75, `crate::tuning`).
pub const B42: u16 = parameter_index(1, 42);
/// B43 test winding: the action's result and the three phases' resistances
/// (per axis; started through A75, `crate::tuning::winding`).
pub const B43: u16 = parameter_index(1, 43);
/// B44 identify mechanics: the action's result, excursion and constant
/// load (per axis; started through A75 selector 1111b,
/// `crate::tuning::mechanics`).
pub const B44: u16 = parameter_index(1, 44);
/// B45 total inertia, 10⁻⁷ kg·m² (g·cm²; per axis; 0 = not identified).
pub const B45: u16 = parameter_index(1, 45);
/// B46 Coulomb friction, µN·m (per axis).
pub const B46: u16 = parameter_index(1, 46);
/// B47 viscous friction, nN·m·s/rad (per axis).
pub const B47: u16 = parameter_index(1, 47);
/// B48 speed-loop bandwidth for the gains of B44, Hz (per axis).
pub const B48: u16 = parameter_index(1, 48);
/// B52 d-axis inductance Ld, µH (per axis, motor data).
pub const B52: u16 = parameter_index(1, 52);
/// B300 test brake: the action's result, the largest movement seen and the
/// test torque (per axis, spec §14).
pub const B300: u16 = parameter_index(1, 300);
/// B301 grind brake: the action's result, the smallest travels of its grind
/// and released phases and the largest grinding torque (per axis, spec §14,
/// `crate::tuning::grind`).
pub const B301: u16 = parameter_index(1, 301);
/// B53 phase resistance, mΩ (per axis, motor data).
pub const B53: u16 = parameter_index(1, 53);
/// B62 q-axis inductance Lq, µH (per axis, motor data).
pub const B62: u16 = parameter_index(1, 62);
/// B64 current-controller bandwidth, Hz (per axis).
pub const B64: u16 = parameter_index(1, 64);
/// B73 thermal time constant of the winding, ms (per axis, motor data).
pub const B73: u16 = parameter_index(1, 73);
/// U10 i²t level (0 inactive, 1 message, 2 warning, 3 fault; per axis).
pub const U10: u16 = parameter_index(20, 10);
/// U11 i²t warning time, ms (per axis).
pub const U11: u16 = parameter_index(20, 11);

/// A21 brake resistor R, Ω (0 = none; device).
pub const A21: u16 = parameter_index(0, 21);
/// A22 brake resistor rated power, W (device; line assumed).
pub const A22: u16 = parameter_index(0, 22);
/// A23 brake resistor thermal time constant, ms (device; line assumed).
pub const A23: u16 = parameter_index(0, 23);
/// A35 DC-link low voltage limit, V (device; line assumed).
pub const A35: u16 = parameter_index(0, 35);
/// A38 brake chopper switch-on threshold, V (device; line assumed).
pub const A38: u16 = parameter_index(0, 38);
/// A40 power stage over-voltage trip, V (read only; line assumed).
pub const A40: u16 = parameter_index(0, 40);
/// A41 power stage maximum current, mA (read only; line assumed).
pub const A41: u16 = parameter_index(0, 41);
/// A42 power stage rated current, mA (read only; line assumed).
pub const A42: u16 = parameter_index(0, 42);
/// A43 power stage thermal time constant, ms (read only; line assumed).
pub const A43: u16 = parameter_index(0, 43);

/// T00 scope state: 0 idle, 1 armed, 2 triggered, 3 complete; a write of 1
/// arms, 0 stops (global; `crate::scope`).
pub const T00: u16 = parameter_index(19, 0);
/// T01 scope channels: 8 elements, each a mapping entry (index << 16 | sub
/// << 8 | bits) or an internal signal (index 0).
pub const T01: u16 = parameter_index(19, 1);
/// T02 number of scope channels in use (0…8).
pub const T02: u16 = parameter_index(19, 2);
/// T03 sample divider: one sample every T03 control cycles.
pub const T03: u16 = parameter_index(19, 3);
/// T04 samples per channel (0 = as many as the buffer holds).
pub const T04: u16 = parameter_index(19, 4);
/// T05 trigger source: 0 none, 1…8 a channel, 10h + n statusword bit n of
/// axis A, 20h + n of axis B.
pub const T05: u16 = parameter_index(19, 5);
/// T06 trigger condition: 0 level ≥, 1 level <, 2 rising edge, 3 falling
/// edge, 4 either edge.
pub const T06: u16 = parameter_index(19, 6);
/// T07 trigger level (the channel's value).
pub const T07: u16 = parameter_index(19, 7);
/// T08 pre-trigger share, %.
pub const T08: u16 = parameter_index(19, 8);
/// T09 scope mode: 0 single, 1 normal.
pub const T09: u16 = parameter_index(19, 9);
/// T10 trace information: \[0\] samples per channel, \[1\] trigger index,
/// \[2\] completed traces, \[3\] buffer words.
pub const T10: u16 = parameter_index(19, 10);
/// T11 trace data: element k = bytes k·4096… of the complete trace.
pub const T11: u16 = parameter_index(19, 11);
