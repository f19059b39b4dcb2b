#!/usr/bin/env python3
"""The drive's scope through SOEM (issue 35): arm a trace (group T, 4600h +
line) on drive 1, run a known move, wait for the trigger, read the trace back
by segmented SDO upload and write it as CSV.

For people: run it as root in the master's network namespace against
`hil-sim serve` (or a drive) and plot the CSV with
`cargo run -p hil-sim -- scope-plot TRACE.csv` (SVG, and PNG where
`rsvg-convert` or ImageMagick's `convert` runs). Run by `hil-sim/tests/soem_scope.rs`,
which checks the trace against physics.

The move: axis A in profile velocity (pv, 6060h = 3; RxPDO 6040h, 6060h,
60FFh; TxPDO 6041h, 6064h), enabled at standstill, then 60FFh = --speed
inc/s. The trace: 4 channels at every control cycle (T03 = 1): the speed
set-point and the speed actual value (internal signals, inc/s), 6064h
(position actual value, inc) and iq (internal, mA: the current loop's
measurement, the torque that accelerates the rotor);
--samples per channel, triggered on the speed set-point's rising edge
through --level, --pre % before the trigger (T08), single mode.

Checks (SOEM's own SDO calls; each failure printed as FAIL):
  - bad input refused with its abort code: a channel naming A00 (not
    mappable) 0604 0041h, T02 = 9 channels 0609 0031h, a length beyond the
    buffer 0609 0031h; T11 read before the trace is complete 0800 0022h
    (idle and armed);
  - the trace completes (T00 = 3) after the move starts; T10 says --samples
    per channel and the trigger index --pre % of them; the trace is read in
    blocks of at most 4096 bytes (T11) and beyond its end refused 0800 0024h.
The physics (the integral of the velocity against the position, the trigger
sample at the edge) is checked by the Rust test on the CSV.
Prints `FAIL: ...` for every check that failed; exit status 0 when none did.
"""
import argparse
import os
import struct
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import line as L  # noqa: E402

say, check = L.say, L.check


def t(line):
    return 0x4600 + line


T00, T01, T02, T03, T04, T05, T06, T07, T08, T09, T10, T11 = (t(k) for k in range(12))
IDLE, ARMED, TRIGGERED, COMPLETE = 0, 1, 2, 3
RX = [L.entry(0x6040, 0, 16), L.entry(0x6060, 0, 8), L.entry(0x60FF, 0, 32)]
TX = [L.entry(0x6041, 0, 16), L.entry(0x6064, 0, 32)]
OUT, IN = "<Hbi", "<Hi"
PV = 3
# internal signals: index 0, sub = axis * 10h + n, 32 bits
SPEED_SET, SPEED_ACT, IQ = 0x0120, 0x0220, 0x0420
CHANNELS = [(SPEED_SET, "speed set-point [inc/s]"), (SPEED_ACT, "speed actual [inc/s]"),
            (0x6064_0020, "6064h position actual [inc]"), (IQ, "iq [mA]")]
BLOCK = 4096


class Axis(L.FreeRunAxis):
    """Axis A of drive 1 in free run, about 1 ms per frame, in pv."""

    OUT, IN = OUT, IN

    def __init__(self, m):
        super().__init__(m)
        self.cw, self.target = 0, 0
        self.sw = self.pos = 0

    def outputs(self):
        return self.cw, PV, self.target

    def inputs(self, sw, pos):
        self.sw, self.pos = sw, pos


def w(s, index, sub, v, n=4, signed=False):
    s.sdo_write(index, sub, v.to_bytes(n, "little", signed=signed))


def refusals(s):
    """Bad input through SOEM, each with its abort code; nothing armed."""
    cases = [
        ("T01[1] = A00 (not mappable)", lambda: w(s, T01, 1, 0x2000_0108), 0x0604_0041),
        ("T02 = 9 channels", lambda: w(s, T02, 0, 9, 1), 0x0609_0031),
        ("T04 = 1,000,000 samples", lambda: w(s, T04, 0, 1_000_000), 0x0609_0031),
        ("T11[1] read while idle", lambda: s.sdo_read(T11, 1, BLOCK), 0x0800_0022),
    ]
    for what, call, code in cases:
        got = L.sdo_abort(call)
        check(got == code, f"{what}: abort {got if got is None else hex(got)}, expected {code:#010x}")


def configure(s, args):
    for k, (code, _) in enumerate(CHANNELS, start=1):
        w(s, T01, k, code)
    w(s, T02, 0, len(CHANNELS), 1)
    w(s, T03, 0, 1, 2)
    w(s, T04, 0, args.samples)
    w(s, T05, 0, 1, 2)  # channel 1, the speed set-point
    w(s, T06, 0, 2, 1)  # rising edge
    w(s, T07, 0, args.level, 4, signed=True)
    w(s, T08, 0, args.pre, 1)
    w(s, T09, 0, 0, 1)  # single
    w(s, T00, 0, 1, 1)  # arm
    check(L.sdo_u(s, T00, 0) == ARMED, f"armed: T00 = {L.sdo_u(s, T00, 0)}")
    got = L.sdo_abort(lambda: s.sdo_read(T11, 1, BLOCK))
    check(got == 0x0800_0022, f"T11[1] read while armed: abort {got}, expected 0x08000022")


def read_trace(s, args):
    frames, trig = L.sdo_u(s, T10, 1), L.sdo_u(s, T10, 2)
    check(frames == args.samples, f"T10[0] samples {frames}, expected {args.samples}")
    want = args.samples * args.pre // 100
    check(trig == want, f"T10[1] trigger index {trig}, expected {want} ({args.pre} %)")
    total = frames * len(CHANNELS) * 4
    data = b""
    k = 1
    while len(data) < total:
        block = s.sdo_read(T11, k, BLOCK)
        check(0 < len(block) <= BLOCK, f"T11[{k}]: {len(block)} bytes")
        data += block
        k += 1
    check(len(data) == total, f"trace {len(data)} bytes, expected {total}")
    got = L.sdo_abort(lambda: s.sdo_read(T11, k, BLOCK))
    check(got == 0x0800_0024, f"T11[{k}] beyond the end: abort {got}, expected 0x08000024")
    n = len(CHANNELS)
    words = struct.unpack(f"<{len(data) // 4}i", data[: len(data) // 4 * 4])
    return [words[i * n:(i + 1) * n] for i in range(frames)], trig


def run(m, args):
    L.scan(m, 1)
    check(m.read_state() == L.PREOP, f"Pre-Op: {L.state_report(m)}")
    s = m.slaves[0]
    L.map_one_pdo_each(s, RX, TX)
    refusals(s)
    axis = L.to_op(m, Axis)
    cycle_us = L.sdo_u(s, 0x2000 + 150, 0)
    for cw in (6, 7, 0xF):
        axis.cw = cw
        axis.cycle(30)
    check(L.sw_is(axis.sw, L.ENABLED), f"enabled: statusword {axis.sw:#06x}")
    configure(s, args)
    # the trigger is taken once the pre-trigger share is recorded (an edge
    # before it is history): at 1 ms per frame or more, wait that long
    axis.cycle(args.samples * args.pre // 100 + 200)
    axis.target = args.speed
    start = time.monotonic()
    state = ARMED
    while time.monotonic() - start < 30.0 and state != COMPLETE:
        axis.cycle(50)
        state = L.sdo_u(s, T00, 0)
    if state != COMPLETE:
        vals = {f"{i:04X}h": int.from_bytes(s.sdo_read(i, 0), "little", signed=True) for i in (0x6041, 0x6061, 0x6064, 0x606C, 0x60FF, 0x6083)}
        say(f"not complete: statusword {axis.sw:#06x}, {vals}")
    check(state == COMPLETE, f"T00 = {state} 30 s after the move started, expected 3 (complete)")
    if state != COMPLETE:
        return
    rows, trig = read_trace(s, args)
    say(f"trace: {len(rows)} samples x {len(CHANNELS)} channels every {cycle_us} us, trigger at sample {trig}, "
        f"read in {(len(rows) * len(CHANNELS) * 4 + BLOCK - 1) // BLOCK} blocks")
    with open(args.csv, "w") as f:
        f.write("time [ms]," + ",".join(name for _, name in CHANNELS) + "\n")
        for i, r in enumerate(rows):
            f.write(f"{(i - trig) * cycle_us / 1000:.3f}," + ",".join(str(v) for v in r) + "\n")
    axis.target = 0
    axis.cycle(300)
    axis.cw = 0
    axis.cycle(20)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--iface", required=True)
    ap.add_argument("--csv", required=True, help="where the trace goes (time relative to the trigger)")
    ap.add_argument("--samples", type=int, default=2000, help="samples per channel (T04)")
    ap.add_argument("--pre", type=int, default=20, help="pre-trigger share, %% (T08)")
    ap.add_argument("--level", type=int, default=100_000, help="trigger level on the speed set-point, inc/s (T07)")
    ap.add_argument("--speed", type=int, default=2_000_000, help="the move's target velocity 60FFh, inc/s")
    args = ap.parse_args()
    return L.master_main(args, run, "scope through SOEM: all checks passed")


if __name__ == "__main__":
    sys.exit(main())
