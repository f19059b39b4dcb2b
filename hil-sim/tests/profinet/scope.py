"""The drive's scope through PROFINET (issue 35): profinet-py (0.6.6) as the
IO controller of `hil-sim serve --fieldbus profinet`, the Example Function
block of fb.py on its cyclic data. The trace is configured and armed through
PKW (group T, PNU = the object's index 4600h + line, element k at subindex
k + 1), recorded during a positioning move, and read back through the trace
records 4700h + k (1 KiB each, docs/profinet.md) as a controller reads any
record; it is written as CSV (time relative to the trigger), the format of
the SOEM script's, so `hil-sim scope-plot` plots it.

Checks (each failure printed in the scenario line):
  - bad input refused through PKW and nothing changed: a channel naming
    A00 (not mappable), a length beyond the buffer; the trace record read
    before a trace is complete refused (state conflict), armed as idle;
  - the trace completes (T00 = 3) after the move starts; T10 says --samples
    per channel and the trigger index --pre % of them; the trace is read in
    records of at most 1024 bytes, the record beyond its end refused.
The physics (the integral of the velocity against the position, the trigger
sample at the edge) is checked by the Rust test on the CSV.

One line:  scenario scope: ok|FAIL: ...
"""

import struct
import sys
import time

from fb import OP, OPMODE_POS, PKW_WRITE, fb_arguments, move, run_fb_scenario
from motor_actions import read, write
from pnctl import Scenario, ms


def t(line):
    return 0x4600 + line


T00, T01, T02, T03, T04, T05, T06, T07, T08, T09, T10, T11 = (t(k) for k in range(12))
IDLE, ARMED, TRIGGERED, COMPLETE = 0, 1, 2, 3
# internal signals: index 0, sub = axis * 10h + n, 32 bits
SPEED_SET, SPEED_ACT, IQ = 0x0120, 0x0220, 0x0420
CHANNELS = [(SPEED_SET, "speed set-point [inc/s]"), (SPEED_ACT, "speed actual [inc/s]"),
            (0x6064_0020, "6064h position actual [inc]"), (IQ, "iq [mA]")]
TRACE_RECORD, PIECE = 0x4700, 1024
A150 = 0x2000 + 150


def refused(fb, index, value, sub=0):
    r = fb.pkw(PKW_WRITE, index, sub, value, timeout=3.0)
    return r is not None and r[0] != PKW_WRITE


def record(dev, index):
    """A record read on the running AR: its bytes, or the exception."""
    # profinet-py connects again before a record access once its last RPC
    # is 10 s old, which would replace the running AR (fb.py, P-206)
    dev._rpc._live_monotonic = time.monotonic()
    try:
        return dev.read(0, 1, index)
    except Exception as e:  # noqa: BLE001 - a refusal is an answer here
        return e


def refusals(fb, sc, dev):
    sc.check(refused(fb, T01, 0x2000_0120, sub=1), "T01[0] = A00 (not mappable): refused")
    sc.check(refused(fb, T04, 10_000_000), "T04 = 10,000,000 samples (beyond the buffer): refused")
    sc.check(read(fb, sc, T01, 1) == 0 and read(fb, sc, T04) == 0, "nothing changed (T01[0] = 0, T04 = 0)")
    r = record(dev, TRACE_RECORD)
    sc.check(isinstance(r, Exception), f"trace record read before any trace: refused ({type(r).__name__})")


def configure(fb, sc, dev, a):
    for k, (code, _) in enumerate(CHANNELS, start=1):
        write(fb, sc, T01, code, sub=k)
    write(fb, sc, T02, len(CHANNELS))
    write(fb, sc, T03, 1)
    write(fb, sc, T04, a.samples)
    write(fb, sc, T05, 1)  # channel 1, the speed set-point
    write(fb, sc, T06, 2)  # rising edge
    write(fb, sc, T07, a.level)
    write(fb, sc, T08, a.pre)
    write(fb, sc, T09, 0)  # single
    write(fb, sc, T00, 1)  # arm
    sc.check(read(fb, sc, T00) == ARMED, "armed: T00 = 1")
    r = record(dev, TRACE_RECORD)
    sc.check(isinstance(r, Exception), f"trace record read while armed: refused ({type(r).__name__})")


def read_trace(fb, sc, dev, a):
    frames, trig = read(fb, sc, T10, 1), read(fb, sc, T10, 2)
    sc.check(frames == a.samples, f"T10[0] samples {frames}, expected {a.samples}")
    want = a.samples * a.pre // 100
    sc.check(trig == want, f"T10[1] trigger index {trig}, expected {want} ({a.pre} %)")
    total = a.samples * len(CHANNELS) * 4
    data = b""
    k = 0
    t0 = time.monotonic()
    while len(data) < total and k < 64:
        piece = record(dev, TRACE_RECORD + k)
        if isinstance(piece, Exception) or not 0 < len(piece) <= PIECE:
            sc.check(False, f"trace record {TRACE_RECORD + k:04X}h: {piece!r}")
            return None, trig
        data += piece
        k += 1
    sc.check(len(data) == total, f"trace {len(data)} bytes in {k} records ({ms(time.monotonic() - t0)}), "
             f"expected {total}")
    r = record(dev, TRACE_RECORD + k)
    sc.check(isinstance(r, Exception), f"record {TRACE_RECORD + k:04X}h beyond the end: refused ({type(r).__name__})")
    n = len(CHANNELS)
    words = struct.unpack(f"<{len(data) // 4}i", data[: len(data) // 4 * 4])
    return [words[i * n:(i + 1) * n] for i in range(a.samples)], trig


def scenario(fb, sc, dev, a):
    refusals(fb, sc, dev)
    cycle_us = read(fb, sc, A150) or 1000
    fb.i.operation_mode = OPMODE_POS
    fb.i.drive_enable = True
    dt = fb.until(lambda o: o.zsw1 & 0x47 == OP, 5.0)
    sc.check(dt is not None, f"operation enabled after {ms(dt)}")
    # homed on the current position (method 34): positioning needs a home
    fb.i.homing_method, fb.i.start_homing = 34, True
    dt = fb.until(lambda o: o.home_valid, 5.0)
    fb.i.start_homing = False
    fb.run_for(0.05)
    sc.check(dt is not None, f"homed (method 34) after {ms(dt)}")
    configure(fb, sc, dev, a)
    # the trigger is taken once the pre-trigger share is recorded
    fb.run_for((a.samples * a.pre // 100) * cycle_us * 1e-6 + 0.2)
    start = fb.o.position_actual_value
    move(fb, sc, "the move under the scope", start + a.distance, 20,
         target_position=start + a.distance, profile_velocity=a.rpm, end_velocity=0)
    state, t0 = None, time.monotonic()
    while time.monotonic() - t0 < 20.0 and state != COMPLETE:
        state = read(fb, sc, T00)
        fb.run_for(0.05)
    sc.check(state == COMPLETE, f"T00 = {state} after the move, expected 3 (complete)")
    if state != COMPLETE:
        return
    rows, trig = read_trace(fb, sc, dev, a)
    if rows is None:
        return
    with open(a.csv, "w") as f:
        f.write("time [ms]," + ",".join(name for _, name in CHANNELS) + "\n")
        for i, r in enumerate(rows):
            f.write(f"{(i - trig) * cycle_us / 1000:.3f}," + ",".join(str(v) for v in r) + "\n")
    sc.note(f"trace: {len(rows)} samples x {len(CHANNELS)} channels every {cycle_us} us, trigger at sample {trig}")
    fb.i.drive_enable = False
    fb.until(lambda o: o.zsw1 & 0x47 != OP, 2.0)


def main():
    ap = fb_arguments(__doc__, "drive-sc", "192.168.0.54")
    ap.add_argument("--csv", required=True, help="where the trace goes (time relative to the trigger)")
    ap.add_argument("--samples", type=int, default=2000, help="samples per channel (T04)")
    ap.add_argument("--pre", type=int, default=20, help="pre-trigger share, %% (T08)")
    ap.add_argument("--level", type=int, default=100_000, help="trigger level on the speed set-point, inc/s (T07)")
    ap.add_argument("--distance", type=int, default=3000, help="the move, 1/1000 rev")
    ap.add_argument("--rpm", type=int, default=300, help="the move's profile velocity, rpm")
    a = ap.parse_args()
    sc = Scenario("scope")
    return run_fb_scenario(a, sc, lambda fb: scenario(fb, sc, fb.dev, a))


if __name__ == "__main__":
    sys.exit(main())
