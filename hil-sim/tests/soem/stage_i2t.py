#!/usr/bin/env python3
"""The current limit and the power stage's i2t through SOEM on the
electrical plant (issue 34; C-038, E-089).

Run by `hil-sim/tests/soem_electrical.rs` as root inside the master's network
namespace against `hil-sim serve --plant electrical --slaves 1` (or by hand).
Free run, one drive, axis A in cst; the maps of motor_protection.py. The
simulated power stage (`foc::Protection::default_stage`): 8 A maximum, 4 A
rated, thermal time constant 5 s; the motor: 2 A rated (6075h), tau 600 s.

  1. 6073h lowered to 25 % by SDO: 6071h = +-100 % (flipped every 10 ms)
     gives 6077h/6078h within 2 % of +-250 and statusword bit 11.
  2. 6073h raised to 500 % (10 A) by SDO (6072h, the max torque, too),
     6071h = +-500 %: the lowest limit
     is now the power stage's maximum, 8 A = 4000 per mille of 6075h:
     |6078h| reaches 4000 (within 2 %), never above it, bit 11 there (the
     free rotor runs into the torque modes' speed limit between the flips,
     so not every frame is at the limit).
  3. The stage's first-order thermal model from (nearly) cold,
     x(t) = u (1 - e^(-t/tau)), u = (i/I_rated)^2 with u taken from the 6078h
     the drive sent: the warning (bit 7) at 80 %, t80 = -tau ln(1 - 0.8/u),
     then the limit to the stage's rated current (|6078h| at most 2000 from
     the first settled frame on after which none was above it) at 100 %,
     t100 = -tau ln(1 - 1/u), each within 3 % + 20 ms (+ the model's 16 ms
     step); the axis stays enabled (the limit is obeyed: no fault).

Prints `FAIL: ...` for every check that failed; exit status 0 when none did.
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import line as L  # noqa: E402
import motor_protection as MP  # noqa: E402
import torque as T  # noqa: E402

say, check = L.say, L.check
TAU_S = 5.0
STAGE_MAX, STAGE_RATED = 4000, 2000  # per mille of 6075h (2 A)
WARNING, LIMIT = MP.WARNING, MP.INTERNAL_LIMIT


def peak(frames, target, what):
    """The limit: |6078h| reaches target (within 2 %) and never goes above
    it; bit 11 in the frames at it. (The free rotor runs into the torque
    modes' speed limit between the flips at these currents, so not every
    frame is at the limit.)"""
    top = max((abs(f[2]) for f in frames), default=0)
    check(len(frames) > 20, f"{what}: {len(frames)} settled frames")
    check(abs(top - target) <= 0.02 * target, f"{what}: max |6078h| {top}, expected {target} (within 2 %)")
    at = [f for f in frames if abs(f[2]) >= 0.98 * target]
    no11 = [f for f in at if not f[3] & LIMIT]
    check(len(no11) <= 0.05 * max(len(at), 1), f"{what}: bit 11 missing in {len(no11)} of the {len(at)} frames at the limit")
    say(f"{what}: 6078h {min(f[2] for f in frames)}..{max(f[2] for f in frames)} over {len(frames)} frames, {len(at)} at the limit")


def run(m, args):
    s = L.one_drive_in_preop(m)
    T.limit_torque(s, 1000)
    L.map_one_pdo_each(s, T.RX, MP.TX)
    axis = L.to_op(m, MP.Axis)
    axis.enable()
    # 1. 6073h lowered
    axis.sdo(0x6073, 0, 250, 2)
    peak(MP.settled(axis.square(1000, 0.2, min_settled=MP.MIN_SETTLED)), 250, "6073h = 25 %")
    # 2. and 3. 6073h (and 6072h, the max torque) raised above the power stage's maximum
    axis.sdo(0x6072, 0, 5000, 2)
    axis.sdo(0x6073, 0, 5000, 2)
    frames = axis.square(5000, 3.0, stop=lambda f: f[3] & MP.FAULT)
    if frames[-1][3] & MP.FAULT:
        # which fault: 603Fh, or the EMCY pysoem raises from the mailbox first
        try:
            why = f"603Fh {L.sdo_u(axis.s, 0x603F, 0):04X}h"
        except Exception as e:  # noqa: BLE001 (pysoem.Emergency and its kin)
            why = f"{type(e).__name__}: {e}"
        check(False, f"no fault while the stage limits: statusword {frames[-1][3]:#06x} after {frames[-1][0]:.3f} s ({why})")
    warn = next((f for f in frames if f[3] & WARNING), None)
    settled = MP.settled(frames)
    # the limit in force from the first settled frame after which none is above the rated current
    above = [k for k, f in enumerate(settled) if abs(f[2]) > 1.02 * STAGE_RATED]
    limited = settled[above[-1] + 1] if above and above[-1] + 1 < len(settled) else None
    if warn is None or limited is None:
        check(False, f"stage i2t: warning {warn}, limit {limited} within 3 s")
        return
    peak([f for f in settled if f[0] < warn[0]], STAGE_MAX, "6073h = 500 %: the power stage's maximum")
    mean_u = lambda t: (lambda fs: sum((f[2] / 2000.0) ** 2 for f in fs) / max(len(fs), 1))([f for f in frames if MP.SETTLE_S <= f[0] < t])
    u80, u100 = mean_u(warn[0]), mean_u(limited[0])
    t80 = -TAU_S * math.log(1.0 - 0.8 / u80)
    t100 = -TAU_S * math.log(1.0 - 1.0 / u100)
    say(f"stage i2t: warning after {warn[0]:.3f} s (closed form with the measured mean (i/I_rated)^2 {u80:.3f}: {t80:.3f} s), limit after {limited[0]:.3f} s ({u100:.3f}: {t100:.3f} s)")
    check(abs(warn[0] - t80) <= 0.03 * t80 + 0.036, f"stage i2t: warning at {warn[0]:.3f} s, closed form {t80:.3f} s")
    check(abs(limited[0] - t100) <= 0.03 * t100 + 0.036, f"stage i2t: limit at {limited[0]:.3f} s, closed form {t100:.3f} s")
    # held at the stage's rated current
    held = MP.settled(axis.square(5000, 0.3, min_settled=MP.MIN_SETTLED))
    peak(held, STAGE_RATED, "stage i2t limiting: its rated current")
    nowarn = [f for f in held if not f[3] & WARNING]
    check(not nowarn, f"stage i2t: bit 7 while limited: missing in {len(nowarn)}")
    check(not any(f[3] & MP.FAULT for f in held), "stage i2t: no fault (the limit is obeyed)")
    L.stop(axis)


L.script(__name__, __doc__, run, "current limit and power-stage i2t on the electrical plant: all checks passed")
