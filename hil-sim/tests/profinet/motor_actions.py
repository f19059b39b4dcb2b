"""The motor actions through the PROFIdrive parameter access on the
electrical plant (issue 35; E-140, E-141 on PROFINET): profinet-py (0.6.6)
as the IO controller of `hil-sim serve --fieldbus profinet --plant
electrical --plant-r R --plant-l L`, the Example Function block of fb.py on
its cyclic data (telegram 0xE0), A75 written and A69 read through PKW (PNU =
the object's index, docs/pnu.md). On PROFINET the parameter access is the
action activation (docs/conformance.md, E-142).

  1. The drive's motor data made wrong through PKW (B53 = 1,000 mOhm,
     B52 = B62 = 4,000 uH): the plant's --r/--l are unknown to it.
  2. Enabled (operation enabled, E48 = 4): A75 = Execute | 1100b (B42) is
     refused, A69 state 3, B53 unchanged. Execute low, disabled.
  3. B43 (1101b, test winding) in ready to switch on, no enable: A69 done
     (100 %), B43[0] = 0, the three resistances within 3 % of --r.
  4. B42 (1100b, optimise current controller): A69 running at 0 % until the
     enable, then done; B42[0] = 0, B53 within 5 % of --r, B52 within 5 % of
     --l. Execute low, disabled: A69 idle.
  5. B300 (0100b, test brake) with the enable: done, B300[0] = 0 (held),
     the largest movement within 1/360 rev.
  6. B44 (1111b, identify mechanics, ours) with the enable: done, B44[0] = 0,
     B45 (J) within 5 % of --j, B46/B47 (Coulomb, viscous friction) within
     10 % of --fc/--b (the plant's, which the drive does not know).

With --offset (serve --plant-offset, the plant's commutation offset, rad,
which the drive does not know), first, before any action that injects in
the rotor's frame, and then after B42 and B300:
  3a. B40 (1010b, test phase) with the enable: done, B40[0] = 0, the pole
      pairs seen B40[2] = B10. B41 (1011b, calibrate motor): done, B41[0] =
      0, B05 within 0.5 degrees electrical of --offset.
  4a. B49 (1110b, optimise the current controller at standstill): done,
      B42[0] = 0 (B49 reports in B42), B53 within 5 % of --r, B52 within 5 % of --l.
  5a. B301 (0101b, grind brake): done, B301[0] = 0, each grind phase turned
      the shaft by at least 0.8 of 60 rpm x 0.5 s (2^19 inc), the grinding
      torque B301[3] the plant's brake (2 N m) plus friction, 2.0 ... 2.3 N m.
      Then, with the enable and Execute still on for 0.5 s, the axis' own
      control holds the shaft where B301 left it (within 3/1000 rev, no fault).

One line:  scenario E-140: ok|FAIL: ...
"""

import sys
import time

from fb import OP, PKW_READ, PKW_WRITE, fb_arguments, run_fb_scenario
from pnctl import Scenario, ms


def b(line):
    return 0x2200 + line


A75, A69 = 0x2000 + 75, 0x2000 + 69
B42, B43, B52, B53, B62, B300 = b(42), b(43), b(52), b(53), b(62), b(300)
B44, B45, B46, B47 = b(44), b(45), b(46), b(47)
B05, B10, B40, B41, B301 = b(5), b(10), b(40), b(41), b(301)
B40_SEL, B41_SEL, B49_SEL, B301_SEL = 0b1010, 0b1011, 0b1110, 0b0101
E48 = 0x2800 + 48
RUNNING, DONE, REFUSED = 1, 2, 3
B42_SEL, B43_SEL, B300_SEL, B44_SEL = 0b1100, 0b1101, 0b0100, 0b1111


def read(fb, sc, index, sub=0):
    """A PKW read; a refusal or no answer is a failed check (the many reads
    that succeed are not listed)."""
    r = fb.pkw(PKW_READ, index, sub, timeout=3.0)
    if r is None or r[0] != PKW_READ:
        sc.check(False, f"PKW read {index:04X}h:{sub}: {r}")
        return None
    return r[1]


def write(fb, sc, index, value, sub=0):
    r = fb.pkw(PKW_WRITE, index, sub, value, timeout=3.0)
    if r != (PKW_WRITE, value):
        sc.check(False, f"PKW write {index:04X}h:{sub} = {value}: {r}")


def a69_until(fb, sc, pred, timeout):
    """Reads A69 through PKW until pred(A69) holds: (A69, seconds) or (last, None)."""
    t0 = time.monotonic()
    last = None
    while time.monotonic() - t0 < timeout:
        last = read(fb, sc, A69)
        if last is not None and pred(last):
            return last, time.monotonic() - t0
        fb.run_for(0.05)
    return last, None


def enable(fb, sc, what):
    fb.i.drive_enable = True
    dt = fb.until(lambda o: o.zsw1 & 0x47 == OP, 5.0)
    sc.check(dt is not None, f"{what}: operation enabled after {ms(dt)}")


def disable(fb):
    fb.i.drive_enable = False
    fb.until(lambda o: o.zsw1 & 0x47 != OP, 2.0)
    fb.run_for(0.05)


def stop(fb, sc):
    write(fb, sc, A75, 0)
    a69, dt = a69_until(fb, sc, lambda v: v == 0, 2.0)
    sc.check(dt is not None, f"Execute low: A69 idle ({a69})")


def mechanics(fb, sc, j, fc, visc):
    write(fb, sc, A75, B44_SEL << 1 | 1)
    fb.run_for(0.05)
    t0 = time.monotonic()
    enable(fb, sc, "B44")
    a69, dt = a69_until(fb, sc, lambda v: v >> 12 not in (0, RUNNING), 30.0)
    sc.check(a69 == (100 | B44_SEL << 8 | DONE << 12), f"B44: A69 {a69} after {ms(dt)} (want done, 100 %)")
    sc.check(read(fb, sc, B44, 1) == 0, "B44[0] = 0")
    # B45 in 1e-7 kg m^2, B46 in uN m, B47 in nN m s/rad
    j_id = (read(fb, sc, B45) or 0) * 1e-7
    fc_id = (read(fb, sc, B46) or 0) * 1e-6
    b_id = (read(fb, sc, B47) or 0) * 1e-9
    sc.note(f"B44: J {j_id:.4e} kg m^2 ({100 * (j_id / j - 1):+.1f} %), Fc {fc_id:.4f} N m "
            f"({100 * (fc_id / fc - 1):+.1f} %), B {b_id:.3e} N m s/rad ({100 * (b_id / visc - 1):+.1f} %) "
            f"in {time.monotonic() - t0:.2f} s")
    sc.check(abs(j_id - j) <= 0.05 * j, f"B45 {j_id} within 5 % of the plant's {j}")
    sc.check(abs(fc_id - fc) <= 0.10 * fc, f"B46 {fc_id} within 10 % of the plant's {fc}")
    sc.check(abs(b_id - visc) <= 0.10 * visc, f"B47 {b_id} within 10 % of the plant's {visc}")
    stop(fb, sc)
    disable(fb)


def action(fb, sc, sel, name, timeout=20.0):
    """Starts `sel` in ready to switch on, enables, waits for its end:
    checks done (100 %); Execute low and disabled afterwards by the caller."""
    write(fb, sc, A75, sel << 1 | 1)
    fb.run_for(0.05)
    t0 = time.monotonic()
    enable(fb, sc, name)
    a69, dt = a69_until(fb, sc, lambda v: v >> 12 not in (0, RUNNING), timeout)
    sc.check(a69 == (100 | sel << 8 | DONE << 12), f"{name}: A69 {a69} after {ms(dt)} (want done, 100 %)")
    return time.monotonic() - t0


def end(fb, sc):
    stop(fb, sc)
    disable(fb)


def phase_and_offset(fb, sc, offset):
    took = action(fb, sc, B40_SEL, "B40")
    pp, b10 = read(fb, sc, B40, 3), read(fb, sc, B10)
    sc.check(read(fb, sc, B40, 1) == 0 and pp == b10, f"B40: done in {took:.2f} s, pole pairs seen {pp} = B10 {b10}")
    end(fb, sc)
    per_el = (1 << 20) // max(b10 or 1, 1)
    truth = round(offset / (2 * 3.141592653589793) * (1 << 20))
    took = action(fb, sc, B41_SEL, "B41")
    b05 = read(fb, sc, B05) or 0
    err = (b05 - truth) % per_el
    err = min(err, per_el - err) / per_el * 360.0
    sc.check(read(fb, sc, B41, 1) == 0 and err < 0.5,
             f"B41: B05 {b05} inc against the plant's {truth}: {err:.3f} deg electrical, in {took:.2f} s")
    end(fb, sc)


def optimise_at_standstill(fb, sc, r, l):
    for index, value in ((B53, 1000), (B52, 4000), (B62, 4000)):
        write(fb, sc, index, value)
    took = action(fb, sc, B49_SEL, "B49")
    r_id, l_id = (read(fb, sc, B53) or 0) * 1e-3, (read(fb, sc, B52) or 0) * 1e-6
    sc.check(read(fb, sc, B42, 1) == 0 and abs(r_id - r) <= 0.05 * r and abs(l_id - l) <= 0.05 * l,
             f"B49: R {r_id:.4f} ohm (plant {r}), L {l_id * 1e3:.4f} mH (plant {l * 1e3}) in {took:.2f} s")
    end(fb, sc)


def grind_brake(fb, sc):
    took = action(fb, sc, B301_SEL, "B301")
    result, grind, released, torque = (read(fb, sc, B301, k) for k in (1, 2, 3, 4))
    sc.check(result == 0 and (grind or 0) >= 0.8 * (1 << 19) and 2000 <= (torque or 0) <= 2300,
             f"B301: result {result}, smallest grind travel {grind} inc, released {released} inc, "
             f"grinding torque {torque} mN m (the plant's brake slides at 2000), in {took:.2f} s")
    hand_back(fb, sc, "B301")
    end(fb, sc)


def hand_back(fb, sc, name):
    """After an action that turned the shaft, with the enable still on: the
    axis' own control holds the shaft where the action left it (no jump back
    to where it stood before, no fault)."""
    p0 = fb.o.position_actual_value
    fb.run_for(0.5)
    moved = abs(fb.o.position_actual_value - p0)
    sc.check(not fb.o.fault and fb.o.zsw1 & 0x47 == OP and moved <= 3,
             f"{name} handed back with the enable on: the axis holds ({moved}/1000 rev in 0.5 s, "
             f"fault {fb.o.fault})")


def run(fb, sc, r, l, offset=None):
    for index, value in ((B53, 1000), (B52, 4000), (B62, 4000)):
        write(fb, sc, index, value)
    # 2. refused while enabled
    enable(fb, sc, "refusal")
    sc.check(read(fb, sc, E48) == 4, "enabled: E48 = 4")
    write(fb, sc, A75, B42_SEL << 1 | 1)
    a69, _ = a69_until(fb, sc, lambda v: v >> 12 != 0, 2.0)
    sc.check(a69 == (B42_SEL << 8 | REFUSED << 12), f"B42 while enabled: A69 {a69} (want refused)")
    sc.check(read(fb, sc, B53) == 1000, "the refused B42 changed nothing (B53 = 1000)")
    stop(fb, sc)
    disable(fb)
    # 3. B43 in ready to switch on
    sc.check(read(fb, sc, E48) == 2, "disabled: E48 = 2 (ready to switch on)")
    t0 = time.monotonic()
    write(fb, sc, A75, B43_SEL << 1 | 1)
    a69, dt = a69_until(fb, sc, lambda v: v >> 12 not in (0, RUNNING), 10.0)
    sc.check(a69 == (100 | B43_SEL << 8 | DONE << 12), f"B43: A69 {a69} after {ms(dt)} (want done, 100 %)")
    sc.check(read(fb, sc, B43, 1) == 0, "B43[0] = 0")
    rs = [(read(fb, sc, B43, k) or 0) * 1e-3 for k in (2, 3, 4)]
    sc.note(f"B43: phase resistances {rs} ohm against the plant's {r} ohm in {time.monotonic() - t0:.2f} s")
    sc.check(all(abs(x - r) <= 0.03 * r for x in rs), f"B43: {rs} within 3 % of {r} ohm")
    stop(fb, sc)
    if offset is not None:
        phase_and_offset(fb, sc, offset)
    # 4. B42: started in ready to switch on, runs once enabled
    write(fb, sc, A75, B42_SEL << 1 | 1)
    fb.run_for(0.05)
    a69 = read(fb, sc, A69)
    sc.check(a69 == (B42_SEL << 8 | RUNNING << 12), f"B42 before the enable: A69 {a69} (want running, 0 %)")
    t0 = time.monotonic()
    enable(fb, sc, "B42")
    a69, dt = a69_until(fb, sc, lambda v: v >> 12 not in (0, RUNNING), 20.0)
    sc.check(a69 == (100 | B42_SEL << 8 | DONE << 12), f"B42: A69 {a69} after {ms(dt)} (want done, 100 %)")
    sc.check(read(fb, sc, B42, 1) == 0, "B42[0] = 0")
    r_id, l_id = (read(fb, sc, B53) or 0) * 1e-3, (read(fb, sc, B52) or 0) * 1e-6
    sc.note(f"B42: R {r_id:.4f} ohm (plant {r}), L {l_id * 1e3:.4f} mH (plant {l * 1e3}) in {time.monotonic() - t0:.2f} s")
    sc.check(abs(r_id - r) <= 0.05 * r, f"B53 {r_id} ohm within 5 % of the plant's {r} ohm")
    sc.check(abs(l_id - l) <= 0.05 * l, f"B52 {l_id} H within 5 % of the plant's {l} H")
    stop(fb, sc)
    disable(fb)
    # 5. B300 against the applied brake
    write(fb, sc, A75, B300_SEL << 1 | 1)
    fb.run_for(0.05)
    enable(fb, sc, "B300")
    a69, dt = a69_until(fb, sc, lambda v: v >> 12 not in (0, RUNNING), 10.0)
    sc.check(a69 == (100 | B300_SEL << 8 | DONE << 12), f"B300: A69 {a69} after {ms(dt)} (want done, 100 %)")
    result, moved = read(fb, sc, B300, 1), read(fb, sc, B300, 2)
    sc.note(f"B300: result {result}, largest movement {moved} inc")
    sc.check(result == 0 and moved is not None and moved <= (1 << 20) // 360,
             f"B300: held (result {result}), moved {moved} inc within 1/360 rev")
    stop(fb, sc)
    disable(fb)
    if offset is not None:
        optimise_at_standstill(fb, sc, r, l)
        grind_brake(fb, sc)


def main():
    ap = fb_arguments(__doc__, "drive-ma", "192.168.0.53")
    ap.add_argument("--r", type=float, required=True, help="the plant's phase resistance (serve --plant-r), ohm")
    ap.add_argument("--l", type=float, required=True, help="the plant's inductance (serve --plant-l), H")
    ap.add_argument("--j", type=float, required=True, help="the plant's inertia, kg m^2")
    ap.add_argument("--fc", type=float, required=True, help="the plant's Coulomb friction, N m")
    ap.add_argument("--b", type=float, required=True, help="the plant's viscous friction, N m s/rad")
    ap.add_argument("--offset", type=float, help="the plant's commutation offset (serve --plant-offset), rad: "
                    "B40, B41, B49 and B301 run as well")
    a = ap.parse_args()
    sc = Scenario("E-140")

    def body(fb):
        run(fb, sc, a.r, a.l, a.offset)
        mechanics(fb, sc, a.j, a.fc, a.b)

    return run_fb_scenario(a, sc, body)


if __name__ == "__main__":
    sys.exit(main())
