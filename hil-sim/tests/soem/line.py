#!/usr/bin/env python3
"""SOEM (through pysoem) drives a line of simulated drives over raw Ethernet.

Run by `hil-sim/tests/soem.rs` as root inside a network namespace whose veth
end leads to `hil-sim serve`. Everything goes through SOEM's own calls; the
expected values come from the drive's declarations, written by the Rust test:

  --sii FILE  the SII image `ecat::build_sii(&drive_ecat::DEVICE, ..)` generates
  --od FILE   the visible objects and entries of a fresh dictionary (SDO Info
              template), tab-separated, with the entries' default values

Steps (spec items in brackets):
  1. scan (config_init): identity from the SII and 1018h, 1000h [E-002, E-004,
     E-005, E-151]; the whole SII read back and compared byte for byte;
  2. SDO Info: the object list and every object and entry description
     [E-080, E-082]; the PDO assignment and mapping objects with their
     defaults [E-048, E-049, E-054, E-056];
  3. refused SDOs with their abort codes [E-071, E-072];
  4. a different mapping and assignment in Pre-Op through SDO, read back;
     config_map must take it over [E-056];
  5. refusals at Pre-Op -> Safe-Op: SM2 length not matching the mapping 001Dh,
     SM3 001Eh, each with its EMCY A000h [E-045, E-057, E-028]; SYNC0 not on
     the 250 us grid 0035h, not k x A150 0036h [E-029, E-116];
  6. DC SYNC0 1 ms, the master aligned to the reference clock (SOEM's ec_sync
     PI on dc_time, frames FRAME_LEAD_NS before SYNC0), Safe-Op, Op
     [E-107, E-021];
  7. per drive, axis A then axis B (objects at +800h, E-015): CiA 402 enable
     6040h 6/7/15 with the statusword patterns of 6041h, a csp move of one
     revolution, disable; the other axis must not move [E-034];
  8. process data for --seconds in Op at 1 ms; cycles with a wrong working
     counter are printed (timing of a shared machine), a state or data error
     fails the run.

A shared machine does not always run the master in time (SOEM times its
frames by the wall clock): a mailbox read that came back wrong or not at all
is repeated (`attempt`, printed as RETRY); a state or data error right after
the line went without frames longer than the drives tolerate is the drives'
specified reaction, printed as STALL, recovered and the step repeated (at most
MAX_STALLS times). Anything else fails.
Exit status 0 when every check passed; each failed check is printed. With
SOEM_TRACE=FILE every cycle's timing goes to FILE (cycle, time, DC time, phase
error, PI offset, integral, working counter, wake-up lateness, round trip).

The script's parts live beside it: soem_report.py (check, say, the report),
soem_mailbox.py (SDO, `attempt`, PDO objects, EMCYs), soem_master.py (AL
states, scan, mapping, a script's frame), soem_cycle.py (the DC-aligned
cycle), soem_cia402.py (statusword patterns, axes) and line_preop.py (steps
1 to 5). This file keeps steps 6 to 8 (the stall limits, `Line`, `step`,
`motion`) and the test's main; `import line as L` gives every name of those
modules too (MAX_STALLS stays here, where `Line` and `motion` read it: a
script may set L.MAX_STALLS).
"""
import argparse
import gc
import math
import sys
import time

import pysoem

# Everything the other scripts use as L.<name> (and every other name
# line.py had before its split) comes from the modules beside it:
from line_preop import (  # noqa: F401
    ASSIGN,
    RX_A,
    TX_A,
    bad_sdos,
    default_pdo_objects,
    identity_and_sii,
    load_od,
    name40,
    object_problems,
    refusal,
    refusals,
    remap,
    sdo_info,
    sii_strings_1,
)
from soem_cia402 import (  # noqa: F401
    ENABLED,
    FAULT,
    INC_PER_REV,
    READY,
    SWITCH_ON_DISABLED,
    SWITCHED_ON,
    Axis,
    FreeRunAxis,
    enable_sequence,
    stop,
    sw_is,
)
from soem_cycle import CYCLE_NS, FRAME_LEAD_NS, SLOT_LATE_NS, TRACE, Cycle, align, wait_states  # noqa: F401
from soem_mailbox import (  # noqa: F401
    SOEM_ERRORS,
    Emcys,
    attempt,
    entry,
    fmt_map,
    map_one_pdo_each,
    pdo_objects,
    sdo_abort,
    sdo_u,
    u,
    write,
    write_map,
)
from soem_master import (  # noqa: F401
    ACK,
    ERR,
    INIT,
    OP,
    PREOP,
    SAFEOP,
    Layout,
    acknowledge,
    config_init,
    config_map,
    master_main,
    one_drive_in_preop,
    priority,
    real_time,
    request,
    required_float,
    scan,
    script,
    script_main,
    state_of,
    state_report,
    stops_as_checks,
    to_op,
)
from soem_report import Fatal, check, failures, report, say  # noqa: F401


# --- 6..8. the cyclic part ---------------------------------------------------


class Stall(Exception):
    """A slave left Op or an axis left Operation enabled right after the line
    was stalled longer than the drive tolerates (see Cycle.stall)."""


class Disturbed(Exception):
    """A move the machine disturbed too often to judge the tracking: the
    axes are disabled again and the move is repeated."""


# the drives' specified reactions to a line without frames in time: AL 0033h
# after 5 late frames in a row (E-046, dcsync's late-frame limit), event 78/3
# (603Fh 8612h) after extrapolating longer than I423 = 10 ms (C-117)
LATE_FRAME_LIMIT = 5
I423_PERIODS = 10
EXTRAPOLATION_OVERRUN = 0x8612
# periods after a gap before the following error counts again (the
# cascade settles within a few; 20 leaves a margin)
SETTLE_PERIODS = 20
# a run of this many periods without a frame in time is a gap (one or two
# the drive bridges by extrapolating, C-116, within its tracking)
GAP_PERIODS = 3
# a following error this small counts as settled at the end of a move
SETTLED_INC = 100
# a run may be stalled by its machine this often (each is printed)
MAX_STALLS = 3


class Line:
    """The cyclic exchange with every slave: outputs kept per slave, inputs
    of the last cycle with the right working counter."""

    def __init__(self, m, cyc, layouts):
        self.m = m
        self.cyc = cyc
        self.outs = [bytearray(len(s.output)) for s in m.slaves]
        self.axes = [[Axis(i, 0, lo, li), Axis(i, 0x800, lo, li)] for i, (lo, li) in enumerate(layouts)]
        self.inp = [s.input for s in m.slaves]
        self.stalls = []

    def cycle(self, fill=None):
        """One cycle with the kept outputs; `fill(slot)` may change them
        for the slot the frame goes in (see Cycle.run)."""

        def send(slot):
            if fill:
                fill(slot)
            for s, o in zip(self.m.slaves, self.outs):
                s.output = bytes(o)

        wkc = self.cyc.run(send)
        if wkc == self.cyc.expected_wkc:
            self.inp = [s.input for s in self.m.slaves]
        return wkc

    def check_stalled(self, what, last=300):
        """After a state or data error: was it the drives' specified reaction
        to a line the machine stalled? Then it is printed, and the caller
        recovers and repeats the step; else it is a failure (False). A slave
        out of Op must show AL 0033h after at least LATE_FRAME_LIMIT periods
        without a frame in time; an axis fault without that must follow more
        than I423 without frames, and axis A (603Fh is in its TxPDO) must show
        8612h."""
        m = self.m
        longest = self.cyc.stall(last)
        m.read_state()
        codes = {s.al_status for s in m.slaves if s.state != OP}
        if codes:
            if codes != {0x0033}:
                return False
            need, reaction = LATE_FRAME_LIMIT, "AL 0033h"
        else:
            need, reaction = I423_PERIODS + 1, "event 78/3"
            for row in self.axes:
                a = row[0]
                inp = self.inp[a.slave]
                if sw_is(a.sw(inp), FAULT) and a.in_l.get(inp, 0x603F) != EXTRAPOLATION_OVERRUN:
                    say(f"{a.name}: fault with 603Fh = {a.in_l.get(inp, 0x603F):04X}h, not {EXTRAPOLATION_OVERRUN:04X}h")
                    return False
        if longest < need:
            say(f"(the longest run of periods without a frame in time was {longest}, {reaction} needs {need})")
            return False
        self.stalls.append(what)
        say(
            f"STALL: {what}, after {longest} SYNC0 periods in a row without a frame in the drives' window "
            f"(the machine did not run the master or the simulator in time): {reaction}, the drives' specified "
            f"reaction; recovering and repeating the step ({len(self.stalls)} of at most {MAX_STALLS})"
        )
        if len(self.stalls) > MAX_STALLS:
            raise Fatal(f"the machine stalled the line {len(self.stalls)} times")
        return True

    def recover(self):
        """What a SOEM program does (the samples' ecatcheck): acknowledge an
        error in Safe-Op and ask for Op again; then reset the axes' faults
        (controlword bit 7 rising edge, C-017)."""
        m = self.m
        for _ in range(3000):
            self.cycle()
            if self.cyc.n % 10:
                continue
            m.read_state()
            if all(s.state == OP for s in m.slaves):
                break
            for s in m.slaves:
                if s.state == SAFEOP | ERR:
                    s.state = SAFEOP | ACK
                    s.write_state()
                elif s.state == SAFEOP:
                    s.state = OP
                    s.write_state()
        else:
            raise Fatal(f"Op not regained: {state_report(m)}")
        for cw in (0x00, 0x80, 0x00):
            for _ in range(20):
                for row in self.axes:
                    for a in row:
                        a.write(self.outs[a.slave], cw, 8, a.pos(self.inp[a.slave]))
                self.cycle()
        bad = [a.name for row in self.axes for a in row if not sw_is(a.sw(self.inp[a.slave]), SWITCH_ON_DISABLED)]
        if bad:
            raise Fatal(f"fault reset did not bring {bad} to Switch on disabled")


def step(line, axes, cw, pattern, what, target):
    """Cycles with controlword `cw` until every axis shows `pattern`."""
    for k in range(300):
        for a in axes:
            a.write(line.outs[a.slave], cw, 8, target(a))
        line.cycle()
        if all(sw_is(a.sw(line.inp[a.slave]), pattern) for a in axes):
            say(f"  controlword {cw:#04x}: every axis {what} after {k + 1} cycles")
            return
    bad = ", ".join(f"{a.name} {a.sw(line.inp[a.slave]):#06x}" for a in axes)
    if line.check_stalled(f"controlword {cw:#04x}: {bad}"):
        raise Stall()
    check(False, f"controlword {cw:#04x}: not all axes {what} within 300 cycles: {bad} (states {state_report(line.m)})")
    raise Fatal(what)


def motion(line, axes, move_cycles=1000, hold_cycles=200):
    """Enable, csp move of one revolution, disable: all `axes` together."""
    inp = line.inp
    start = {a.name: a.pos(inp[a.slave]) for a in axes}
    for a in axes:
        sw = a.sw(inp[a.slave])
        say(f"{a.name}: statusword {sw:#06x} at {start[a.name]} inc")
        if not check(sw_is(sw, SWITCH_ON_DISABLED), f"{a.name}: Switch on disabled expected, statusword {sw:#06x}"):
            raise Fatal(f"{a.name} not ready")
    # enable: Shutdown, Switch on, Enable operation; csp, target = actual position
    for cw, pattern, what in [(0x06, READY, "Ready to switch on"), (0x07, SWITCHED_ON, "Switched on"), (0x0F, ENABLED, "Operation enabled")]:
        step(line, axes, cw, pattern, what, lambda a: start[a.name])
    for a in axes:
        mode = a.mode(line.inp[a.slave])
        check(mode == 8, f"{a.name}: mode display {mode}, csp (8) expected")
    # csp: one revolution as a cosine S-curve, then hold. The curve runs on
    # the slot clock, as a real master's trajectory does: a slot the master
    # left out (descheduled) advances it too, so the drive's extrapolation
    # over the gap (C-117) meets the next set-point instead of running ahead
    # of a curve that stood still.
    max_ferr = {a.name: 0 for a in axes}
    slot0 = line.cyc.n + line.cyc.skipped

    def curve(slot):
        k = slot - slot0
        x = (1 - math.cos(math.pi * min(k, move_cycles) / move_cycles)) / 2
        for a in axes:
            a.write(line.outs[a.slave], 0x0F, 8, start[a.name] + round(x * INC_PER_REV))

    # The tracking check counts the cycles of an undisturbed line only: a
    # gap of GAP_PERIODS or more periods without a frame in the window (a
    # late or descheduled master) makes the drive extrapolate the set-point
    # for longer (C-116/C-117) and the following error after it measures the
    # gap, not the control. Samples within SETTLE_PERIODS of such a gap are
    # left out (and counted).
    clean = {a.name: 0 for a in axes}
    raw_ferr = {a.name: 0 for a in axes}
    gap = 0  # the longest gap seen (runs longer than SETTLE_PERIODS count as that)
    for _ in range(move_cycles + hold_cycles):
        line.cycle(curve)
        recent = line.cyc.stall(SETTLE_PERIODS)
        gap = max(gap, recent)
        undisturbed = recent < GAP_PERIODS
        for a in axes:
            sw = a.sw(line.inp[a.slave])
            if not sw_is(sw, ENABLED):
                what = f"{a.name} left Operation enabled during the move, statusword {sw:#06x}"
                if line.check_stalled(what):
                    raise Stall()
                check(False, f"{what} (states {state_report(line.m)})")
                raise Fatal("move")
            ferr = abs(a.ferr(line.inp[a.slave]))
            raw_ferr[a.name] = max(raw_ferr[a.name], ferr)
            if undisturbed:
                clean[a.name] += 1
                max_ferr[a.name] = max(max_ferr[a.name], ferr)
    total = move_cycles + hold_cycles
    # the end position once the line has been undisturbed for a while and
    # the axes have settled (after a late master's gap late in the move the
    # axis may still be on its way back to the set-point)
    for _ in range(2000):
        settled = all(abs(a.ferr(line.inp[a.slave])) <= SETTLED_INC for a in axes)
        if line.cyc.stall(SETTLE_PERIODS) < GAP_PERIODS and settled:
            break
        line.cycle(curve)
    too_few = [a.name for a in axes if clean[a.name] < total // 2]
    # a gap longer than the drive extrapolates (I423) ends the extrapolation
    # (C-117) and the set-point jumps by the motion of the whole gap when the
    # master is back: the catch-up after it takes longer than SETTLE_PERIODS
    # and measures the gap, so such a move is not judged either (repeated)
    if gap > I423_PERIODS and not too_few:
        say(f"(a gap of {gap} or more periods without a frame in time during the move, longer than I423 = {I423_PERIODS})")
        too_few = [a.name for a in axes]
    for a in axes:
        moved = a.pos(line.inp[a.slave]) - start[a.name]
        say(
            f"{a.name}: moved {moved} inc ({moved / INC_PER_REV:.4f} rev), following error max "
            f"{max_ferr[a.name]} inc over {clean[a.name]} of {total} cycles on an undisturbed line "
            f"({raw_ferr[a.name]} inc over all)"
        )
        check(abs(moved - INC_PER_REV) <= 200, f"{a.name}: moved {moved} inc, one revolution ({INC_PER_REV}) expected")
        if not too_few:
            check(max_ferr[a.name] < INC_PER_REV // 64, f"{a.name}: following error {max_ferr[a.name]} inc")
    # disable: Disable operation, Shutdown, Disable voltage
    for cw, pattern, what in [(0x07, SWITCHED_ON, "Switched on"), (0x06, READY, "Ready to switch on"), (0x00, SWITCH_ON_DISABLED, "Switch on disabled")]:
        step(line, axes, cw, pattern, what, lambda a: a.pos(line.inp[a.slave]))
    if too_few:
        # the machine, not the drive: the move is repeated (a bounded number of times)
        line.stalls.append(f"move disturbed: {too_few}")
        say(
            f"(fewer than {total // 2} of {total} cycles on an undisturbed line, or a gap longer than I423, "
            f"for {too_few}: the machine disturbed the move, repeating it ({len(line.stalls)} of at most "
            f"{MAX_STALLS}))"
        )
        if len(line.stalls) > MAX_STALLS:
            check(False, f"{too_few}: every move disturbed, the tracking could not be judged")
            raise Fatal("move")
        raise Disturbed()


def diagnose(m, emcys):
    """What the drives say after a failure: error codes, statuswords, EMCYs."""
    for i, s in enumerate(m.slaves):
        try:
            words = {x: sdo_u(s, x, 0) for x in (0x603F, 0x6041, 0x683F, 0x6841)}
            say(f"slave {i + 1}: " + ", ".join(f"{k:04X}h = {v:#06x}" for k, v in words.items()))
            say(f"slave {i + 1}: A261 = {[sdo_u(s, 0x2105, k) for k in (1, 2, 3)]}")
        except Exception as e:  # noqa: BLE001 - diagnostics only
            say(f"slave {i + 1}: diagnostics by SDO failed: {e!r}")
        for e in emcys.drain(m, i):
            say(f"slave {i + 1}: EMCY {e}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--iface", required=True)
    ap.add_argument("--slaves", type=int, default=3)
    ap.add_argument("--sii", required=True)
    ap.add_argument("--od", required=True)
    ap.add_argument("--seconds", type=float, default=12.0, help="process data in Op, s")
    ap.add_argument("--until", choices=["sdo-info", "refusals", "op"], default="op", help="stop after this step")
    args = ap.parse_args()
    sii = open(args.sii, "rb").read()
    od = load_od(args.od)
    return master_main(args, lambda m, a: run(m, a, sii, od), "all checks passed")


def run(m, args, sii, od):
    scan(m, args.slaves)
    n = len(m.slaves)
    check(m.read_state() == PREOP, f"every slave in Pre-Op after config_init: {state_report(m)}")
    identity_and_sii(m, sii)
    for i in range(n):
        sdo_info(m, i, od)
    want_assign, want_maps = default_pdo_objects(od)
    for i, s in enumerate(m.slaves):

        def defaults():
            assign, maps = pdo_objects(s)
            if i == 0:
                for p in (0x1600, 0x1601, 0x1A00, 0x1A01):
                    say(f"  {p:04X}h default: {fmt_map(maps[p])}")
                say(f"  1C12h {[hex(x) for x in assign[0x1C12]]}, 1C13h {[hex(x) for x in assign[0x1C13]]}")
            problems = []
            if assign != want_assign:
                problems.append(f"slave {i + 1}: default assignment {assign}, declared {want_assign}")
            for p in maps:
                if maps[p] != want_maps[p]:
                    problems.append(f"slave {i + 1}: {p:04X}h default mapping {fmt_map(maps[p])}, declared {fmt_map(want_maps[p])}")
            return problems

        attempt(m, i, "default PDO assignment and mapping", defaults)
    for i in range(n):
        bad_sdos(m, i, od)
    if args.until == "sdo-info":
        return

    # 4. remap in Pre-Op through SDO, read back; config_map takes it over
    layouts = []
    for i, s in enumerate(m.slaves):
        found = []

        def remapped():
            remap(s)
            assign, maps = pdo_objects(s)
            problems = []
            if assign != ASSIGN:
                problems.append(f"slave {i + 1}: assignment read back {assign}")
            if maps[0x1600] != RX_A or maps[0x1A00] != TX_A:
                problems.append(f"slave {i + 1}: mapping read back 1600h {fmt_map(maps[0x1600])}, 1A00h {fmt_map(maps[0x1A00])}")
            if maps[0x1601] != want_maps[0x1601] or maps[0x1A01] != want_maps[0x1A01]:
                problems.append(f"slave {i + 1}: axis B mapping changed")
            found[:] = [maps]
            return problems

        if not attempt(m, i, "remap and read back", remapped):
            raise Fatal("remap")
        maps = found[0]
        layouts.append((Layout(maps, ASSIGN[0x1C12]), Layout(maps, ASSIGN[0x1C13])))
    say(f"remapped: 1600h {fmt_map(RX_A)}; 1A00h {fmt_map(TX_A)}; 1601h/1A01h assigned (axis B)")
    m.manual_state_change = 1
    size = m.config_map()
    out_l, in_l = layouts[0]
    say(f"config_map: IO map {size} bytes; per slave {out_l.bytes} output, {in_l.bytes} input bytes; expected WKC {m.expected_wkc}")
    for i, s in enumerate(m.slaves):
        check(
            (len(s.output), len(s.input)) == (layouts[i][0].bytes, layouts[i][1].bytes),
            f"slave {i + 1}: SOEM mapped {len(s.output)}/{len(s.input)} bytes, the mapping written has {layouts[i][0].bytes}/{layouts[i][1].bytes}",
        )
    check(m.config_dc(), "config_dc: the slaves have DC")
    emcys = Emcys(m)

    # 5. refusals
    refusals(m, emcys, in_l)
    if args.until == "refusals":
        return

    # 6. DC SYNC0 1 ms, aligned cycle, Safe-Op, Op
    try:
        real_time(True)
        cyclic(m, args, layouts, emcys)
        real_time(False)
    except Fatal:
        real_time(False)
        m.state = PREOP
        m.write_state()
        m.state_check(PREOP, 1_000_000)
        diagnose(m, emcys)
        raise


def cyclic(m, args, layouts, emcys):
    # no garbage collector pauses in the cycle
    gc.disable()
    n = len(m.slaves)
    for s in m.slaves:
        s.dc_sync(True, CYCLE_NS)
    cyc = Cycle(m)
    line = Line(m, cyc, layouts)
    # the PI settles in a few hundred cycles; a frame answered late now and
    # then does not keep the run from going on
    recent = align(cyc)
    say(
        f"aligned to the reference clock after {cyc.n} cycles: {sum(recent)} of the last {len(recent)} frames within 100 us, "
        f"phase error {cyc.delta / 1000:.1f} us, offset {cyc.toff} ns/cycle"
    )
    m.state = SAFEOP
    m.write_state()
    if not wait_states(m, cyc, SAFEOP, 3000):
        raise Fatal(f"Safe-Op not reached: {state_report(m)}")
    say(f"Safe-Op after {cyc.n} cycles")
    # valid outputs before Op: controlword 0, csp, target = actual position
    for k in range(20):
        for row in line.axes:
            for a in row:
                a.write(line.outs[a.slave], 0, 8, a.pos(line.inp[a.slave]))
        line.cycle()
    m.state = OP
    m.write_state()
    cyc.counting = True
    t_op = time.monotonic()
    if not wait_states(m, cyc, OP, 3000):
        raise Fatal(f"Op not reached: {state_report(m)}")
    say(f"Op after {cyc.op_cycles} cycles: {state_report(m)}")

    # 7. axis A of every drive, then axis B; the other axis must stay still
    for which in (0, 1):
        while True:
            still = {}
            for row in line.axes:
                other = row[1 - which]
                still[other.name] = (other, other.pos(line.inp[other.slave]))
            try:
                motion(line, [row[which] for row in line.axes])
                break
            except Stall:
                line.recover()
            except Disturbed:
                pass
        for name, (a, p0) in still.items():
            p = a.pos(line.inp[a.slave])
            check(abs(p - p0) <= 50, f"{name} moved {p - p0} inc while the other axis moved")
        st = state_report(m)
        check(all(s.state == OP for s in m.slaves), f"every slave in Op after the moves: {st}")

    # 8. process data until --seconds in Op
    while time.monotonic() - t_op < args.seconds:
        line.cycle()
        if cyc.n % 250 == 0 and m.read_state() != OP:
            what = f"a slave left Op after {cyc.op_cycles} cycles: {state_report(m)}"
            if not line.check_stalled(what, last=600):
                raise Fatal(what)
            line.recover()
    final = state_report(m)
    check(all(s.state == OP for s in m.slaves), f"every slave in Op at the end: {final}")
    say(
        f"process data: {cyc.op_cycles} cycles in Op ({time.monotonic() - t_op:.1f} s), {len(cyc.bad_wkc)} with a wrong working counter "
        f"(expected {cyc.expected_wkc}); {cyc.outside} frames outside the drives' window (phase error up to {cyc.max_delta / 1000:.0f} us), "
        f"{cyc.skipped} slots left out by a late master, {len(line.stalls)} stall(s); states {final}"
    )
    for k, wkc in cyc.bad_wkc[:50]:
        say(f"  cycle {k}: working counter {wkc}")
    m.state = SAFEOP
    m.write_state()
    wait_states(m, cyc, SAFEOP, 1000)
    real_time(False)
    gc.enable()
    # what the drives counted: A261 (2105h) sync diagnostics, 1C32h:0B/20h
    for i, s in enumerate(m.slaves):
        try:
            a261 = [sdo_u(s, 0x2105, k) for k in (1, 2, 3)]
            sm_missed, sync_err = sdo_u(s, 0x1C32, 0x0B), sdo_u(s, 0x1C32, 0x20)
            say(f"slave {i + 1}: A261 error code {a261[0]}, data to SYNC0 {a261[1]} us, late frames {a261[2]}; 1C32h:0B {sm_missed}, :20 {sync_err}")
        except (pysoem.SdoError, pysoem.WkcError, pysoem.MailboxError, pysoem.PacketError) as e:
            check(False, f"slave {i + 1}: reading the sync diagnostics: {e!r}")
    m.state = INIT
    m.write_state()
    m.state_check(INIT, 2_000_000)

if __name__ == "__main__":
    sys.exit(main())
