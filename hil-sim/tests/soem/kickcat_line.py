#!/usr/bin/env python3
"""KickCAT (C++ master, its Python bindings from PyPI, kickcat==2.5) drives a
line of simulated drives (`hil-sim serve`) over raw Ethernet: a third master
next to ethercrab and SOEM (issue 33). Run by `hil-sim/tests/kickcat.rs` as
root in the master's network namespace (or by hand against `serve`).

  1. scan (Bus.init): the drives in Pre-Op;
  2. SDO Info: the object and entry descriptions of 1018h and 6040h against
     the names the Rust test passes (the drive's declarations) [E-080, E-082];
  3. complete access of 1A00h, KickCAT's and its emulated one compared
     [E-078]; 1018h:01 the vendor ID B9h [E-005];
  4. a remap by SDO: axis A only (1600h: 6040h, 6060h, 607Ah; 1A00h: 6041h,
     6061h, 6064h, 60F4h, 606Ch, 603Fh), read back [E-056]; I423 (the
     longest the drive extrapolates a missing cyclic set-point, C-117)
     raised by SDO from its 10 ms to --i423-ms, read back: a master's
     setting for its own jitter, as a user sets it for a Python master;
  5. Safe-Op, Op with process data [E-021], the sizes the remap gives;
  6. the CiA 402 enable in csp (6060h = 8, 607Ah = 6064h) 6/7/15 with the
     statusword patterns [E-034];
  7. csp for --seconds of process data: a move of one revolution on axis A
     of every drive, a cosine S-curve over --move-seconds whose set-point
     (607Ah) the script computes each cycle from the master's clock, then
     the target held [C-116, C-117]: in every cycle with new inputs 6064h
     within --tolerance increments of the set-point sent, plus twice what
     the drive's extrapolation over the longest gap so far misses of the
     curve (a/2 g²); the end within --end-tolerance of the target; the
     drives still enabled without a fault; the cycles with a wrong working
     counter, the longest gap between cycles and the largest deviation
     printed;
  8. Init.
KickCAT 2.5 does not report the abort of an SDO write (it times out), so no
check here relies on one.
"""
import argparse
import faulthandler
import math
import struct
import sys
import time

import kickcat

failures = []


def say(*a):
    print(*a, flush=True)


def check(ok, what):
    if not ok:
        failures.append(what)
        say(f"FAIL: {what}")
    return ok


def entry(index, sub, bits):
    return (index << 16) | (sub << 8) | bits


RX = [entry(0x6040, 0, 16), entry(0x6060, 0, 8), entry(0x607A, 0, 32)]
TX = [entry(0x6041, 0, 16), entry(0x6061, 0, 8), entry(0x6064, 0, 32), entry(0x60F4, 0, 32), entry(0x606C, 0, 32), entry(0x603F, 0, 16)]
OUT_BYTES, IN_BYTES = 7, 17


def sdo_write(bus, s, index, sub, data, tries=3):
    for _ in range(tries):
        msg = s.mailbox.write_sdo(index, sub, False, data, 0.5)
        while msg.status() == kickcat.mailbox.request.MessageStatus.RUNNING:
            bus.process_mailboxes()
            time.sleep(0.001)
        if msg.status() == kickcat.mailbox.request.MessageStatus.SUCCESS:
            return True
        say(f"RETRY write {index:04X}h:{sub:02X}: {msg.status()}")
    return check(False, f"write {index:04X}h:{sub:02X}")


def retry(bus, what, f, tries=3):
    """f() again after a RuntimeError of KickCAT's mailbox (a mailbox frame
    lost or late: KickCAT waits 2 to 10 ms for each, a loaded machine can be
    slower, issue 33 point 6), as a master retries a lost request; the
    mailboxes are polled in between so a late answer is not taken for the
    next one."""
    for k in range(1, tries + 1):
        try:
            return f()
        except RuntimeError as e:
            if k == tries:
                raise
            say(f"RETRY {what}: {e}")
            for _ in range(20):
                try:
                    bus.process_mailboxes()
                except RuntimeError:
                    pass
                time.sleep(0.005)


def sdo_read(bus, s, index, sub, access=kickcat.Access.PARTIAL, size=64):
    return retry(bus, f"read {index:04X}h:{sub:02X}", lambda: bus.read_sdo(s, index, sub, access, size, 1.0))


def main():
    # a crash inside KickCAT's C++ prints where the script was
    faulthandler.enable()
    p = argparse.ArgumentParser()
    p.add_argument("--iface", required=True)
    p.add_argument("--slaves", type=int, default=2)
    p.add_argument("--seconds", type=float, default=10)
    p.add_argument("--name-1018", required=True)
    p.add_argument("--name-6040", required=True)
    p.add_argument("--i423-index", type=lambda v: int(v, 0), required=True)
    p.add_argument("--i423-ms", type=int, default=100)
    p.add_argument("--inc-per-rev", type=int, default=1 << 20)
    p.add_argument("--move-seconds", type=float, default=2.0)
    p.add_argument("--tolerance", type=int, required=True, help="6064h against the set-point, increments")
    p.add_argument("--end-tolerance", type=int, required=True, help="6064h against the target at the end, increments")
    args = p.parse_args()
    link = kickcat.create_link(args.iface, "")
    # the scan and the mailbox work wait up to 50 ms for each frame (a
    # master's setting; KickCAT's own 2 ms comes back for the cyclic phase):
    # on a loaded machine `serve`'s answers took longer than 10 ms at times
    # (issue 33 point 6), KickCAT then failed its scan
    link.set_timeout(0.05)
    for k in range(5):
        # a fresh Bus for every try: after an init that failed half-way
        # (a timeout on a loaded machine) KickCAT 2.5's create_mapping on the
        # same Bus crashed the interpreter (a segmentation fault in CI)
        bus = kickcat.Bus(link)
        try:
            bus.init(0.1)
            if len(bus.slaves()) == args.slaves and all(bus.get_state(s) == kickcat.State.PREOP for s in bus.slaves()):
                break
            say(f"init found {len(bus.slaves())} slave(s), not all in Pre-Op, again")
        except Exception as e:  # noqa: BLE001 (KickCAT raises its own error types)
            say(f"init failed ({e}), again")
        time.sleep(0.5)
    slaves = bus.slaves()
    say(f"KickCAT found {len(slaves)} slave(s)")
    if not check(len(slaves) == args.slaves, f"{args.slaves} slaves expected"):
        return 1
    for i, s in enumerate(slaves):
        check(bus.get_state(s) == kickcat.State.PREOP, f"drive {i + 1} in Pre-Op after init")
        name, _ = retry(bus, "description of 1018h", lambda: bus.read_object_description(s, 0x1018))
        check(name == args.name_1018, f"drive {i + 1}: 1018h described as {name!r}")
        name, _ = retry(bus, "description of 6040h", lambda: bus.read_object_description(s, 0x6040))
        check(name == args.name_6040, f"drive {i + 1}: 6040h described as {name!r}")
        # KickCAT's binding decodes the whole entry description (the value
        # information it asks for included) as UTF-8: an entry whose default
        # is not text-like (1018h:01 = B9h) cannot come through it
        desc = retry(bus, "description of 6040h:00", lambda: bus.read_entry_description(s, 0x6040, 0))
        say(f"drive {i + 1}: 6040h:00 described as {desc}")
        check(args.name_6040 in "".join(desc), f"drive {i + 1}: 6040h:00 entry description {desc!r}")
        vendor = struct.unpack("<I", sdo_read(bus, s, 0x1018, 1)[:4])[0]
        check(vendor == 0xB9, f"drive {i + 1}: vendor ID {vendor:#x}")
        ca = sdo_read(bus, s, 0x1A00, 0, kickcat.Access.COMPLETE, 256)
        emu = sdo_read(bus, s, 0x1A00, 0, kickcat.Access.EMULATE_COMPLETE, 256)
        say(f"drive {i + 1}: 1A00h complete access {ca.hex()} / emulated {emu.hex()}")
        check(len(ca) >= 2 and ca[0] >= 1, f"drive {i + 1}: 1A00h by complete access")
        # the drive's complete access from sub 0 carries sub 0 as 16 bits
        # (ETG), KickCAT's emulation reads the entries 1..n only
        check(ca[:2] == bytes([len(emu) // 4, 0]) and ca[2:] == emu, f"drive {i + 1}: complete access and its emulation differ")
        # the remap
        for a in (0x1C12, 0x1C13):
            sdo_write(bus, s, a, 0, b"\x00")
        for pdo, entries in ((0x1600, RX), (0x1A00, TX)):
            sdo_write(bus, s, pdo, 0, b"\x00")
            for k, e in enumerate(entries, 1):
                sdo_write(bus, s, pdo, k, struct.pack("<I", e))
            sdo_write(bus, s, pdo, 0, bytes([len(entries)]))
        for a, pdo in ((0x1C12, 0x1600), (0x1C13, 0x1A00)):
            sdo_write(bus, s, a, 1, struct.pack("<H", pdo))
            sdo_write(bus, s, a, 0, b"\x01")
        back = [struct.unpack("<I", sdo_read(bus, s, 0x1600, k)[:4])[0] for k in range(1, 4)]
        check(back == RX, f"drive {i + 1}: 1600h read back {[hex(x) for x in back]}")
        # I423: 10 ms by default, shorter than a Python master's stalls on a
        # loaded machine (the drive then faults with C-117, rightly)
        old = struct.unpack("<H", sdo_read(bus, s, args.i423_index, 0)[:2])[0]
        sdo_write(bus, s, args.i423_index, 0, struct.pack("<H", args.i423_ms))
        new = struct.unpack("<H", sdo_read(bus, s, args.i423_index, 0)[:2])[0]
        say(f"drive {i + 1}: I423 ({args.i423_index:04X}h) {old} ms -> {new} ms")
        check(new == args.i423_ms, f"drive {i + 1}: I423 read back {new}, {args.i423_ms} written")
    say("create the mapping, Safe-Op")
    bus.create_mapping()
    for i, s in enumerate(slaves):
        check((s.output_size, s.input_size) == (OUT_BYTES, IN_BYTES), f"drive {i + 1}: mapped {s.output_size}/{s.input_size} bytes")
    retry(bus, "Safe-Op request", lambda: bus.request_state(kickcat.State.SAFE_OP))
    bus.wait_for_state(kickcat.State.SAFE_OP, 3.0)
    # in csp the drive extrapolates for at most I423 (10 ms) without a new
    # set-point (C-117): a frame lost with the 10 ms link timeout of the scan
    # alone is longer; KickCAT's usual 2 ms keeps one lost frame within I423
    link.set_timeout(0.002)
    wkc_errors = [0]
    last = [None, 0.0]

    def cycle():
        t = time.monotonic()
        if last[0] is not None:
            last[1] = max(last[1], t - last[0])
        last[0] = t
        try:
            bus.process_data()
            return True
        except Exception:  # noqa: BLE001 (a wrong working counter or a timeout)
            wkc_errors[0] += 1
            return False

    for s in slaves:
        s.set_output_bytes(bytes(OUT_BYTES))
    for _ in range(100):
        cycle()
        time.sleep(0.001)
    retry(bus, "Op request", lambda: bus.request_state(kickcat.State.OPERATIONAL))
    bus.wait_for_state(kickcat.State.OPERATIONAL, 3.0, lambda: (cycle(), time.sleep(0.001)))
    for i, s in enumerate(slaves):
        check(bus.get_state(s) == kickcat.State.OPERATIONAL, f"drive {i + 1} in Op")

    def run(ms, outs):
        for _ in range(ms):
            for s, o in zip(slaves, outs):
                s.set_output_bytes(o)
            cycle()
            time.sleep(0.001)

    def sw(s):
        return struct.unpack_from("<H", s.input_data, 0)[0]

    run(20, [struct.pack("<HBi", 0, 8, 0) for _ in slaves])
    positions = [struct.unpack_from("<i", s.input_data, 3)[0] for s in slaves]
    say(f"positions {positions}")
    for cw, mask, want in ((6, 0x6F, 0x21), (7, 0x6F, 0x23), (15, 0x6F, 0x27)):
        outs = [struct.pack("<HBi", cw, 8, p) for p in positions]
        for _ in range(50):
            run(10, outs)
            if all(sw(s) & mask == want for s in slaves):
                break
        got = [hex(sw(s)) for s in slaves]
        say(f"controlword {cw}: statusword {got}")
        check(all(sw(s) & mask == want for s in slaves), f"controlword {cw}: statusword {got}, {want:#x} expected")
    # csp: one revolution as a cosine S-curve on the master's clock (a slot
    # the master missed, descheduled, advances the curve too, as a real
    # master's trajectory does: the drive extrapolates over the gap, C-116,
    # for up to I423, and meets the next set-point), then the target held
    def curve(t):
        x = (1 - math.cos(math.pi * min(t / args.move_seconds, 1.0))) / 2
        return round(x * args.inc_per_rev)

    starts = positions
    targets = [p + args.inc_per_rev for p in starts]
    # the curve's largest acceleration, rev/s²: what the drive's linear
    # extrapolation over a gap of g seconds misses is at most a/2 · g² rev
    accel = math.pi ** 2 / (2 * args.move_seconds ** 2)
    t0 = time.monotonic()
    n0 = wkc_errors[0]
    last[1] = 0.0
    cycles = 0
    worst = [(-(1 << 40), 0)] * len(slaves)  # (deviation beyond the bound, deviation)
    gap = 0.0  # the longest gap between cycles so far
    faults = []

    def pos(s):
        return struct.unpack_from("<i", s.input_data, 3)[0]

    def hold(t_end):
        nonlocal cycles
        while time.monotonic() - t0 < t_end:
            t = time.monotonic() - t0
            sp = [p + curve(t) for p in starts]
            for s, x in zip(slaves, sp):
                s.set_output_bytes(struct.pack("<HBi", 15, 8, x))
            ok = cycle()
            cycles += 1
            time.sleep(0.001)
            if not ok:
                # no new inputs in this cycle: nothing to judge
                continue
            yield t, sp

    # the bound: the lag of the position loop (--tolerance) plus twice what
    # the extrapolation over the longest gap so far misses of the curve
    def bound():
        return args.tolerance + round(2 * accel / 2 * gap ** 2 * args.inc_per_rev)

    for t, sp in hold(args.seconds):
        gap = max(gap, last[1])
        for k, (s, x) in enumerate(zip(slaves, sp)):
            if sw(s) & 0x6F != 0x27 and not faults:
                faults.append(f"drive {k + 1} left Operation enabled at {t:.3f} s: statusword {sw(s):#06x}, "
                              f"603Fh {struct.unpack_from('<H', s.input_data, 15)[0]:#06x}")
            d = abs(pos(s) - x)
            worst[k] = max(worst[k], (d - bound(), d))
    say(
        f"{cycles} cycles in Op in csp, {wkc_errors[0] - n0} with a wrong working counter or a timeout; "
        f"longest gap between two cycles {gap * 1e3:.1f} ms (I423 {args.i423_ms} ms); "
        f"tracking bound {bound()} inc ({args.tolerance} + the curve's bend over that gap)"
    )
    check(not faults, "; ".join(faults) or "no fault")
    # the end: the first cycle with new inputs after --seconds in which every
    # drive is within --end-tolerance, at most 2 s later. (Under load, with
    # many of KickCAT's 2 ms frames late, 6064h was seen up to ~1000 inc off
    # the held target at the run's end and back within 1 s; the cause, late
    # frames of the master or the drive, is not found yet: the deviation at
    # the run's end is printed.)
    at_run_end = [pos(s) - x for s, x in zip(slaves, targets)]
    settled = None
    for t, _ in hold(args.seconds + 2.0):
        if all(abs(pos(s) - x) <= args.end_tolerance for s, x in zip(slaves, targets)):
            settled = t
            break
    ends = [pos(s) for s in slaves]
    for k in range(len(slaves)):
        moved = ends[k] - starts[k]
        over, dev = worst[k]
        say(
            f"drive {k + 1}: moved {moved} inc ({moved / args.inc_per_rev:.5f} rev) in {args.move_seconds} s, "
            f"end {ends[k] - targets[k]:+d} inc from the target"
            + (f" ({settled - args.seconds:.3f} s after the run" if settled is not None else " (not settled")
            + f"; {at_run_end[k]:+d} inc at the run's end)"
            + f", 6064h at most {dev} inc ({dev / args.inc_per_rev:.5f} rev) from the set-point sent"
        )
        check(over <= 0, f"drive {k + 1}: 6064h {dev} inc from the set-point, beyond the bound by {over} inc")
        check(abs(ends[k] - targets[k]) <= args.end_tolerance,
              f"drive {k + 1}: end {ends[k] - targets[k]:+d} inc from the target, tolerance {args.end_tolerance}")
    modes = [s.input_data[2] for s in slaves]
    check(modes == [8] * len(slaves), f"6061h still csp (8) at the end: {modes}")
    end = [(hex(sw(s)), hex(struct.unpack_from("<H", s.input_data, 15)[0])) for s in slaves]
    check(all(sw(s) & 0x6F == 0x27 for s in slaves), f"still enabled after the process data: statusword, 603Fh {end}")
    retry(bus, "Init request", lambda: bus.request_state(kickcat.State.INIT))
    bus.wait_for_state(kickcat.State.INIT, 3.0)
    check(all(bus.get_state(s) == kickcat.State.INIT for s in slaves), "Init at the end")
    if failures:
        say(f"\n{len(failures)} check(s) failed")
        return 1
    say("\nall checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
