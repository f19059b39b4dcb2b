#!/usr/bin/env python3
"""cst on the electrical plant through SOEM (issue 34, C-038, P-187): 6077h is
the measured current's torque, and it meets 6071h once the current loop has
settled.

Run by `hil-sim/tests/soem_electrical.rs` as root inside the master's network
namespace against `hil-sim serve --plant electrical --slaves 1` (or by hand).
Free run, one drive, axis A, the PDOs of torque.py (6040h, 6060h, 6071h out;
6041h, 6061h, 6077h, 606Ch, 6064h in):

  1. Pre-Op: G472 = G475 = 100 % of I10 by SDO (the torque modes' speed limit
     out of the way); Safe-Op, Op; cst enabled.
  2. For 6071h = 10 %, 50 %, 100 % of the rated torque, each way (+ then -:
     the step back brakes the free rotor through standstill): every frame
     from the fourth after the step (the set-point's arrival, the current
     loop's settling, well under 1 ms at omega_c = 2 pi 1 kHz, and one cycle
     of measurement) until the speed passes half the limit in the torque's
     direction shows 6077h within 2 % of 6071h. On the rigid model the same holds trivially (6077h is the
     demand); on the electrical plant 6077h is kt times the measured iq.

Prints `FAIL: ...` for every check that failed; exit status 0 when none did.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import line as L  # noqa: E402
import torque as T  # noqa: E402  (its Axis and PDO layout)

say, check = L.say, L.check
SETTLE_FRAMES = 3


def step(axis, per_mille, limit, what):
    """6071h = per_mille until the speed passes half the limit in the
    torque's direction (at most 400 frames; the step back first brakes the
    rotor through standstill); checks 6077h from SETTLE_FRAMES on."""
    axis.torque = per_mille
    sign = 1 if per_mille > 0 else -1
    seen = []
    for k in range(400):
        axis.cycle()
        if axis.velocity * sign >= 0.5 * limit:
            break
        if k >= SETTLE_FRAMES:
            seen.append(axis.actual_torque)
    check(len(seen) >= 3, f"{what}: {len(seen)} frames below half the speed limit")
    bad = [t for t in seen if abs(t - per_mille) > 0.02 * abs(per_mille)]
    check(not bad, f"{what}: 6077h within 2 % of {per_mille}: off in {len(bad)} of {len(seen)}: {bad[:8]}")
    say(f"{what}: 6077h {min(seen, default=0)}..{max(seen, default=0)} over {len(seen)} frames, speed {axis.velocity / L.INC_PER_REV:.1f} rev/s")


def run(m, args):
    s = L.one_drive_in_preop(m)
    T.limit_torque(s, 1000)
    L.map_one_pdo_each(s, T.RX, T.TX)
    axis = T.to_op(m)
    axis.enable(T.CST)
    limit = args.i10
    for share in (100, 500, 1000):
        step(axis, share, limit, f"6071h = {share / 10:.0f} %")
        step(axis, -share, limit, f"6071h = -{share / 10:.0f} %")
        axis.torque = 0
        axis.cycle(20)
    L.stop(axis)


L.script(__name__, __doc__, run, "cst on the electrical plant: all checks passed",
         L.required_float("--i10", "I10 maximum speed, inc/s"))
