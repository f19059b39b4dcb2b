#!/usr/bin/env python3
"""Checks in the style of the ETG conformance test tool, written on SOEM's
low-level API (pysoem's register access `_fprd`/`_fpwr`), against `hil-sim
serve` over raw Ethernet (issue 33). Run by `hil-sim/tests/soem_conformance.rs`
as root inside the master's network namespace (or by hand against `serve`).

  --case op-repeat  E-033/E-047: Safe-Op -> Op that cannot succeed (A258 =
                    100 ms, no process data): refused with 002Bh whether the
                    master writes AL control once or every 5 ms (a repeated
                    identical request does not restart the drive's wait).

Exit status 0 when every check passed; each failed check is printed.
"""
import argparse
import os
import struct
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import line as L  # noqa: E402  (line.py beside this file)
import pysoem  # noqa: E402

say, check = L.say, L.check
INIT, PREOP, SAFEOP, OP, ERR, ACK = L.INIT, L.PREOP, L.SAFEOP, L.OP, L.ERR, L.ACK
AL_CONTROL, AL_STATUS, AL_CODE = 0x0120, 0x0130, 0x0134
A258 = 0x2000 + 258
TIMEOUT_US = 20_000


def rd(s, ado, n):
    """FPRD with SOEM's repetition (a frame lost on a loaded machine)."""
    for _ in range(5):
        try:
            return s._fprd(ado, n, TIMEOUT_US)
        except pysoem.WkcError:
            time.sleep(0.002)
    raise L.Fatal(f"FPRD {ado:#06x}: no answer")


def wr(s, ado, data):
    for _ in range(5):
        try:
            s._fpwr(ado, data, TIMEOUT_US)
            return
        except pysoem.WkcError:
            time.sleep(0.002)
    raise L.Fatal(f"FPWR {ado:#06x}: no answer")


def al(s):
    """(AL status, AL status code) read by one FPRD of 0x0130..0x0135."""
    raw = rd(s, AL_STATUS, 6)
    return raw[0], struct.unpack_from("<H", raw, 4)[0]


def control(s, value):
    wr(s, AL_CONTROL, struct.pack("<H", value))


def to(s, value, want, timeout_s=3.0):
    """AL control `value` written once; the AL status until it shows `want`
    (state bits) or an error; (status, code)."""
    control(s, value)
    end = time.monotonic() + timeout_s
    while True:
        st, code = al(s)
        if (st & 0x0F) == want or st & ERR or time.monotonic() > end:
            return st, code
        time.sleep(0.005)


def to_safeop(m, s):
    """From Pre-Op (after the scan): SOEM's map, Safe-Op."""
    m.manual_state_change = 1
    m.config_map()
    st, code = to(s, SAFEOP, SAFEOP)
    if st != SAFEOP:
        raise L.Fatal(f"Safe-Op not reached: {st:#04x}/{code:04X}h")


def case_op_repeat(m):
    s = m.slaves[0]
    s.sdo_write(A258, 0, struct.pack("<H", 100))
    to_safeop(m, s)
    for every_ms in (None, 5, 1):
        how = "written once" if every_ms is None else f"rewritten every {every_ms} ms"
        t0 = time.monotonic()
        control(s, OP)
        writes, seen = 1, []
        while time.monotonic() - t0 < 3.0:
            if every_ms is not None:
                control(s, OP)
                writes += 1
            st, code = al(s)
            seen.append((time.monotonic() - t0, st, code))
            if st & ERR:
                break
            time.sleep((every_ms or 5) / 1000)
        dt, st, code = seen[-1]
        say(f"Op {how}: {st:#04x}/{code:04X}h after {dt * 1000:.0f} ms, {writes} writes")
        waiting = [x for x in seen if x[0] < 0.15]
        check(all(x[1] == SAFEOP and x[2] == 0 for x in waiting), f"Op {how}: Safe-Op without error while waiting: {waiting[:3]}")
        check((st, code) == (SAFEOP | ERR, 0x002B), f"Op {how}: refused with 002Bh, got {st:#04x}/{code:04X}h")
        # the drive refuses 200 ms after the request; a loaded machine may
        # read it later, never earlier (nor never, as before issue 33)
        check(0.19 <= dt <= 1.5, f"Op {how}: refused {dt * 1000:.0f} ms after the first request")
        st, code = to(s, SAFEOP | ACK, SAFEOP)
        check((st, code) == (SAFEOP, 0), f"acknowledged: {st:#04x}/{code:04X}h")


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--iface", required=True)
    p.add_argument("--case", required=True, choices=["op-repeat"])
    args = p.parse_args()
    m = pysoem.Master()
    m.open(args.iface)
    try:
        L.scan(m, 1)
        check(m.read_state() == PREOP, f"Pre-Op after the scan: {L.state_report(m)}")
        {"op-repeat": case_op_repeat}[args.case](m)
    except L.Fatal as e:
        check(False, str(e))
    finally:
        m.close()
    if L.failures:
        say(f"\n{len(L.failures)} check(s) failed")
        return 1
    say("\nall checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
