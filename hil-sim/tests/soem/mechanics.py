#!/usr/bin/env python3
"""B44 "identify mechanics" through SOEM on the electrical plant (issue 35;
E-140, E-141; A75 selector 1111b, ours): A75 in the RxPDO, A69 in the
TxPDO, the figures by SDO.

Run by `hil-sim/tests/soem_electrical.rs` as root inside the master's network
namespace against `hil-sim serve --plant electrical --slaves 1` (or by hand),
with --j, --fc, --b the plant's inertia and friction, which the drive does
not know (B45 = B46 = B47 = 0). Free run, one drive, axis A in cst (the
layout of motor_actions.py).

  1. Op, the axis switch-on disabled: A75 = Execute | 1111b is refused
     (A69 state 3), B45...B47 and C31 unchanged.
  2. Software limits 607Dh = -1000 ... +1000 around the axis at 0: started in
     ready to switch on and enabled, B44 is refused before it moves (A69
     state 3, B44[0] = 12), 6064h unchanged. The limits off again (0, 0).
  3. Started in ready to switch on and enabled: A69 running, its progress
     rising, then done at 100 %; B44[0] = 0, B45 within 5 % of --j, B46 and B47
     within 10 % of --fc and --b, C31 = J * 2 pi B48 / (250 us / A150),
     back within 1/100 rev of the start. Execute low: A69 idle.

Prints `FAIL: ...` for every check that failed; exit status 0 when none did.
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import line as L  # noqa: E402
import motor_actions as M  # noqa: E402

say, check = L.say, L.check

B44, B45, B46, B47, B48 = (M.b(k) for k in (44, 45, 46, 47, 48))
C31 = 0x2000 + 2 * 0x200 + 31
A150 = 0x2000 + 150
SEL = 0b1111


def tuning(s):
    return [L.sdo_u(s, i, 0) for i in (B45, B46, B47, C31)]


def position(s):
    return int.from_bytes(s.sdo_read(0x6064, 0), "little", signed=True)


def refused_switch_on_disabled(axis):
    before = tuning(axis.s)
    axis.a75 = SEL << 1 | 1
    axis.cycle(10)
    want = SEL << 8 | M.REFUSED << 12
    check(axis.a69 == want, f"B44 switch-on disabled: A69 {axis.a69:04X}h, expected {want:04X}h (refused)")
    check(tuning(axis.s) == before, f"refused B44 changed nothing: {tuning(axis.s)} vs {before}")
    axis.a75 = 0
    axis.cycle(5)


def refused_beyond_the_limits(axis):
    at = position(axis.s)
    axis.s.sdo_write(0x607D, 1, (at - 1000).to_bytes(4, "little", signed=True))
    axis.s.sdo_write(0x607D, 2, (at + 1000).to_bytes(4, "little", signed=True))
    seen, _ = M.start(axis, SEL)
    want = SEL << 8 | M.REFUSED << 12
    check(seen[-1] == want, f"B44 beyond 607Dh: A69 ends {seen[-1]:04X}h, expected {want:04X}h; seen {[f'{s:04X}' for s in seen]}")
    check(L.sdo_u(axis.s, B44, 1) == 12, f"B44[0] {L.sdo_u(axis.s, B44, 1)}, expected 12 (limit)")
    moved = abs(position(axis.s) - at)
    check(moved < 100, f"B44 refused: the axis moved {moved} inc")
    say(f"B44 beyond the software limits: refused (A69 {seen[-1]:04X}h, B44[0] 12), moved {moved} inc")
    M.execute_low(axis)
    for sub in (1, 2):
        axis.s.sdo_write(0x607D, sub, (0).to_bytes(4, "little", signed=True))


def identify(axis, j, fc, b):
    at = position(axis.s)
    seen, took = M.start(axis, SEL)
    result = L.sdo_u(axis.s, B44, 1)
    M.check_done("B44", SEL, seen, f"; B44[0] {result}")
    check(all((a & 0xFF) <= (b_ & 0xFF) for a, b_ in zip(seen, seen[1:])), f"B44: progress rises: {[f'{s:04X}' for s in seen]}")
    check(result == 0, f"B44[0] result {result}, expected 0")
    j_id, fc_id, b_id, c31 = tuning(axis.s)
    j_id, fc_id, b_id = j_id * 1e-7, fc_id * 1e-6, b_id * 1e-9
    err = lambda x, y: (x - y) / y * 100.0  # noqa: E731
    say(f"B44: J {j_id:.4e} kg m2 ({err(j_id, j):+.2f} %), Fc {fc_id:.4f} N m ({err(fc_id, fc):+.2f} %), "
        f"B {b_id:.3e} N m s/rad ({err(b_id, b):+.2f} %), excursion {L.sdo_u(axis.s, B44, 2)} inc, in {took:.2f} s")
    check(abs(err(j_id, j)) <= 5.0, f"B45 {j_id} not within 5 % of {j}")
    check(abs(err(fc_id, fc)) <= 10.0, f"B46 {fc_id} not within 10 % of {fc}")
    check(abs(err(b_id, b)) <= 10.0, f"B47 {b_id} not within 10 % of {b}")
    r = min(1.0, 250.0 / L.sdo_u(axis.s, A150, 0))
    kp = j_id * 2 * math.pi * L.sdo_u(axis.s, B48, 0) / r
    check(abs(c31 * 1e-6 - kp) <= 1e-3 * kp + 2e-6, f"C31 {c31} vs J ω / r = {kp * 1e6:.0f} µN m s/rad")
    back = abs(position(axis.s) - at)
    check(back < (1 << 20) // 100, f"B44: {back} inc from the start at the end")
    M.execute_low(axis, "B44")


def run(m, args):
    s = L.one_drive_in_preop(m)
    L.map_one_pdo_each(s, M.RX, M.TX)
    axis = L.to_op(m, M.Axis)
    refused_switch_on_disabled(axis)
    refused_beyond_the_limits(axis)
    identify(axis, args.j, args.fc, args.b)
    L.stop(axis)


L.script(__name__, __doc__, run, "B44 identify mechanics on the electrical plant: all checks passed",
         L.required_float("--j", "the plant's inertia, kg m2"),
         L.required_float("--fc", "the plant's Coulomb friction, N m"),
         L.required_float("--b", "the plant's viscous friction, N m s/rad"))
