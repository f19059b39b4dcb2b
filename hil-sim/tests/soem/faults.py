#!/usr/bin/env python3
"""Fault cases of the fault matrix (issue 19, docs/fault-matrix.md) run by
SOEM (through pysoem) against `hil-sim serve` over raw Ethernet.

Run by `hil-sim/tests/soem.rs` as root inside the master's network namespace
(or by hand against any `serve --slaves N`). It builds on line.py's master
and soak.py's mapping (imported from beside this file): scan, A258 and 6065h
written in Pre-Op, both axes' PDOs assigned, DC SYNC0 1 ms with the master's
cycle aligned to the reference clock (soem_cycle.py's Cycle through line:
SOEM's ec_sync PI), Safe-Op, Op, axis A of every drive enabled in profile velocity (pv, target
velocity 0: no cyclic set-point, so I423's extrapolation limit, C-117, does
not apply), axis B left in Switch on disabled.

  --case pause    A258 = 100 ms. Row 61: the master sends no frame for 20 ms
                  (shorter than A258). Row 62: for 500 ms (beyond it); then
                  the master acknowledges, asks for Op and resets the faults.
  --case restart  Row 63, in free run (--dc: DC SYNC0 1 ms): a first master
                  process (this script, --role first-master) writes A258 =
                  100 ms and 6065h, brings the line to Op with axis A
                  enabled and is killed (SIGKILL); 500 ms later the AL
                  status registers are read by one raw APRD frame (SOEM's
                  config_init would reset every drive to Init first), then
                  a new SOEM master scans, reads what the drives kept and
                  brings the line to Op again.
  --case stop-restart
                  row 64: a master stops as SOEM's samples do (Op, Safe-Op,
                  Init, socket closed, SYNC0 left active) and a new one
                  brings the line to Op under DC. Specified: Op at the first
                  request (the drive refused it with AL 0034h until Pre-Op
                  → Safe-Op cleared a PLL fault latched below Safe-Op).

Each case prints one line `ROW <order> <seen>`: the end the master read,
written in the words of hil_sim::matrix (the Rust test compares it with the
expected end and writes the row). The values come from the drives: the AL
status (SOEM's read_state), the EMCYs (SOEM's emergency callback while it
reads the mailbox), 603Fh/683Fh and 6041h/6841h by SDO, the newest message
of the diagnosis history 10F3h, the parameters by SDO.

A loaded machine does not always run the master in time. A stall of the
master is told apart from the case by the drives' own clock (the DC time
each frame carries back): the longest time between two frames that came
back since the case began. Only the drives' specified reaction to a stall
where the case expects the line to stay in Op (AL 001Bh when that time,
a deliberate pause stretched by a stall included, reached A258; AL 0033h
after at least 5 frames outside the drives' window) makes a case be
repeated (STALL, at most MAX_TRIES times, from Op with the faults reset
and axis A enabled again); anything else is the case's end and is printed
as it was read.
"""
import argparse
import gc
import os
import signal
import socket
import struct
import subprocess
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import line as L  # noqa: E402  (line.py beside this file)
import pysoem  # noqa: E402
import soak as S  # noqa: E402  (soak.py: both axes' maps)

say = L.say
OP, SAFEOP, PREOP, INIT, ERR, ACK = L.OP, L.SAFEOP, L.PREOP, L.INIT, L.ERR, L.ACK

A258 = 0x2000 + 258
A258_MS = 100
SHORT_MS = 20
LONG_MS = 500
# 6065h following error window, written before the faults (must be kept)
WINDOW_BEFORE_PAUSE = 123456
WINDOW_BEFORE_RESTART = 654321
PV = 3
MAX_TRIES = 3
PDO_TIMEOUT = 0x001B
SYNC_IO_ERROR = 0x0033
AXES = ((0, "A"), (0x800, "B"))


def row(order, seen):
    say(f"ROW {order} {seen}")


# --- words as hil_sim::matrix writes them -----------------------------------


def al_text(state, code):
    name = {1: "Init", 2: "Pre-Op", 3: "Bootstrap", 4: "Safe-Op", 8: "Op"}.get(state & 0x0F, "?")
    return f"{name}{' + ERR' if state & ERR else ''}, AL {code:04X}h"


def cia402(sw):
    return {
        0x40: "Switch on disabled",
        0x60: "Switch on disabled",
        0x21: "Ready to switch on",
        0x23: "Switched on",
        0x27: "Operation enabled",
        0x07: "Quick stop active",
        0x0F: "Fault reaction active",
        0x2F: "Fault reaction active",
        0x08: "Fault",
        0x28: "Fault",
    }.get(sw & 0x6F, "Not ready")


def emcy_text(got):
    if not got:
        return "no EMCY"
    return " + ".join(f"EMCY {e.error_code:04X}h/{e.error_reg:02X}h event {e.b1} cause {e.w1 & 0xFF}" for e in got)


def per_drive(texts):
    """One text for every drive when they agree, else one per drive."""
    if len(set(texts)) == 1:
        who = "drive 1" if len(texts) == 1 else "drives " + ", ".join(str(i + 1) for i in range(len(texts)))
        return f"{who}: {texts[0]}"
    return "; ".join(f"drive {i + 1}: {t}" for i, t in enumerate(texts))


# --- SDO with SOEM's repetition (soem_mailbox.py's attempt) -----------------


def sdo_bytes(m, i, index, sub):
    got = []

    def read():
        got[:] = [m.slaves[i].sdo_read(index, sub)]
        return []

    if not L.attempt(m, i, f"read {index:04X}h:{sub:02X}", read):
        raise L.Fatal(f"slave {i + 1}: {index:04X}h:{sub:02X} not read")
    return got[0]


def sdo_u(m, i, index, sub):
    return L.u(sdo_bytes(m, i, index, sub))


def history(m, i, between=lambda: None, since=None):
    """The newest message of 10F3h in the words of the ethercrab rows;
    with `since` (10F3h:02 read before the case) only a message that came
    after it ("history: no new message" else)."""
    newest = sdo_u(m, i, 0x10F3, 2)
    between()
    if since is not None and newest == since:
        return "history: no new message"
    if newest == 0:
        return "history empty"
    msg = sdo_bytes(m, i, 0x10F3, newest)
    between()
    code = L.u(msg[0:4])
    kind = {0: "info", 1: "warning"}.get(L.u(msg[4:6]) & 0x0F, "error")
    if code & 0xFFFF == 0xE800:
        # parameters: flags u16 + u32 each, after the 16 fixed bytes
        axis, ev = L.u(msg[18:22]), L.u(msg[24:28])
        return f"history: {kind} {code >> 16:04X}h axis {'A' if axis == 0 else 'B'} event {ev >> 8}/{ev & 0xFF}"
    if code & 0xFFFF_0000 == 0xE000_0000:
        return f"history: {kind} AL {code & 0xFFFF:04X}h"
    return f"history: {kind} {code:08X}h"


def drive_words(m, i, emcys, between=lambda: None, since=None):
    """Axis states (6041h/6841h), the EMCYs, 603Fh/683Fh and the history of
    drive i, by SDO; the EMCYs are those SOEM found in the mailbox until now.
    `between()` runs after each read (cycles, where the line is in Op);
    `since`: see `history`."""

    def read(index):
        value = sdo_u(m, i, index, 0)
        between()
        return value

    states = [cia402(read(0x6041 + base)) for base, _ in AXES]
    codes = [read(0x603F + base) for base, _ in AXES]
    hist = history(m, i, between, since)
    em = emcy_text(emcys.drain(m, i))
    return (
        f"axis A {states[0]}, axis B {states[1]}; {em}; 603Fh {codes[0]:04X}h, 683Fh {codes[1]:04X}h; {hist}"
    )


# --- the line ---------------------------------------------------------------


class Cycle(L.Cycle):
    """soem_cycle.py's cycle that also keeps, by the drives' clock (the DC time a
    frame carries back), the longest time between two frames that came back
    since `watch()`."""

    def __init__(self, m):
        super().__init__(m)
        self.last_dc = None
        self.max_gap_ns = 0
        self.counting = True

    def run(self, fill=None):
        wkc = super().run(fill)
        if wkc > 0:
            dc = self.m.dc_time
            if self.last_dc is not None:
                self.max_gap_ns = max(self.max_gap_ns, dc - self.last_dc)
            self.last_dc = dc
        return wkc

    def watch(self):
        self.max_gap_ns = 0
        self.outside = 0


class Bus:
    """A master with the line in cyclic exchange."""

    def __init__(self, m, layouts, emcys):
        self.m = m
        self.emcys = emcys
        self.cyc = Cycle(m)
        self.line = L.Line(m, self.cyc, layouts)
        self.n = len(m.slaves)
        self.history_before = [None] * self.n

    def cycles(self, k, fill=None):
        for _ in range(k):
            self.line.cycle(fill)

    def set_axes(self, a_cw, a_mode, b_cw=0):
        """Controlword and mode of axis A of every drive, the controlword of
        axis B (csp, never enabled); the targets at the actual positions."""
        for a, b in self.line.axes:
            a.write(self.line.outs[a.slave], a_cw, a_mode, a.pos(self.line.inp[a.slave]))
            b.write(self.line.outs[b.slave], b_cw, 8, b.pos(self.line.inp[b.slave]))

    def fault_reset(self):
        """Controlword bit 7 edge on both axes (C-017), the axes left disabled."""
        for cw in (0x00, 0x80, 0x00):
            self.set_axes(cw, PV, cw)
            self.cycles(20)

    def axis_states(self):
        return [(cia402(a.sw(self.line.inp[a.slave])), cia402(b.sw(self.line.inp[b.slave]))) for a, b in self.line.axes]

    def states(self):
        """(state, AL status code) of every drive; read until SOEM's read
        came back with all of them."""
        for _ in range(20):
            self.m.read_state()
            got = [(s.state, s.al_status) for s in self.m.slaves]
            if all(st for st, _ in got):
                return got
            self.cycles(1)
        return got

    def enable_a(self):
        """Fault reset, then axis A of every drive Shutdown, Switch on,
        Enable operation in pv; True when every axis A is enabled and every
        axis B in Switch on disabled."""
        self.fault_reset()
        for cw, want in ((0x06, "Ready to switch on"), (0x07, "Switched on"), (0x0F, "Operation enabled")):
            for _ in range(300):
                self.set_axes(cw, PV)
                self.cycles(1)
                if all(a == want for a, _ in self.axis_states()):
                    break
            else:
                return False
        return all(b == "Switch on disabled" for _, b in self.axis_states())

    def to_op(self):
        """Acknowledge an error, Safe-Op, Op (SOEM's ecatcheck); True when
        every drive is in Op."""
        m = self.m
        for k in range(3000):
            self.set_axes(0, PV)
            self.cycles(1)
            if k % 10:
                continue
            got = self.states()
            if all(st == OP for st, _ in got):
                return True
            for s in m.slaves:
                if s.state & ERR:
                    s.state = (s.state & 0x0F) | ACK
                    s.write_state()
                elif s.state == SAFEOP:
                    s.state = OP
                    s.write_state()
        return False

    def ready(self):
        """Op, axis A enabled in pv, axis B Switch on disabled, the
        EMCYs so far read and dropped (printed), the newest message of each
        drive's history noted, the stall watch started: a case (or its
        repetition after a stall) starts from here."""
        for k in range(MAX_TRIES + 1):
            if self.to_op() and self.enable_a():
                self.history_before = []
                for i in range(self.n):
                    before = self.emcys.drain(self.m, i)
                    if before:
                        say(f"drive {i + 1}: EMCYs before the case: {emcy_text(before)}")
                    self.history_before.append(sdo_u(self.m, i, 0x10F3, 2))
                    self.cycles(10)
                self.cycles(20)
                # judged after the reads: a stall during them is not the case's
                if all_op(self.states()) and self.axis_states() == [("Operation enabled", "Switch on disabled")] * self.n:
                    self.cyc.watch()
                    return
            say(f"(line not ready: {L.state_report(self.m)}, axes {self.axis_states()}; again)")
        raise L.Fatal(f"the line did not come to Op with axis A enabled: {L.state_report(self.m)}")

    def stalled(self, got):
        """Were the drives out of Op in `got` their specified reaction to a
        stall of the master rather than to the case? By the drives' clock
        since `watch()`: AL 001Bh after a time between two frames that came
        back (a deliberate pause included) at least as long as A258, AL 0033h
        after at least 5 frames outside the window."""
        gap_ms = self.cyc.max_gap_ns / 1e6
        out = [code for st, code in got if st != OP]
        if not out:
            return False
        explained = all(
            (code == PDO_TIMEOUT and gap_ms >= A258_MS - 1) or (code == SYNC_IO_ERROR and self.cyc.outside >= L.LATE_FRAME_LIMIT)
            for code in out
        )
        say(
            f"{'STALL' if explained else '(not a stall)'}: {L.state_report(self.m)} after {gap_ms:.1f} ms at most between "
            f"two frames (by the drives' clock), {self.cyc.outside} frames outside the window"
        )
        return explained


def bring_up(m, n, writes=(), scan=True, dc=True, must_op=True):
    """Scan (unless done), `writes` (index, sub, bytes) by SDO in Pre-Op,
    both axes' maps, DC SYNC0 1 ms (free run without `dc`; the master's
    cycle aligned to the reference clock either way), Safe-Op, Op (a
    failure unless `must_op` is False); the Bus."""
    if scan:
        L.scan(m, n)
    L.check(m.read_state() == PREOP, f"every drive in Pre-Op: {L.state_report(m)}")
    for i in range(n):
        for index, sub, data in writes:
            L.write(m, i, index, sub, data)
    layouts = [S.remap(m, i) for i in range(n)]
    m.manual_state_change = 1
    L.config_map(m, layouts)
    if not m.config_dc():
        raise L.Fatal("config_dc: no DC")
    emcys = L.Emcys(m)
    if dc:
        for s in m.slaves:
            s.dc_sync(True, L.CYCLE_NS)
    L.real_time(True)
    gc.disable()
    bus = Bus(m, layouts, emcys)
    L.align(bus.cyc)
    say(f"aligned to the reference clock after {bus.cyc.n} cycles, phase error {bus.cyc.delta / 1000:.1f} us")
    # frames outside the drives' window count from here (not while aligning)
    bus.cyc.watch()
    m.state = SAFEOP
    m.write_state()
    if not L.wait_states(m, bus.cyc, SAFEOP, 3000):
        raise L.Fatal(f"Safe-Op not reached: {L.state_report(m)}")
    bus.set_axes(0, PV)
    bus.cycles(20)
    got = request_op(bus)
    if must_op and not all_op(got) and not (bus.stalled(got) and bus.to_op()):
        raise L.Fatal(f"Op not reached: {L.state_report(m)}")
    say(f"Op requested: {L.state_report(m)}")
    return bus


def request_op(bus):
    """Safe-Op -> Op (SOEM's write_state), cycles until every drive is in
    Op or one shows an error (at most 3 s); the states then."""
    m = bus.m
    m.state = OP
    m.write_state()
    for _ in range(300):
        bus.cycles(10)
        got = bus.states()
        if all_op(got) or any(st & ERR for st, _ in got):
            break
    return got


def pause(bus, ms):
    """No frame from the master for `ms` (the cycle leaves the slots out)."""
    say(f"pause: no frame for {ms} ms")
    time.sleep(ms / 1000)


# --- rows 61 and 62: pauses of the master's frames ---------------------------


def all_op(got):
    return all(st == OP for st, _ in got)


def case_pause(m, n):
    writes = [(A258, 0, A258_MS.to_bytes(2, "little")), (0x6065, 0, WINDOW_BEFORE_PAUSE.to_bytes(4, "little"))]
    bus = bring_up(m, n, writes)

    def between():
        bus.cycles(10)

    # 61: shorter than A258; what the drives show read in Op (pv: no
    # set-point to miss while SOEM waits for an SDO answer)
    for attempt in range(1, MAX_TRIES + 1):
        bus.ready()
        bus.cycles(200)
        pause(bus, SHORT_MS)
        bus.cycles(300)
        got = bus.states()
        texts = [f"{al_text(*got[i])}; {drive_words(m, i, bus.emcys, between, bus.history_before[i])}" for i in range(n)]
        final = bus.states()
        if not (all_op(got) and all_op(final)) and bus.stalled(final) and attempt < MAX_TRIES:
            continue
        say(f"axes from the process data: {bus.axis_states()}; at the end: {L.state_report(m)}")
        row("61", per_drive(texts))
        break

    # 62: beyond A258; acknowledge, Op, fault reset; the parameters written before
    for attempt in range(1, MAX_TRIES + 1):
        bus.ready()
        bus.cycles(200)
        got = bus.states()
        if not all_op(got):
            if bus.stalled(got) and attempt < MAX_TRIES:
                continue
            raise L.Fatal(f"the drives left Op before the pause: {L.state_report(m)}")
        pause(bus, LONG_MS)
        bus.cycles(50)
        got = bus.states()
        texts = [f"{al_text(*got[i])}; {drive_words(m, i, bus.emcys, between, bus.history_before[i])}" for i in range(n)]
        recovered = bus.to_op()
        bus.cyc.watch()
        bus.fault_reset()
        axes = bus.axis_states()
        kept = []
        for i in range(n):
            window = sdo_u(m, i, 0x6065, 0)
            between()
            a258 = sdo_u(m, i, A258, 0)
            between()
            kept.append(f"6065h {window}, A258 {a258}")
        after = bus.states()
        if not all_op(after) and bus.stalled(after) and attempt < MAX_TRIES:
            continue
        say(f"Op again: {recovered}")
        again = per_drive(
            [f"{al_text(*after[i])}; a fault reset: axis A {axes[i][0]}, axis B {axes[i][1]}; {kept[i]}" for i in range(n)]
        )
        row("62", f"{per_drive(texts)}; the master acknowledges and requests Op: {again}")
        break
    leave(bus)


def leave(bus):
    m = bus.m
    m.state = SAFEOP
    m.write_state()
    L.wait_states(m, bus.cyc, SAFEOP, 1000)
    L.real_time(False)
    gc.enable()
    m.state = INIT
    m.write_state()
    m.state_check(INIT, 2_000_000)


# --- row 63: the master killed in Op, a new master ----------------------------


def first_master(args):
    """The master that is killed: A258 and 6065h written, Op, axis A
    enabled; READY, then the cycle goes on until SIGKILL."""
    L.priority()
    m = pysoem.Master()
    m.open(args.iface)
    writes = [(A258, 0, A258_MS.to_bytes(2, "little")), (0x6065, 0, WINDOW_BEFORE_RESTART.to_bytes(4, "little"))]
    bus = bring_up(m, args.slaves, writes, dc=args.dc)
    bus.ready()
    bus.cycles(100)
    say(f"READY {L.state_report(m)}, axes {bus.axis_states()}")
    end = time.monotonic() + 60
    while time.monotonic() < end:
        bus.set_axes(0x0F, PV)
        bus.cycles(1)
    say("first master: not killed within 60 s")
    return 1


def raw_al_status(iface, n):
    """(AL status, AL status code) of drives 1..n by one frame of APRD
    datagrams (0130h, 6 bytes), as any master reads them before it changes
    anything."""
    sock = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.htons(0x88A4))
    sock.bind((iface, 0))
    mac = sock.getsockname()[4]
    body = b""
    for k in range(n):
        more = 0x8000 if k < n - 1 else 0
        body += struct.pack("<BBHHHH", 0x01, 0xA0 + k, (-k) & 0xFFFF, 0x0130, 6 | more, 0) + bytes(6) + b"\x00\x00"
    frame = b"\xff" * 6 + mac + b"\x88\xa4" + struct.pack("<H", len(body) | 0x1000) + body
    frame += bytes(max(0, 60 - len(frame)))
    sock.settimeout(0.2)
    for _ in range(5):
        sock.send(frame)
        end = time.monotonic() + 0.2
        while time.monotonic() < end:
            try:
                data, addr = sock.recvfrom(2048)
            except socket.timeout:
                break
            if addr[2] == socket.PACKET_OUTGOING or data[12:14] != b"\x88\xa4" or len(data) < 16 + len(body):
                continue
            got = []
            off = 16
            for k in range(n):
                if data[off + 1] != 0xA0 + k:
                    break
                status, _, code = struct.unpack_from("<HHH", data, off + 10)
                wkc = struct.unpack_from("<H", data, off + 16)[0]
                got.append((status, code, wkc))
                off += 18
            if len(got) == n:
                sock.close()
                return got
    sock.close()
    raise L.Fatal("no answer to the APRD frame")


def case_restart(args):
    n = args.slaves
    for attempt in range(1, MAX_TRIES + 1):
        child = subprocess.Popen(
            [sys.executable, "-u", os.path.abspath(__file__), "--iface", args.iface, "--slaves", str(n), "--role", "first-master"]
            + (["--dc"] if args.dc else []),
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        ready = threading.Event()

        def echo():
            for text in child.stdout:
                say(f"  first master: {text.rstrip()}")
                if text.startswith("READY"):
                    ready.set()

        reader = threading.Thread(target=echo, daemon=True)
        reader.start()
        if not ready.wait(90):
            child.kill()
            child.wait()
            raise L.Fatal("the first master did not bring the line to Op")
        time.sleep(0.3)
        os.kill(child.pid, signal.SIGKILL)
        child.wait()
        reader.join(2)
        say(f"first master killed (SIGKILL) in Op; {LONG_MS} ms without a master")
        time.sleep(LONG_MS / 1000)
        raw = raw_al_status(args.iface, n)
        say(f"APRD 0130h: {[(f'{st:#06x}', f'{code:04X}h', wkc) for st, code, wkc in raw]}")
        stopped = per_drive([al_text(st & 0xFF, code) for st, code, _ in raw])

        m = pysoem.Master()
        m.open(args.iface)
        try:
            L.scan(m, n)
            emcys = L.Emcys(m)
            m.read_state()
            scanned = []
            for i in range(n):
                st, code = m.slaves[i].state, m.slaves[i].al_status
                words = drive_words(m, i, emcys)
                window, a258 = sdo_u(m, i, 0x6065, 0), sdo_u(m, i, A258, 0)
                scanned.append(f"{al_text(st, code)}; {words}; 6065h {window}, A258 {a258}")
            # the new master's own configuration (the same maps), DC, Op
            bus = bring_up(m, n, scan=False, dc=args.dc)
            bus.emcys = emcys
            bus.cyc.watch()
            enabled = bus.enable_a()
            got = bus.states()
            if not (enabled and all_op(got)) and bus.stalled(got) and attempt < MAX_TRIES:
                leave(bus)
                continue
            axes = bus.axis_states()
            end = per_drive([f"{al_text(*got[i])}; axis A {axes[i][0]}, axis B {axes[i][1]}" for i in range(n)])
            row(
                "63",
                f"{LONG_MS} ms after the kill (AL status by a raw APRD frame): {stopped}; the new master's scan: {per_drive(scanned)}; "
                f"its maps, {'DC, ' if args.dc else ''}Safe-Op, Op, a fault reset and the enable: {end}",
            )
            leave(bus)
            return
        finally:
            m.close()


def case_stop_restart(args):
    """`ROW 64`: a master stops as
    SOEM's samples do (Op, Safe-Op, Init, the socket closed; SYNC0 left
    active, the drives' PLLs lock again in Init), a new master scans
    (SOEM's config_init deactivates SYNC0 and resets the DC registers) and
    brings the line to Op with DC again; a refused Op is acknowledged and
    requested again, and the row says so."""
    n = args.slaves
    writes = [(A258, 0, A258_MS.to_bytes(2, "little")), (0x6065, 0, WINDOW_BEFORE_RESTART.to_bytes(4, "little"))]
    for attempt in range(1, MAX_TRIES + 1):
        m = pysoem.Master()
        m.open(args.iface)
        try:
            bus = bring_up(m, n, writes)
            bus.ready()
            bus.cycles(100)
            leave(bus)
        finally:
            m.close()
        say("first master stopped (Init, SYNC0 left active, socket closed); 300 ms without a master")
        time.sleep(0.3)
        m = pysoem.Master()
        m.open(args.iface)
        try:
            L.scan(m, n)
            bus = bring_up(m, n, scan=False, must_op=False)
            got = bus.states()
            if not all_op(got) and bus.stalled(got) and attempt < MAX_TRIES:
                leave(bus)
                continue
            first = per_drive([al_text(*g) for g in got])
            acked = ""
            if not all_op(got):
                ok = bus.to_op()
                acked = f"; after an acknowledge: {per_drive([al_text(*g) for g in bus.states()])}"
                say(f"Op after the acknowledge: {ok}")
            bus.cyc.watch()
            enabled = bus.enable_a()
            axes = bus.axis_states()
            kept = []
            for i in range(n):
                window = sdo_u(m, i, 0x6065, 0)
                bus.cycles(10)
                a258 = sdo_u(m, i, A258, 0)
                bus.cycles(10)
                kept.append(f"axis A {axes[i][0]}; 6065h {window}, A258 {a258}")
            end = bus.states()
            if not (enabled and all_op(end)) and bus.stalled(end) and attempt < MAX_TRIES:
                leave(bus)
                continue
            row("64", f"the new master's scan, maps, DC, Safe-Op and Op request: {first}{acked}; the enable: {per_drive(kept)}")
            leave(bus)
            return
        finally:
            m.close()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--iface", required=True)
    ap.add_argument("--slaves", type=int, default=2)
    ap.add_argument("--case", choices=["pause", "restart", "stop-restart"])
    ap.add_argument("--dc", action="store_true", help="restart: both masters with DC SYNC0 1 ms (default free run)")
    ap.add_argument("--role", choices=["master", "first-master"], default="master")
    args = ap.parse_args()
    if args.role == "first-master":
        return first_master(args)
    if not args.case:
        ap.error("--case is needed")
    L.priority()
    with L.stops_as_checks():
        if args.case == "pause":
            m = pysoem.Master()
            m.open(args.iface)
            try:
                case_pause(m, args.slaves)
            finally:
                m.close()
        elif args.case == "restart":
            case_restart(args)
        else:
            case_stop_restart(args)
    return L.report("all cases ran")


if __name__ == "__main__":
    sys.exit(main())
