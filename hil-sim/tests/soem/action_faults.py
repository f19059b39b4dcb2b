#!/usr/bin/env python3
"""The motor actions against a faulty plant through SOEM (issue 35; E-140,
E-141): each fault of the motor, its wiring or its brake makes the action
that checks it fail with its result code, and nothing else changes.

Run by `hil-sim/tests/soem_electrical.rs` as root inside the master's network
namespace against `hil-sim serve --plant electrical --plant-fault FAULT
--slaves 1` (or by hand), with the same --fault. Free run, one drive, axis A
in cst; RxPDO 6040h, 6060h, A75; TxPDO 6041h, A69 (as motor_actions.py).

  swapped-phases      B40 (1010b, test phase): the rotor turns backwards,
                      B40[0] = 7, the count over the turn negative
  reversed-encoder    B40: the rotor turns forwards, counted backwards:
                      B40[0] = 7, B40[1] -2^20/4 (4 pole pairs) within 1 %
  open-phase          B43 (1101b, test winding, no enable): B43[0] = 2 (no
                      current), E48 still 2; then B40: B40[0] = 2
  unbalanced-winding  B43: B43[0] = 6, the resistances along U, V, W those of
                      phase V 10 % high, (R_x + R_y||R_z)/1.5: 1.016 R,
                      1.067 R, 1.016 R within 1 % of R
  slipping-brake      B300 (0100b, test brake): the brake (1.0 N m) slips
                      under the rated torque: B300[0] = 9, the movement
                      beyond 1/360 rev, the axis enabled again (E48 = 4)
  stuck-brake         B301 (0101b, grind brake): ground, not released:
                      B301[0] = 11, each grind phase 0.8 of 2^19 inc, the
                      released one below a tenth of 2^18

Each action is started as an engineer does (A75 = Execute | selector in
Ready to switch on, the enable where it needs one) and followed in A69 until
it leaves running. Then, for each: A69 failed with the selector shown, no
fault (603Fh 0, no new message in 10F3h), the motor data (B05, B52, B53,
B62) as before, Execute low gives A69 idle, and the axis enables again
(Operation enabled, held 0.1 s). Prints `ROW <order> <seen>` (the end in
the fault matrix' words, docs/fault-matrix.md), `FAIL: ...` for every check
that failed; exit status 0 when none did.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import line as L  # noqa: E402
import motor_actions as M  # noqa: E402

say, check = L.say, L.check
FAILED, IDLE = 5, 0
STATES = {0: "idle", 1: "running", 2: "done", 3: "refused", 4: "not available", 5: "failed"}
# the fault matrix' order of each case (hil-sim/tests/soem_electrical.rs)
ORDER = {
    "swapped-phases": "65",
    "reversed-encoder": "66",
    "open-phase": "67",
    "unbalanced-winding": "68",
    "slipping-brake": "69",
    "stuck-brake": "70",
}
PER_TURN = (1 << 20) // 4


def motor_data(s):
    return tuple(L.sdo_u(s, i, 0) for i in (M.B05, M.B52, M.B53, M.B62))


def a69_text(a69, sel):
    shown = "the selector shown" if a69 >> 8 & 0xF == sel else f"selector {a69 >> 8 & 0xF:04b}b shown"
    return f"A69 {STATES.get(a69 >> 12, a69 >> 12)} ({shown})"


def run_winding(axis):
    """B43 in Ready to switch on, no enable; A69 until it leaves running."""
    M.ready(axis)
    axis.a75 = M.B43_SEL << 1 | 1
    seen = []
    for _ in range(10_000):
        axis.cycle()
        if not seen or seen[-1] != axis.a69:
            seen.append(axis.a69)
        if axis.a69 >> 12 not in (IDLE, M.RUNNING):
            break
    e48 = L.sdo_u(axis.s, M.E48, 0)
    return seen, f"E48 {e48} throughout" if e48 == 2 else f"E48 {e48} after it"


def action(axis, sel):
    """Runs `sel`: its A69 (the last seen), a text of the end."""
    if sel == M.B43_SEL:
        seen, e48 = run_winding(axis)
        extra = [e48]
    else:
        seen, _ = M.start(axis, sel)
        extra = []
    say(f"{sel:04b}: A69 seen {[f'{s:04X}' for s in seen]}")
    return seen[-1], extra


def b40(axis, words, fault):
    a69, _ = action(axis, M.B40_SEL)
    code = L.sdo_u(axis.s, M.B40, 1)
    per_turn = int.from_bytes(axis.s.sdo_read(M.B40, 2), "little", signed=True)
    say(f"B40 ({fault}): result {code}, {per_turn} inc per electrical turn")
    words.append(f"B40: {a69_text(a69, M.B40_SEL)}, B40[0] {code}")
    if code == 7:
        if fault == "reversed-encoder":
            ok = abs(per_turn + PER_TURN) <= PER_TURN // 100
            words.append("the count -2^20/4" if ok else f"the count {per_turn}")
        else:
            words.append("the count negative" if per_turn < 0 else f"the count {per_turn}")
    return a69


def b43(axis, words, fault, r):
    a69, extra = action(axis, M.B43_SEL)
    code = L.sdo_u(axis.s, M.B43, 1)
    words.append(f"B43: {a69_text(a69, M.B43_SEL)}, B43[0] {code}, " + ", ".join(extra))
    if fault == "unbalanced-winding":
        rs = [L.sdo_u(axis.s, M.B43, k) * 1e-3 for k in (2, 3, 4)]
        say(f"B43 ({fault}): resistances along U, V, W {rs} ohm (plant {r} ohm, V 10 % high)")
        want = (1.0159 * r, 1.0667 * r, 1.0159 * r)
        ok = all(abs(x - w) < 0.01 * r for x, w in zip(rs, want))
        words.append("U, V, W 1.016 R, 1.067 R, 1.016 R" if ok else "U, V, W " + ", ".join(f"{x / r:.3f} R" for x in rs))
    else:
        say(f"B43 ({fault}): result {code}")
    return a69


def b300(axis, words):
    a69, _ = action(axis, M.B300_SEL)
    code, moved = L.sdo_u(axis.s, M.B300, 1), L.sdo_u(axis.s, M.B300, 2)
    e48 = L.sdo_u(axis.s, M.E48, 0)
    say(f"B300: result {code}, largest movement {moved} inc, E48 {e48}")
    slipped = "beyond" if moved > (1 << 20) // 360 else "within"
    words.append(f"B300: {a69_text(a69, M.B300_SEL)}, B300[0] {code}, moved {slipped} 1/360 rev, E48 {e48}")
    return a69


def b301(axis, words):
    a69, _ = action(axis, M.B301_SEL)
    code, grind, released = (L.sdo_u(axis.s, M.B301, k) for k in (1, 2, 3))
    say(f"B301: result {code}, smallest grind travel {grind} inc, released {released} inc")
    ground = "ground" if grind >= 0.8 * (1 << 19) else f"grind travel {grind} inc"
    freed = "not released" if released < 0.1 * (1 << 18) else f"released {released} inc"
    words.append(f"B301: {a69_text(a69, M.B301_SEL)}, B301[0] {code}, {ground}, {freed}")
    return a69


def afterwards(axis, words, before, history):
    """Nothing else changed: no fault, the motor data, A69 idle, the enable."""
    fault = L.sdo_u(axis.s, 0x603F, 0)
    newest = L.sdo_u(axis.s, 0x10F3, 2)
    same = motor_data(axis.s) == before
    words.append(
        f"603Fh {fault:04X}h; history: {'no new message' if newest == history else 'new message'}; "
        f"B05, B52, B53, B62 {'unchanged' if same else 'changed'}"
    )
    M.execute_low(axis)
    words.append(f"Execute low: A69 {STATES.get(axis.a69 >> 12, axis.a69)}")
    M.switch_on_and_enable(axis)
    enabled = axis.until(lambda: L.sw_is(axis.sw, L.ENABLED), 300)
    axis.cycle(100)
    held = enabled and L.sw_is(axis.sw, L.ENABLED)
    words.append("the enable: Operation enabled" if held else f"the enable: statusword {axis.sw:#06x}")
    axis.cw = 6
    axis.cycle(20)


# the action(s) of each fault, the result code each must give
CASES = {
    "swapped-phases": [("B40", 7)],
    "reversed-encoder": [("B40", 7)],
    "open-phase": [("B43", 2), ("B40", 2)],
    "unbalanced-winding": [("B43", 6)],
    "slipping-brake": [("B300", 9)],
    "stuck-brake": [("B301", 11)],
}


def run(m, args):
    s = L.one_drive_in_preop(m)
    L.map_one_pdo_each(s, M.RX, M.TX)
    axis = L.to_op(m, M.Axis)
    before = motor_data(axis.s)
    history = L.sdo_u(axis.s, 0x10F3, 2)
    words = []
    for name, code in CASES[args.fault]:
        if name == "B40":
            a69 = b40(axis, words, args.fault)
            got = L.sdo_u(axis.s, M.B40, 1)
        elif name == "B43":
            a69 = b43(axis, words, args.fault, args.r)
            got = L.sdo_u(axis.s, M.B43, 1)
        elif name == "B300":
            a69 = b300(axis, words)
            got = L.sdo_u(axis.s, M.B300, 1)
        else:
            a69 = b301(axis, words)
            got = L.sdo_u(axis.s, M.B301, 1)
        check(a69 >> 12 == FAILED, f"{args.fault}: {name} A69 {a69:04X}h, expected failed")
        check(got == code, f"{args.fault}: {name}[0] {got}, expected {code}")
        afterwards(axis, words, before, history)
    L.stop(axis)
    print(f"ROW {ORDER[args.fault]} " + "; ".join(words), flush=True)


L.script(__name__, __doc__, run, "motor actions against the plant's fault: all checks passed",
         ("--fault", dict(required=True, choices=sorted(CASES), help="serve's --plant-fault")),
         ("--r", dict(type=float, default=3.6, help="the plant's phase resistance, ohm")))
