#!/usr/bin/env python3
"""The motor actions through SOEM on the electrical plant (issue 35; E-140,
E-141): A75 in the RxPDO, A69 in the TxPDO, the motor data by SDO.

Run by `hil-sim/tests/soem_electrical.rs` as root inside the master's network
namespace against `hil-sim serve --plant electrical --plant-r R --plant-l L
--slaves 1` (or by hand), with the same --r and --l: the plant's motor, which
the drive's dictionary does not know (it keeps B53 = 3.6 ohm, B52 = 12 mH).
Free run, one drive, axis A in cst; RxPDO 6040h, 6060h, A75; TxPDO 6041h, A69.

  1. Op, the axis switch-on disabled: A75 = Execute | 1100b (B42, optimise
     current controller) is refused (A69 state 3), B53/B52 unchanged.
  2. B40 (1010b, test phase), as below: done, B40[0] = 0, B40[2] (the pole
     pairs the encoder's count over one electrical turn means) = B10.
     B41 (1011b, calibrate motor), as below: B05 (commutation offset, 0
     before) within 0.5 degrees electrical of the plant's --offset (rad,
     mechanical; modulo an electrical revolution, 2^20 / B10 increments),
     B41[0] = 0. B42 needs it: it injects in the rotor's frame.
  3. Execute low, shutdown (6040h = 6): ready to switch on (E48 = 2). For
     B42 (1100b) and then B49 (1110b, at standstill): Execute; A69 shows it
     running at 0 % until the enable (6040h = 7, 15); then the progress
     rises to 100 %, state done; B42[0] (sub 1) = 0, B53 and B52/B62 within
     5 % of --r/--l, B42[1]/[2] the same figures. Execute low and shutdown:
     A69 idle.
  4. B43 (1101b, test winding) in ready to switch on, no enable: done,
     B43[0] = 0, the three resistances within 3 % of --r, E48 still 2.
  5. B300 (0100b, test brake), as B40: the brake applied against the rated
     torque both ways: done, B300[0] = 0, B300[1] (the largest movement)
     within 1/360 rev, B300[2] = 6076h (the test torque, mN m).
  6. B301 (0101b, grind brake), as B40: 4 rounds of 0.5 s grinding against
     the applied brake and 0.25 s released at 60 rpm, then 0.1 s stopped on
     the brake: done, B301[0] = 0, each grind phase turned the shaft by at
     least 0.8 of 60 rpm x 0.5 s (2^19 inc), each released phase by 0.8 of
     its 2^18, and the grinding torque B301[3] is the plant's brake (its
     default 2 N m holding and sliding torque, which the drive does not know)
     plus friction, within 2.0 ... 2.3 N m.

Prints `FAIL: ...` for every check that failed; exit status 0 when none did.
"""
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import line as L  # noqa: E402

say, check = L.say, L.check


def b(line):
    return 0x2000 + 1 * 0x200 + line


A75, A69 = 0x2000 + 75, 0x2000 + 69
B05, B10, B40, B41, B42, B43, B52, B53, B62 = b(5), b(10), b(40), b(41), b(42), b(43), b(52), b(53), b(62)
B300, B301 = b(300), b(301)
E48 = 0x2000 + 4 * 0x200 + 48
RX = [L.entry(0x6040, 0, 16), L.entry(0x6060, 0, 8), L.entry(A75, 0, 8)]
TX = [L.entry(0x6041, 0, 16), L.entry(A69, 0, 16)]
OUT, IN = "<HbB", "<HH"
RUNNING, DONE, REFUSED = 1, 2, 3
# cst with 6071h = 0 (not mapped): the axis holds no position, so the one B41
# turns the rotor to needs no cyclic target (csp would: a master there sends
# the actual position as the target, as before any enable)
CST = 10
B40_SEL, B41_SEL, B42_SEL, B43_SEL, B49_SEL = 0b1010, 0b1011, 0b1100, 0b1101, 0b1110
B300_SEL, B301_SEL = 0b0100, 0b0101


class Axis(L.FreeRunAxis):
    """Axis A of drive 1 in free run, about 1 ms per frame."""

    OUT, IN = OUT, IN

    def __init__(self, m):
        super().__init__(m)
        self.cw, self.a75 = 0, 0
        self.sw = self.a69 = 0

    def outputs(self):
        return self.cw, CST, self.a75

    def inputs(self, sw, a69):
        self.sw, self.a69 = sw, a69


def motor_data(s):
    return L.sdo_u(s, B53, 0), L.sdo_u(s, B52, 0), L.sdo_u(s, B62, 0)


def refused(axis):
    before = motor_data(axis.s)
    axis.a75 = B42_SEL << 1 | 1
    axis.cycle(10)
    want = B42_SEL << 8 | REFUSED << 12
    check(axis.a69 == want, f"B42 switch-on disabled: A69 {axis.a69:04X}h, expected {want:04X}h (refused)")
    check(motor_data(axis.s) == before, f"refused B42 changed nothing: {motor_data(axis.s)} vs {before}")
    axis.a75 = 0
    axis.cycle(5)


def ready(axis):
    """Controlword 6 until the statusword shows Ready to switch on (300
    frames at most)."""
    axis.cw = 6
    check(axis.until(lambda: L.sw_is(axis.sw, L.READY), 300), f"ready to switch on: statusword {axis.sw:#06x}")


def switch_on_and_enable(axis):
    """Controlwords 7 and 0xF, 10 frames each."""
    for cw in (7, 0xF):
        axis.cw = cw
        axis.cycle(10)


def watch(axis, seconds, busy=(RUNNING,)):
    """A69 frame by frame until its state is not in `busy` (`seconds` at
    most): the values it showed, the time it took."""
    seen = []
    start_t = time.monotonic()
    while time.monotonic() - start_t < seconds:
        axis.cycle()
        if not seen or seen[-1] != axis.a69:
            seen.append(axis.a69)
        if axis.a69 >> 12 not in busy:
            break
    return seen, time.monotonic() - start_t


def check_done(what, sel, seen, more=""):
    """A69 ended in `sel` done (100 %); `more` goes into the message."""
    done = 100 | sel << 8 | DONE << 12
    check(seen[-1] == done, f"{what}: A69 ends {seen[-1]:04X}h, expected {done:04X}h; seen {[f'{s:04X}' for s in seen]}{more}")


def execute_low(axis, what=None):
    """Execute (A75 bit 0) low in Ready to switch on, 20 frames; with `what`,
    A69 must then be idle."""
    axis.a75 = 0
    axis.cw = 6
    axis.cycle(20)
    if what is not None:
        check(axis.a69 == 0, f"{what}: A69 {axis.a69:04X}h after Execute low, expected idle")


def start(axis, sel):
    """Starts `sel` in Ready to switch on, enables; A69 until it leaves running."""
    ready(axis)
    axis.a75 = sel << 1 | 1
    axis.cycle(10)
    switch_on_and_enable(axis)
    return watch(axis, 30.0)


def phase_test(axis):
    seen, took = start(axis, B40_SEL)
    result = L.sdo_u(axis.s, B40, 1)
    check_done("B40", B40_SEL, seen, f"; B40[0] {result}")
    check(result == 0, f"B40[0] result {result}, expected 0")
    per_turn = int.from_bytes(axis.s.sdo_read(B40, 2), "little", signed=True)
    pp = L.sdo_u(axis.s, B40, 3)
    say(f"B40: {per_turn} inc per electrical turn, {pp} pole pairs seen, in {took:.2f} s")
    check(pp == L.sdo_u(axis.s, B10, 0), f"B40: pole pairs seen {pp} vs B10")
    execute_low(axis)


def calibrate(axis, offset_rad):
    pp = L.sdo_u(axis.s, B10, 0)
    per_el = (1 << 20) // pp
    truth = round(offset_rad / (2 * 3.141592653589793) * (1 << 20))
    check(L.sdo_u(axis.s, B05, 0) == 0, "B05 = 0 before")
    seen, took = start(axis, B41_SEL)
    check_done("B41", B41_SEL, seen)
    check(L.sdo_u(axis.s, B41, 1) == 0, f"B41[0] result {L.sdo_u(axis.s, B41, 1)}, expected 0")
    b05 = L.sdo_u(axis.s, B05, 0)
    err = (b05 - truth) % per_el
    err = min(err, per_el - err) / per_el * 360.0
    say(f"B41: plant offset {truth} inc, B05 {b05} inc: {err:.3} deg electrical off, alignments {L.sdo_u(axis.s, B41, 2)} inc apart, in {took:.2f} s")
    check(err < 0.5, f"B41: B05 {b05} vs the plant's {truth} (mod {per_el}): {err} deg el")
    execute_low(axis)


def test_brake(axis):
    seen, took = start(axis, B300_SEL)
    result, moved, torque = (L.sdo_u(axis.s, B300, k) for k in (1, 2, 3))
    check_done("B300", B300_SEL, seen, f"; B300[0] {result}")
    check(result == 0, f"B300[0] result {result}, expected 0 (held)")
    check(moved <= (1 << 20) // 360, f"B300: the shaft moved {moved} inc under the test torque")
    rated = L.sdo_u(axis.s, 0x6076, 0)
    check(torque == rated, f"B300: test torque {torque} mN m, 6076h {rated}")
    say(f"B300: the brake held {torque} mN m both ways, largest movement {moved} inc, in {took:.2f} s")
    execute_low(axis)


def grind_brake(axis):
    seen, took = start(axis, B301_SEL)
    # A69 first: a fault's EMCY would come with the first SDO read
    check_done("B301", B301_SEL, seen, f"; statusword {axis.sw:#06x}")
    result, grind, released, torque = (L.sdo_u(axis.s, B301, k) for k in (1, 2, 3, 4))
    check(result == 0, f"B301[0] result {result}, expected 0 (ground in)")
    check(grind >= 0.8 * (1 << 19), f"B301: a grind phase turned the shaft {grind} inc only")
    check(released >= 0.8 * (1 << 18), f"B301: a released phase turned the shaft {released} inc only")
    check(2000 <= torque <= 2300, f"B301: grinding torque {torque} mN m, the plant's brake slides at 2000")
    say(f"B301: smallest grind travel {grind} inc, released {released} inc, grinding torque {torque} mN m, in {took:.2f} s")
    execute_low(axis)


def winding(axis, r):
    ready(axis)
    axis.a75 = B43_SEL << 1 | 1
    seen, took = watch(axis, 10.0, busy=(0, RUNNING))
    check_done("B43", B43_SEL, seen)
    check(L.sdo_u(axis.s, E48, 0) == 2, "B43 runs without the enable: E48 = 2")
    check(L.sdo_u(axis.s, B43, 1) == 0, f"B43[0] result {L.sdo_u(axis.s, B43, 1)}, expected 0")
    rs = [L.sdo_u(axis.s, B43, k) * 1e-3 for k in (2, 3, 4)]
    say(f"B43: resistances along U, V, W {rs} ohm (plant {r} ohm) in {took:.2f} s")
    check(all(abs(x - r) <= 0.03 * r for x in rs), f"B43: {rs} not within 3 % of {r} ohm")
    axis.a75 = 0
    axis.cycle(10)


def optimise(axis, sel, r, l):
    ready(axis)
    check(L.sdo_u(axis.s, E48, 0) == 2, "E48 = 2")
    axis.a75 = sel << 1 | 1
    axis.cycle(10)
    want = sel << 8 | RUNNING << 12
    check(axis.a69 == want, f"{sel:04b}: A69 {axis.a69:04X}h before the enable, expected {want:04X}h (running, 0 %)")
    switch_on_and_enable(axis)
    seen, took = watch(axis, 10.0)
    check_done(f"{sel:04b}", sel, seen, f"; B42[0] {L.sdo_u(axis.s, B42, 1)}, statusword {axis.sw:#06x}")
    check(all((a & 0xFF) <= (b_ & 0xFF) for a, b_ in zip(seen, seen[1:])), f"{sel:04b}: progress rises: {[f'{s:04X}' for s in seen]}")
    check(L.sdo_u(axis.s, B42, 1) == 0, f"{sel:04b}: B42[0] result {L.sdo_u(axis.s, B42, 1)}, expected 0")
    r_mohm, l_uh, lq_uh = motor_data(axis.s)
    r_id, l_id = r_mohm * 1e-3, l_uh * 1e-6
    say(f"{sel:04b}: plant R {r} ohm L {l * 1e3} mH; identified R {r_id:.3f} ohm ({(r_id - r) / r * 100:+.2f} %), L {l_id * 1e3:.3f} mH ({(l_id - l) / l * 100:+.2f} %) in {took:.2f} s")
    check(abs(r_id - r) <= 0.05 * r, f"{sel:04b}: B53 {r_id} ohm not within 5 % of the plant's {r} ohm")
    check(abs(l_id - l) <= 0.05 * l, f"{sel:04b}: B52 {l_id} H not within 5 % of the plant's {l} H")
    check(lq_uh == l_uh, f"{sel:04b}: B62 {lq_uh} = B52 {l_uh}")
    check((L.sdo_u(axis.s, B42, 2), L.sdo_u(axis.s, B42, 3)) == (r_mohm, l_uh), f"{sel:04b}: B42[1]/[2] = B53/B52")
    execute_low(axis, f"{sel:04b}")


def run(m, args):
    s = L.one_drive_in_preop(m)
    L.map_one_pdo_each(s, RX, TX)
    axis = L.to_op(m, Axis)
    refused(axis)
    # the wiring, then the commutation offset: B42 injects in the rotor's frame
    phase_test(axis)
    calibrate(axis, args.offset)
    for sel in (B42_SEL, B49_SEL):
        optimise(axis, sel, args.r, args.l)
    winding(axis, args.r)
    test_brake(axis)
    grind_brake(axis)
    L.stop(axis)


L.script(__name__, __doc__, run, "motor actions on the electrical plant: all checks passed",
         L.required_float("--r", "the plant's phase resistance, ohm"),
         L.required_float("--l", "the plant's inductance, H"),
         L.required_float("--offset", "the plant's commutation offset, rad (mechanical)"))
