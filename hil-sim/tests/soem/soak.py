#!/usr/bin/env python3
"""Soak test: SOEM (through pysoem) holds a line of simulated drives in csp at
1 ms for a long time and counts what went wrong.

Run by `cargo bench -p hil-sim --bench soak` (as root, inside a network
namespace whose veth end leads to `hil-sim serve --slaves N`), or by hand
against any `serve` (`--seconds` for runs of hours). It builds on line.py's
master (imported from beside this file): scan, both axes' PDOs assigned (a
short map per axis: 6040h/6060h/607Ah out, 6041h/6061h/6064h/60F4h/606Ch/
603Fh in, +800h for axis B), DC SYNC0 1 ms with the master's cycle aligned to
the reference clock (soem_cycle.py's Cycle through line: SOEM's ec_sync
PI), Safe-Op, Op, the
CiA 402 enable of every axis in csp, then for --seconds every axis moves
back and forth on a slow sine of its own from where it was enabled, A (1 −
cos(2 pi t / T)) (A = --amplitude rev, axis k of 2N with T = --period x (1 + k /
2N)), the set-points on the slot clock as in line.py.

Counted, per drive and axis where it applies:
  lost frames          the cyclic frame did not come back (SOEM: EC_NOFRAME)
  WKC errors           it came back with a working counter other than expected
  slots left out       the master woke too late for its slot and left it out
                       (a stall of the master on a loaded machine, not the drives)
  outside the window   frames the drives' clock saw outside SYNC0 - A150/2 .. SYNC0
  AL state changes     a drive seen out of Op (AL status read every 100 cycles
                       and after a wrong working counter); each is judged as
                       line.py does: AL 0033h after >= 5 periods without a frame
                       in the window (or an axis fault 8612h after more than I423)
                       is the drives' specified reaction to a master stall, printed
                       as STALL, recovered (acknowledge, Op, fault reset, enable)
                       and the run goes on from where the axes are; anything else
                       is a defect and ends the run
  following error max  |60F4h| per axis over the cycles of an undisturbed line
                       (no gap of GAP_PERIODS periods without a frame in the window
                       within the last SETTLE_CYCLES cycles), and over all cycles
                       with the axes enabled
  PLL status           A298 (bit 10 phase locked, bit 11 error) and A261 (late
                       frames) of every drive by SDO after the run

Progress every --progress seconds, a report at the end, then `SOAK RESULT:`
with the totals on one line. Exit status 0 unless a defect was seen (an axis
that left Operation enabled or a drive that left Op without a master stall to
explain it, a drive that did not come back to Op, a drive out of Op or not
phase locked at the end), 1 then. A run the machine stalled more than
--max-stalls times stops early and says so (not a defect of the drives).
"""
import argparse
import gc
import math
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import line as L  # noqa: E402  (line.py beside this file)
import pysoem  # noqa: E402

say = L.say
OP, SAFEOP, PREOP, INIT = L.OP, L.SAFEOP, L.PREOP, L.INIT

# A298 PLL status (0x2000 + 298), bits 10 and 11 (dcsync::PllStatus); A261
A298 = 0x2000 + 298
A261 = 0x2000 + 261
PHASE_LOCKED = 1 << 10
PLL_ERROR = 1 << 11

# AL status read every this many cycles (one extra frame)
STATE_EVERY = 100
# cycles after a gap of GAP_PERIODS or more periods without a frame in the
# window (the drive extrapolated, C-116) before the following error counts as
# that of an undisturbed line again: the axes settle back onto the sine in
# a few tens of cycles
SETTLE_CYCLES = 100
EC_NOFRAME = -1


class TooManyStalls(L.Fatal):
    """The machine stalled the line more than --max-stalls times."""


def entry(index, sub, bits):
    return (index << 16) | (sub << 8) | bits


def rx_map(base):
    return [entry(0x6040 + base, 0, 16), entry(0x6060 + base, 0, 8), entry(0x607A + base, 0, 32)]


def tx_map(base):
    return [
        entry(0x6041 + base, 0, 16),
        entry(0x6061 + base, 0, 8),
        entry(0x6064 + base, 0, 32),
        entry(0x60F4 + base, 0, 32),
        entry(0x606C + base, 0, 32),
        entry(0x603F + base, 0, 16),
    ]


MAPS = {0x1600: rx_map(0), 0x1601: rx_map(0x800), 0x1A00: tx_map(0), 0x1A01: tx_map(0x800)}
ASSIGN = {0x1C12: [0x1600, 0x1601], 0x1C13: [0x1A00, 0x1A01]}


def remap(m, i):
    """Both axes' short maps, both assigned, read back."""
    s = m.slaves[i]

    def write_and_read():
        for a in ASSIGN:
            s.sdo_write(a, 0, b"\x00")
        for pdo, entries in MAPS.items():
            L.write_map(s, pdo, entries)
        for a, pdos in ASSIGN.items():
            for k, p in enumerate(pdos, 1):
                s.sdo_write(a, k, p.to_bytes(2, "little"))
            s.sdo_write(a, 0, bytes([len(pdos)]))
        assign, maps = L.pdo_objects(s)
        problems = []
        if assign != ASSIGN:
            problems.append(f"slave {i + 1}: assignment read back {assign}")
        for pdo, entries in MAPS.items():
            if maps[pdo] != entries:
                problems.append(f"slave {i + 1}: {pdo:04X}h read back {L.fmt_map(maps[pdo])}")
        return problems

    if not L.attempt(m, i, "remap both axes", write_and_read):
        raise L.Fatal("remap")
    return L.Layout(MAPS, ASSIGN[0x1C12]), L.Layout(MAPS, ASSIGN[0x1C13])


class Figures:
    """What the soak counted."""

    def __init__(self, axes):
        self.cycles = 0
        self.lost = 0
        self.wkc_errors = 0
        self.wkc_seen = {}
        self.ferr = {a.name: 0 for a in axes}  # undisturbed
        self.ferr_all = {a.name: 0 for a in axes}
        self.ferr_interval = 0  # undisturbed, since the last progress line
        self.judged = 0  # cycles on an undisturbed line
        self.al_changes = {}  # slave -> [(time s, state, AL code, judged as)]
        self.state_reads_lost = 0  # AL state reads that came back without the states
        self.defects = []

    def al_total(self):
        return sum(len(v) for v in self.al_changes.values())


class Soak:
    def __init__(self, m, args, layouts):
        self.m = m
        self.args = args
        self.cyc = L.Cycle(m)
        self.line = L.Line(m, self.cyc, layouts)
        self.axes = [a for row in self.line.axes for a in row]
        self.fig = Figures(self.axes)
        n = len(self.axes)
        two_pi = 2 * math.pi
        self.omega = {a.name: two_pi / (args.period * 1000 * (1 + k / n)) for k, a in enumerate(self.axes)}
        self.amp = args.amplitude * L.INC_PER_REV
        self.start = {}
        self.slot0 = 0
        self.skip0 = 0
        self.t0 = None
        self.emcys = None
        self.state_due = False
        self.settle_until = 0
        self.gap_at = 0
        self.stopped = None
        self.t_end = None

    # --- set-points -----------------------------------------------------------

    def hold_here(self):
        """The curve starts again from where the axes are (1 − cos: from
        standstill, no jump in position or velocity)."""
        self.start = {a.name: a.pos(self.line.inp[a.slave]) for a in self.axes}
        self.slot0 = self.cyc.n + self.cyc.skipped
        self.settle_until = self.cyc.n + L.SETTLE_PERIODS

    def curve(self, slot):
        k = slot - self.slot0
        outs = self.line.outs
        for a in self.axes:
            a.write(outs[a.slave], 0x0F, 8, self.start[a.name] + round(self.amp * (1 - math.cos(self.omega[a.name] * k))))

    # --- the run --------------------------------------------------------------

    def enable(self):
        here = {a.name: a.pos(self.line.inp[a.slave]) for a in self.axes}
        for cw, pattern, what in [(0x06, L.READY, "Ready to switch on"), (0x07, L.SWITCHED_ON, "Switched on"), (0x0F, L.ENABLED, "Operation enabled")]:
            L.step(self.line, self.axes, cw, pattern, what, lambda a: here[a.name])
        self.hold_here()

    def left_out(self):
        return self.cyc.skipped - self.skip0

    def elapsed(self):
        return (self.t_end or time.monotonic()) - self.t0

    def read_states(self):
        """The AL state of every drive (SOEM's read_state); False when the
        read came back without them (state 0: its frame lost or answered
        late), then the caller judges nothing now and reads again next cycle."""
        self.m.read_state()
        if all(s.state != 0 for s in self.m.slaves):
            self.state_due = False
            return True
        self.fig.state_reads_lost += 1
        self.state_due = True
        return False

    def judge(self, what, faulted=()):
        """After a drive seen out of Op or an axis out of Operation enabled:
        was it the drives' specified reaction to a master stall (line.py's
        rule)? A drive out of Op must show AL 0033h after at least
        LATE_FRAME_LIMIT periods in a row without a frame in the window; an
        axis fault (every drive in Op) must be 603Fh 8612h (event 78/3) after
        more than I423. Then it is printed as STALL and True; else False."""
        m = self.m
        longest = self.cyc.stall(600)
        codes = {s.al_status for s in m.slaves if s.state != OP}
        if codes:
            need = L.LATE_FRAME_LIMIT if codes == {0x0033} else None
            reaction = "AL 0033h"
        else:
            errors = {a.in_l.get(self.line.inp[a.slave], 0x603F + a.base) for a in faulted}
            need = L.I423_PERIODS + 1 if errors == {L.EXTRAPOLATION_OVERRUN} else None
            reaction = "event 78/3 (603Fh 8612h)"
        if need is None or longest < need:
            say(f"(not a stall: {reaction if need else 'no specified reaction to a stall'}, the longest run of periods without a frame in time {longest})")
            return False
        self.line.stalls.append(what)
        say(
            f"STALL at {self.elapsed():.1f} s: {what}, after {longest} SYNC0 periods in a row without a frame in the "
            f"drives' window (the machine did not run the master or the simulator in time): {reaction}, the drives' "
            f"specified reaction; recovering ({len(self.line.stalls)} of at most {self.args.max_stalls})"
        )
        if len(self.line.stalls) > self.args.max_stalls:
            raise TooManyStalls(f"the machine stalled the line {len(self.line.stalls)} times")
        return True

    def note_states(self):
        """Reads the AL states: a drive out of Op is an AL state change,
        judged, recovered. False when it recovered (the cycle is done)."""
        if not self.read_states():
            return True
        out = [(i, s.state, s.al_status) for i, s in enumerate(self.m.slaves) if s.state != OP]
        if not out:
            return True
        what = "left Op: " + ", ".join(f"slave {i + 1} {st:#04x}/{code:04X}h" for i, st, code in out)
        stalled = self.judge(what)
        judged = "after a master stall" if stalled else "DEFECT"
        for i, st, code in out:
            self.fig.al_changes.setdefault(i, []).append((self.elapsed(), st, code, judged))
        if not stalled:
            self.defect(f"{what} (no master stall explains it)")
        self.recover()
        return False

    def recover(self):
        """Op again, the faults reset, every axis enabled; the sine goes on
        from where the axes are."""
        while True:
            self.line.recover()
            try:
                self.enable()
                return
            except L.Stall:
                pass

    def defect(self, what):
        what = f"at {self.elapsed():.3f} s (cycle {self.fig.cycles}): {what}"
        self.fig.defects.append(what)
        L.check(False, what)
        raise L.Fatal(what)

    def check_axes(self):
        """Every axis in Operation enabled: True. Else the states are read
        and it is judged (a stall is recovered): False."""
        faulted = [a for a in self.axes if not L.sw_is(a.sw(self.line.inp[a.slave]), L.ENABLED)]
        if not faulted:
            return True
        # a drive out of Op takes its axes along: judged there
        if not self.note_states() or self.state_due:
            return False
        inp = self.line.inp
        what = "left Operation enabled: " + ", ".join(f"{a.name} statusword {a.sw(inp[a.slave]):#06x}" for a in faulted[:4])
        if len(faulted) > 4:
            what += f" and {len(faulted) - 4} more"
        if self.judge(what, faulted):
            self.recover()
            return False
        self.defect(f"{what} (no master stall explains it; states {L.state_report(self.m)})")
        return False

    def run(self):
        args, cyc = self.args, self.cyc
        self.t0 = time.monotonic()
        # the counts of the set-up (alignment, Op, enable) are not the soak's
        # (cyc.skipped is the slot clock's: kept, counted from here)
        cyc.outside = cyc.max_delta = 0
        self.skip0 = cyc.skipped
        next_progress = self.t0 + args.progress
        say(
            f"SOAK: moving, {len(self.axes)} axes in csp, A (1 - cos) with A = {args.amplitude} rev, periods "
            f"{args.period:.1f}..{args.period * 2:.1f} s, for {args.seconds:.0f} s"
        )
        try:
            self.soak(next_progress)
        finally:
            self.t_end = time.monotonic()

    def soak(self, next_progress):
        args, cyc, line, fig = self.args, self.cyc, self.line, self.fig
        last_cycles = 0
        expected = cyc.expected_wkc
        while True:
            now = time.monotonic()
            if now - self.t0 >= args.seconds:
                break
            if now >= next_progress:
                next_progress += args.progress
                self.progress(fig.cycles - last_cycles)
                last_cycles = fig.cycles
                fig.ferr_interval = 0
            wkc = line.cycle(self.curve)
            fig.cycles += 1
            if wkc == EC_NOFRAME:
                # nothing came back: nothing to judge (a line that stays
                # silent leaves its drives out of Op, seen with the next read)
                fig.lost += 1
                continue
            if wkc != expected:
                fig.wkc_errors += 1
                fig.wkc_seen[wkc] = fig.wkc_seen.get(wkc, 0) + 1
            if (wkc != expected or self.state_due or cyc.n % STATE_EVERY == 0) and not self.note_states():
                continue
            if wkc != expected or not self.check_axes():
                continue
            # following errors of axes that follow: not in the cycles after an enable
            if cyc.n < self.settle_until:
                continue
            if cyc.stall(10) >= L.GAP_PERIODS:
                self.gap_at = cyc.n
            undisturbed = cyc.n - self.gap_at > SETTLE_CYCLES
            if undisturbed:
                fig.judged += 1
            for a in self.axes:
                e = abs(a.ferr(line.inp[a.slave]))
                if e > fig.ferr_all[a.name]:
                    fig.ferr_all[a.name] = e
                if undisturbed:
                    if e > fig.ferr[a.name]:
                        fig.ferr[a.name] = e
                    if e > fig.ferr_interval:
                        fig.ferr_interval = e
        self.progress(fig.cycles - last_cycles)

    def progress(self, cycles):
        fig, cyc = self.fig, self.cyc
        say(
            f"soak {self.elapsed():6.0f} s: {fig.cycles} cycles (+{cycles}), {fig.lost} lost, {fig.wkc_errors} WKC errors, "
            f"{self.left_out()} slots left out, {cyc.outside} outside the window, {len(self.line.stalls)} stall(s), "
            f"{fig.al_total()} AL change(s); following error max {fig.ferr_interval} inc in this interval"
        )


def report(soak, pll):
    fig, cyc, args = soak.fig, soak.cyc, soak.args
    n = len(soak.m.slaves)
    seconds = soak.elapsed()
    say(f"\nsoak report: {n} drives, {len(soak.axes)} axes in csp at 1 ms, {seconds:.1f} s of {args.seconds:.0f} s")
    if soak.stopped:
        say(f"  stopped early        {soak.stopped}")
    say(f"  cycles               {fig.cycles} ({fig.judged} on an undisturbed line)")
    say(f"  lost frames          {fig.lost}")
    wkcs = ", ".join(f"{w}: {c}x" for w, c in sorted(fig.wkc_seen.items()))
    say(f"  WKC errors           {fig.wkc_errors} (expected {cyc.expected_wkc}{'; seen ' + wkcs if wkcs else ''})")
    say(f"  slots left out       {soak.left_out()} (the master late for its slot)")
    say(f"  outside the window   {cyc.outside} (phase error up to {cyc.max_delta / 1000:.0f} us)")
    stalls = soak.line.stalls
    say(f"  master stalls        {len(stalls)}{' (recovered: ' + '; '.join(stalls) + ')' if stalls else ''}")
    say(f"  AL state changes     {fig.al_total()} (AL state reads without an answer, repeated: {fig.state_reads_lost})")
    for i, changes in sorted(fig.al_changes.items()):
        stall = sum(1 for c in changes if c[3] != "DEFECT")
        codes = ", ".join(sorted({f"{st:#04x}/{code:04X}h" for _, st, code, _ in changes}))
        say(
            f"    slave {i + 1}: {len(changes)} ({stall} after a master stall, {len(changes) - stall} DEFECT), "
            f"state/AL status code {codes}, the first at {changes[0][0]:.1f} s"
        )
    say("  following error max, inc (undisturbed line / all cycles with the axes enabled), per drive: axis A, axis B")
    for row in soak.line.axes:
        a, b = row
        say(
            f"    slave {a.slave + 1:>2}: A {fig.ferr[a.name]:>6} / {fig.ferr_all[a.name]:>7}   "
            f"B {fig.ferr[b.name]:>6} / {fig.ferr_all[b.name]:>7}"
        )
    say("  at the end, per drive: A298 PLL status, phase locked, error; A261 late frames; EMCYs of the run")
    for i, (a298, late, codes) in enumerate(pll):
        emcy = ", ".join(f"{c:04X}h" for c in codes) or "none"
        if a298 is None:
            say(f"    slave {i + 1:>2}: A298/A261 not read; EMCYs {emcy}")
            continue
        say(
            f"    slave {i + 1:>2}: A298 {a298:#06x}, locked {'yes' if a298 & PHASE_LOCKED else 'NO'}, "
            f"error {'YES' if a298 & PLL_ERROR else 'no'}; late frames {late}; EMCYs {emcy}"
        )
    ferr = max(fig.ferr.values(), default=0)
    ferr_all = max(fig.ferr_all.values(), default=0)
    locked = sum(1 for a298, _, _ in pll if a298 is not None and a298 & PHASE_LOCKED)
    say(
        f"SOAK RESULT: seconds={seconds:.1f} drives={n} cycles={fig.cycles} lost={fig.lost} wkc_errors={fig.wkc_errors} "
        f"left_out={soak.left_out()} outside={cyc.outside} stalls={len(soak.line.stalls)} al_changes={fig.al_total()} "
        f"ferr_max_inc={ferr} ferr_max_all_inc={ferr_all} pll_locked={locked}/{n} defects={len(fig.defects)}"
    )


def end_diagnostics(m, emcys):
    """(A298, A261[2], [EMCY codes]) per drive, by SDO (None when it could
    not be read), the EMCYs the drive sent during the run."""
    out = []
    for i, s in enumerate(m.slaves):
        got = []
        codes = [e.error_code for e in emcys.drain(m, i)]

        def read():
            got[:] = [L.sdo_u(s, A298, 0), L.sdo_u(s, A261, 3)]
            return []

        if not L.attempt(m, i, "A298/A261", read):
            got = [None, None]
        codes += [e.error_code for e in emcys.drain(m, i)]
        out.append((got[0], got[1], codes))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--iface", required=True)
    ap.add_argument("--slaves", type=int, default=16)
    ap.add_argument("--seconds", type=float, default=60.0, help="time in csp with moving set-points, s")
    ap.add_argument("--progress", type=float, default=10.0, help="a progress line every this many s")
    ap.add_argument("--amplitude", type=float, default=1.0, help="A of A (1 - cos), revolutions (the stroke is 2 A)")
    ap.add_argument("--period", type=float, default=4.0, help="sine period of the first axis, s (the last: twice)")
    ap.add_argument(
        "--max-stalls",
        type=int,
        help="master stalls recovered before the run stops early (default: one per 6 s of --seconds, at least 20)",
    )
    ap.add_argument("--cpu", type=int, help="pin the master to this CPU (serve on another: they do not take turns)")
    args = ap.parse_args()
    if args.max_stalls is None:
        args.max_stalls = max(20, int(args.seconds / 6))
    L.MAX_STALLS = args.max_stalls
    L.priority()
    if args.cpu is not None:
        os.sched_setaffinity(0, {args.cpu})
        say(f"master: pinned to CPU {args.cpu}")
    m = pysoem.Master()
    m.open(args.iface)
    soak = None
    try:
        soak = setup(m, args)
        try:
            soak.run()
        except TooManyStalls as e:
            soak.stopped = str(e)
            say(f"soak stopped early: {e}")
        except L.Fatal as e:
            # a defect (already counted) or a line that did not come back
            if not soak.fig.defects:
                L.check(False, f"soak stopped: {e}")
            soak.stopped = str(e)
        finally:
            L.real_time(False)
            gc.enable()
        end_states = L.state_report(m)
        in_op = m.read_state() == OP and all(s.state == OP for s in m.slaves)
        L.check(in_op, f"every drive in Op at the end: {end_states}")
        m.state = SAFEOP
        m.write_state()
        L.wait_states(m, soak.cyc, SAFEOP, 1000)
        pll = end_diagnostics(m, soak.emcys)
        for i, (a298, _, _) in enumerate(pll):
            L.check(a298 is not None and a298 & PHASE_LOCKED and not a298 & PLL_ERROR, f"slave {i + 1}: PLL phase locked without error at the end (A298 {a298})")
        report(soak, pll)
        m.state = INIT
        m.write_state()
        m.state_check(INIT, 2_000_000)
    except L.Fatal as e:
        L.check(False, f"stopped: {e}")
    except L.SOEM_ERRORS as e:
        L.check(False, f"stopped by SOEM: {type(e).__name__} {vars(e)}")
    finally:
        m.close()
    if L.failures:
        say(f"\n{len(L.failures)} defect(s):")
        for f in L.failures:
            say(f"  {f}")
        return 1
    say("\nno defect seen")
    return 0


def setup(m, args):
    L.scan(m, args.slaves)
    L.check(m.read_state() == PREOP, f"every slave in Pre-Op after config_init: {L.state_report(m)}")
    layouts = [remap(m, i) for i in range(len(m.slaves))]
    m.manual_state_change = 1
    # SOEM sizes each slave's process data from the PDO objects it reads by
    # SDO in config_map; a mailbox exchange it gave up on (a loaded machine)
    # leaves a slave sized from the SII instead: mapped again
    size = L.config_map(m, layouts)
    out_l, in_l = layouts[0]
    say(f"config_map: IO map {size} bytes; per slave {out_l.bytes} output, {in_l.bytes} input bytes; expected WKC {m.expected_wkc}")
    if not m.config_dc():
        raise L.Fatal("config_dc: no DC")
    # EMCYs go to callbacks (read whenever SOEM reads a mailbox), reported at the end
    emcys = L.Emcys(m)
    for s in m.slaves:
        s.dc_sync(True, L.CYCLE_NS)
    L.real_time(True)
    gc.disable()
    soak = Soak(m, args, layouts)
    soak.emcys = emcys
    cyc = soak.cyc
    L.align(cyc)
    say(f"aligned to the reference clock after {cyc.n} cycles, phase error {cyc.delta / 1000:.1f} us")
    m.state = SAFEOP
    m.write_state()
    if not L.wait_states(m, cyc, SAFEOP, 3000):
        raise L.Fatal(f"Safe-Op not reached: {L.state_report(m)}")
    for _ in range(20):
        for a in soak.axes:
            a.write(soak.line.outs[a.slave], 0, 8, a.pos(soak.line.inp[a.slave]))
        soak.line.cycle()
    m.state = OP
    m.write_state()
    cyc.counting = True
    if not L.wait_states(m, cyc, OP, 3000):
        raise L.Fatal(f"Op not reached: {L.state_report(m)}")
    say(f"Op after {cyc.op_cycles} cycles: {L.state_report(m)}")
    while True:
        try:
            soak.enable()
            break
        except L.Stall:
            soak.line.recover()
    say(f"every axis in Operation enabled, csp; {L.state_report(m)}")
    return soak


if __name__ == "__main__":
    sys.exit(main())
