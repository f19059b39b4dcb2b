#!/usr/bin/env python3
"""Motor data, the current limit and the motor i2t through SOEM on the
electrical plant (issue 34; C-038, E-089).

Run by `hil-sim/tests/soem_electrical.rs` as root inside the master's network
namespace against `hil-sim serve --plant electrical --slaves 1` (or by hand).
Free run, one drive, axis A; RxPDO 6040h, 6060h, 6071h; TxPDO 6041h, 6061h,
6077h, 6078h, 606Ch.

  1. Pre-Op, the motor data by SDO: 6076h reads kt (B17) x 6075h = 1300 mNm;
     6075h = 0, B10 = 0 (pole pairs) are refused with 0609 0032h and B64 (the
     current loop's bandwidth) above a fifth of the PWM rate with 0609 0031h,
     each changing nothing. B73 (thermal time constant) = --tau-ms, U11 (i2t
     warning time) = --u11-ms, G472 = G475 = 100 % of I10.
  2. cst, 6073h (max current) lowered to 50 % by SDO in Op: 6071h = +-100 %
     (the sign flipped every 10 ms, so the free rotor stays slow) gives 6077h
     and 6078h (kt x measured iq, measured iq; both per mille of 6076h/6075h)
     never above 500 + 2 % and within 2 % of +-500 in 95 % of the frames once
     the current loop settled, statusword bit 11 set.
     6073h back to 300 %.
  3. i2t: 6071h = +-200 % (flipped every 10 ms: i^2 stays (2 I_r)^2 but the
     rotor stays below half the speed limit). The first-order thermal model
     from cold, x(t) = u (1 - e^(-t/tau)) with u = (i/I_r)^2, reaches 100 % at
         t100 = -tau ln(1 - 1/u)
     (u = 4: t100 = 0.2877 tau). u is taken from the 6078h the drive sent
     (the mean of (6078h/1000)^2 over all frames before the warning: the
     current flips through zero every 10 ms, which lowers the mean a little);
     the warning (statusword bit 7) must come within 3 % + 20 ms of t100.
     Then the current is limited to the rated current (|6078h| never above
     1000 + 2 %, within 2 % of 1000 in 95 % of the settled frames, bit 11), and U11 after the warning the axis faults:
     603Fh = 4380h, EMCY 4380h / error register bit 3 (temperature), E82
     event 45.

Prints `FAIL: ...` for every check that failed; exit status 0 when none did.
"""
import math
import os
import struct
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import line as L  # noqa: E402
import torque as T  # noqa: E402  (its RX layout, limit_torque)

say, check = L.say, L.check


def b(line):
    return 0x2000 + 1 * 0x200 + line


def u_(line):
    return 0x2000 + 20 * 0x200 + line


B10, B17, B64, B73 = b(10), b(17), b(64), b(73)
U10, U11 = u_(10), u_(11)
TX = [L.entry(0x6041, 0, 16), L.entry(0x6061, 0, 8), L.entry(0x6077, 0, 16), L.entry(0x6078, 0, 16), L.entry(0x606C, 0, 32)]
OUT = "<HbH"
IN = "<Hbhhi"
WARNING, INTERNAL_LIMIT, FAULT = 1 << 7, 1 << 11, 1 << 3
ABORT_TOO_LOW, ABORT_TOO_HIGH = 0x06090032, 0x06090031
FLIP_S = 0.010
SETTLE_S = 0.004
SETTLE_FRAMES = 4
# a half period has at least this many frames (SETTLE_FRAMES + 6 settled)
FLIP_FRAMES = 10
# settled frames the fixed-length square waves collect at least
MIN_SETTLED = 60


class Axis:
    """Axis A of drive 1 in free run, about 1 ms per frame."""

    def __init__(self, m):
        self.m, self.s = m, m.slaves[0]
        self.cw, self.mode, self.torque = 0, T.CST, 0
        self.sw = self.display = self.actual_torque = self.current = self.velocity = 0

    def cycle(self, k=1):
        for _ in range(k):
            self.s.output = struct.pack(OUT, self.cw, self.mode, self.torque & 0xFFFF)
            self.m.send_processdata()
            self.m.receive_processdata(4000)
            n = struct.calcsize(IN)
            if len(self.s.input) >= n:
                self.sw, self.display, self.actual_torque, self.current, self.velocity = struct.unpack(IN, bytes(self.s.input[:n]))
            time.sleep(0.001)

    def enable(self):
        L.enable_sequence(self)
        self.cycle(5)
        check(self.display == T.CST, f"6061h shows {self.display} in cst")

    def sdo(self, index, sub, value, n):
        L.write(self.m, 0, index, sub, value.to_bytes(n, "little"))
        self.cycle(2)

    def square(self, per_mille, seconds, stop=None, min_settled=0):
        """6071h = +-per_mille, the sign flipped every FLIP_S (the first half
        period FLIP_S/2) but after FLIP_FRAMES frames at the earliest; frames
        as (t since start, 6077h, 6078h, 6041h, s since the last flip) until
        `seconds` and min_settled settled frames (at most 20 x `seconds`), or
        stop(frame). Counting frames too keeps the settled frames of a half
        period when a loaded machine stretches the master's cycle (9 settled
        frames in 0.2 s were seen with 1 ms frames taking 5 ms)."""
        start = time.monotonic()
        frames = []
        flipped = 0
        flip_t = -FLIP_S / 2
        n_settled = 0
        want = per_mille
        while True:
            t = time.monotonic() - start
            if t >= seconds and (n_settled >= min_settled or t >= 20 * seconds):
                break
            if t - flip_t >= FLIP_S and len(frames) - flipped >= FLIP_FRAMES:
                want = -want
                flip_t = t
                flipped = len(frames)
            self.torque = want
            since_flip = t - flip_t
            self.cycle()
            # settled: SETTLE_S since the flip and SETTLE_FRAMES frames (a
            # frame delayed on a loaded machine carries an older value)
            if len(frames) - flipped < SETTLE_FRAMES:
                since_flip = 0.0
            f = (time.monotonic() - start, self.actual_torque, self.current, self.sw, since_flip, self.torque)
            frames.append(f)
            n_settled += len(settled([f]))
            if stop and stop(f):
                break
        self.torque = 0
        return frames


def settled(frames):
    return [f for f in frames if f[4] >= SETTLE_S and f[0] >= SETTLE_S]


def motor_data(s, tau_ms, u11_ms):
    check(L.sdo_u(s, 0x6076, 0) == 1300, "6076h = kt (B17 650 mNm/A) x 6075h (2000 mA) = 1300 mNm")
    for index, value, n, want, what in (
        (0x6075, 0, 4, ABORT_TOO_LOW, "6075h rated current 0"),
        (B10, 0, 1, ABORT_TOO_LOW, "B10 pole pairs 0"),
        (B64, 3201, 2, ABORT_TOO_HIGH, "B64 bandwidth above 16 kHz / 5"),
    ):
        before = L.sdo_u(s, index, 0)
        code = L.sdo_abort(lambda: s.sdo_write(index, 0, value.to_bytes(n, "little")))
        check(code == want, f"{what}: abort {code}, expected {want:#010x}")
        check(L.sdo_u(s, index, 0) == before, f"{what}: {index:04X}h unchanged ({before})")
    check(L.sdo_u(s, U10, 0) == 2, "U10 = 2 (warning) by default")
    s.sdo_write(B73, 0, tau_ms.to_bytes(4, "little"))
    s.sdo_write(U11, 0, u11_ms.to_bytes(2, "little"))
    T.limit_torque(s, 1000)


def current_limit(axis):
    axis.sdo(0x6073, 0, 500, 2)
    frames = settled(axis.square(1000, 0.2, min_settled=MIN_SETTLED))
    bad = [(t, c) for _, t, c, _, _, d in frames if abs(t - 500 * (1 if d > 0 else -1)) > 10 or abs(c - 500 * (1 if d > 0 else -1)) > 10]
    over = [(t, c) for _, t, c, _, _, _ in frames if max(abs(t), abs(c)) > 510]
    check(len(frames) > 30, f"6073h = 50 %: {len(frames)} settled frames")
    check(not over, f"6073h = 50 %: |6077h|, |6078h| never above 500 + 2 %: above in {len(over)}: {over[:6]}")
    check(len(bad) <= 0.05 * len(frames), f"6073h = 50 %: 6077h/6078h within 2 % of +-500 in 95 % of the settled frames (a frame delayed on a loaded machine may carry a flip): off in {len(bad)}: {bad[:6]}")
    no11 = [sw for _, _, _, sw, _, _ in frames if not sw & INTERNAL_LIMIT]
    check(len(no11) <= 0.05 * len(frames), f"6073h = 50 %: statusword bit 11 in the settled frames: missing in {len(no11)} of {len(frames)}")
    say(f"6073h = 50 %: 6077h {min(f[1] for f in frames)}..{max(f[1] for f in frames)}, 6078h {min(f[2] for f in frames)}..{max(f[2] for f in frames)} over {len(frames)} frames")
    axis.sdo(0x6073, 0, 3000, 2)
    axis.cycle(20)


def i2t(m, axis, emcys, tau_s, u11_s):
    emcys.drain(m, 0)
    frames = axis.square(2000, 3 * tau_s, stop=lambda f: f[3] & (WARNING | FAULT))
    warned = frames[-1]
    check(warned[3] & WARNING and not warned[3] & FAULT, f"i2t: warning (bit 7) first, statusword {warned[3]:#06x}")
    # every frame: the drive's model integrates the flips through zero too
    before = [f for f in frames[:-1] if f[0] >= SETTLE_S]
    mean_u = sum((f[2] / 1000.0) ** 2 for f in before) / max(len(before), 1)
    t_closed = -tau_s * math.log(1.0 - 1.0 / mean_u)
    t_nominal = -tau_s * math.log(1.0 - 1.0 / 4.0)
    t_warn = warned[0]
    say(f"i2t: warning after {t_warn:.3f} s; closed form with the measured mean (i/I_r)^2 = {mean_u:.3f}: {t_closed:.3f} s (with u = 4: {t_nominal:.3f} s)")
    check(abs(t_warn - t_closed) <= 0.03 * t_closed + 0.02, f"i2t: warning at {t_warn:.3f} s, closed form {t_closed:.3f} s")
    # the limit: |6078h| held at the rated current until the fault
    frames = axis.square(2000, u11_s + 0.5, stop=lambda f: f[3] & FAULT)
    fault_after = frames[-1][0]
    check(frames[-1][3] & FAULT, f"i2t: fault within U11 + 0.5 s: statusword {frames[-1][3]:#06x}")
    check(abs(fault_after - u11_s) <= 0.1, f"i2t: fault {fault_after:.3f} s after the warning, U11 = {u11_s:.3f} s")
    held = [f for f in settled(frames[:-1]) if f[0] > 0.05]
    over = [f[2] for f in held if abs(f[2]) > 1020]
    check(len(held) > 20 and not over, f"i2t: |6078h| never above 1000 + 2 % (the rated current) while limited: above in {len(over)} of {len(held)}: {over[:6]}")
    bad = [f[2] for f in held if abs(abs(f[2]) - 1000) > 20]
    check(len(bad) <= 0.05 * len(held), f"i2t: |6078h| within 2 % of 1000 in 95 % of the settled frames: off in {len(bad)} of {len(held)}: {bad[:6]}")
    no11 = [f for f in held if not f[3] & INTERNAL_LIMIT]
    check(len(no11) <= 0.05 * len(held), f"i2t: bit 11 while limited: missing in {len(no11)} of {len(held)}")
    code = L.sdo_u(axis.s, 0x603F, 0)
    check(code == 0x4380, f"i2t: 603Fh = {code:04X}h, expected 4380h (event 45)")
    got = emcys.drain(m, 0, 1.0)
    text = [f"{e.error_code:04X}h/{e.error_reg:02X}h event {e.b1}" for e in got]
    check(any(e.error_code == 0x4380 and e.error_reg & 0x08 and e.b1 == 45 for e in got), f"i2t: EMCY 4380h, register bit 3, event 45: {text}")
    say(f"i2t: fault {fault_after:.3f} s after the warning, 603Fh {code:04X}h, EMCY {text}")


def run(m, args):
    s = L.one_drive_in_preop(m)
    emcys = L.Emcys(m)
    motor_data(s, args.tau_ms, args.u11_ms)
    L.map_one_pdo_each(s, T.RX, TX)
    axis = L.to_op(m, Axis)
    axis.enable()
    current_limit(axis)
    i2t(m, axis, emcys, args.tau_ms / 1000.0, args.u11_ms / 1000.0)
    L.stop(axis)


L.script(__name__, __doc__, run, "motor protection on the electrical plant: all checks passed",
         ("--tau-ms", dict(type=int, default=4000, help="B73 thermal time constant, ms")),
         ("--u11-ms", dict(type=int, default=500, help="U11 i2t warning time, ms")))
