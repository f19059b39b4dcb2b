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
"""
import argparse
import contextlib
import ctypes
import gc
import math
import os
import struct
import sys
import time

import pysoem

INIT, PREOP, SAFEOP, OP = 0x01, 0x02, 0x04, 0x08
ERR = ACK = 0x10

CYCLE_NS = 1_000_000
# frames this long before SYNC0 (DC time), as a DC master places them
FRAME_LEAD_NS = 300_000
INC_PER_REV = 1 << 20
# a master this late for its slot leaves the slot out (its frame would reach
# the drive after SYNC0)
SLOT_LATE_NS = 250_000

failures = []
TRACE = open(os.environ["SOEM_TRACE"], "w") if os.environ.get("SOEM_TRACE") else None


def check(ok, what):
    if not ok:
        failures.append(what)
        print(f"FAIL: {what}", flush=True)
    return ok


class Fatal(Exception):
    """A failure after which the run cannot go on."""


def say(*a):
    print(*a, flush=True)


# --- expected values from the Rust side -------------------------------------


def load_od(path):
    """{index: (code, max_sub, dtype or None, name, {sub: (dtype, bits, access, default, name)})}"""
    od = {}
    with open(path, encoding="utf-8") as f:
        for line in f:
            p = line.rstrip("\n").split("\t")
            if p[0] == "obj":
                dtype = None if p[4] == "-" else int(p[4], 16)
                od[int(p[1], 16)] = (int(p[2]), int(p[3]), dtype, p[5], {})
            elif p[0] == "ent":
                od[int(p[1], 16)][4][int(p[2], 16)] = (
                    int(p[3], 16),
                    int(p[4]),
                    int(p[5], 16),
                    int(p[6]),
                    p[7],
                )
    return od


def name40(s):
    """A name as SOEM keeps it (EC_MAXNAME = 40 bytes)."""
    return s.encode("utf-8")[:40]


# --- SOEM helpers -------------------------------------------------------------


def u(data):
    return int.from_bytes(data, "little")


def sdo_u(s, index, sub):
    return u(s.sdo_read(index, sub))


def sdo_abort(call):
    """The abort code of an SDO call that must fail (None if it succeeded)."""
    try:
        call()
    except pysoem.SdoError as e:
        return e.abort_code
    return None


def state_of(m, i):
    m.read_state()
    s = m.slaves[i]
    return s.state, s.al_status


def request(m, i, state, timeout_s=3.0):
    """Requests `state` of slave i (SOEM's write_state), then reads the AL
    status until the slave is there or shows an error; returns (state, AL
    status code)."""
    s = m.slaves[i]
    s.state = state
    s.write_state()
    want = state & 0x0F
    end = time.monotonic() + timeout_s
    while True:
        st, code = state_of(m, i)
        if st == want or st & ERR or time.monotonic() > end:
            return st, code
        time.sleep(0.005)


def acknowledge(m, i):
    st, code = state_of(m, i)
    if st & ERR:
        st, code = request(m, i, (st & 0x0F) | ACK)
    return st, code


# --- 1. scan, identity, SII ---------------------------------------------------


def config_init(m):
    """`m.config_init()` up to three times, 0.5 s apart; the slaves found."""
    for k in range(3):
        n = m.config_init()
        if n > 0:
            break
        say(f"config_init found no slave (attempt {k + 1}), again in 0.5 s")
        time.sleep(0.5)
    return n


def scan(m, n_expected):
    n = config_init(m)
    say(f"config_init: {n} slave(s)")
    if n != n_expected:
        raise Fatal(f"config_init found {n} slaves, expected {n_expected}")


SOEM_ERRORS = (pysoem.SdoError, pysoem.SdoInfoError, pysoem.WkcError, pysoem.MailboxError, pysoem.PacketError)


def attempt(m, i, what, fn, tries=3):
    """Runs fn(), which returns the problems it found (empty: fine).

    SOEM times its frames by the wall clock and has no recovery for a
    mailbox exchange it gave up on while the exchange did reach the slave;
    the late answer then answers its next request (it compares the index of
    an SDO response, not the subindex; of an SDO Info response neither). A
    master the machine does not run for a few ms so gets a wrong or no
    answer. As a SOEM user would, a read is repeated (after the slave's send
    mailbox is emptied); a problem that stays is a failure."""
    for k in range(tries):
        try:
            problems = fn()
        except SOEM_ERRORS as e:
            problems = [f"{what}: {type(e).__name__} {vars(e)}"]
        if not problems:
            if k:
                say(f"slave {i + 1}: {what}: fine on attempt {k + 1}")
            return True
        if k + 1 < tries:
            more = f" (and {len(problems) - 1} more)" if len(problems) > 1 else ""
            say(f"slave {i + 1}: RETRY {what}: {problems[0]}{more}")
            time.sleep(0.05)
            try:
                m.slaves[i].mbx_receive()
            except SOEM_ERRORS:
                pass
            m._collect_mailbox_errors()
    for p in problems:
        check(False, p)
    return False


def sii_strings_1(sii):
    """String 1 of the STRINGS category (10): SOEM's name of a slave."""
    word = 0x40
    while word * 2 + 4 <= len(sii):
        cat, size = struct.unpack_from("<HH", sii, word * 2)
        if cat == 0xFFFF:
            break
        if cat == 10:
            off = word * 2 + 4
            n = sii[off + 1]
            return sii[off + 2 : off + 2 + n].decode("latin-1")
        word += 2 + size
    return None


def identity_and_sii(m, sii):
    vendor, product, revision = struct.unpack_from("<III", sii, 0x08 * 2)
    name = sii_strings_1(sii)
    say(f"expected from the SII image: '{name}', vendor {vendor:#x}, product {product:#x}, revision {revision:#x}")
    for i, s in enumerate(m.slaves):
        say(f"slave {i + 1}: '{s.name}' vendor {s.man:#x} product {s.id:#x} revision {s.rev:#x}")
        check(s.name == name, f"slave {i + 1}: SOEM's name '{s.name}' (SII string 1) is '{name}'")
        check(
            (s.man, s.id, s.rev) == (vendor, product, revision),
            f"slave {i + 1}: identity from the SII {s.man:#x}/{s.id:#x}/{s.rev:#x}",
        )

        # E-004, E-005, E-151: 1000h, 1018h, and 1018h:03 equal to the SII's revision
        def identity():
            problems = []
            dev = sdo_u(s, 0x1000, 0)
            if dev != 0x0002_0192:
                problems.append(f"slave {i + 1}: 1000h = {dev:08X}h, expected 0002 0192h")
            ident = [sdo_u(s, 0x1018, k) for k in range(4)]
            if ident != [4, vendor, product, revision]:
                problems.append(f"slave {i + 1}: 1018h:00..03 = {ident}, the SII says {[4, vendor, product, revision]}")
            return problems

        attempt(m, i, "identity objects", identity)

        def sii_image():
            t = time.monotonic()
            got = bytearray()
            for w in range(0, len(sii) // 2, 2):
                got += s.eeprom_read(w, 100_000)
            got = bytes(got[: len(sii)])
            diff = [k for k in range(len(sii)) if got[k] != sii[k]]
            say(f"slave {i + 1}: SII read back through SOEM, {len(got)} bytes in {time.monotonic() - t:.2f} s, {len(diff)} differ")
            return [f"slave {i + 1}: SII byte {k:#x} is {got[k]:#04x}, the image has {sii[k]:#04x}" for k in diff[:8]]

        attempt(m, i, "SII", sii_image)


# --- 2. SDO Info, PDO objects ------------------------------------------------


def object_problems(m, i, o, od):
    """What SOEM read of object `o` (description, every entry) against the
    declaration."""
    code, max_sub, dtype, name, ents = od[o.index]
    at = f"slave {i + 1}: {o.index:04X}h"
    problems = []
    m._collect_mailbox_errors()
    if o.name != name40(name):
        problems.append(f"{at} name {o.name!r}, declared {name!r}")
    if o.object_code != code:
        problems.append(f"{at} object code {o.object_code}, declared {code}")
    if dtype is not None and o.data_type != dtype:
        problems.append(f"{at} data type {o.data_type:#06x}, declared {dtype:#06x}")
    got = o.entries  # SOEM reads the description of every sub 0..max sub
    errors = m._collect_mailbox_errors()  # the SDO Info errors of subs that do not exist
    if max_sub == 0:
        e = ents[0]
        if (o.bit_length, o.obj_access) != (e[1], e[2]):
            problems.append(f"{at}:00 bit length {o.bit_length}, access {o.obj_access:#06x}; declared {e[1]}, {e[2]:#06x}")
        return problems, 1
    if len(got) != max_sub + 1:
        problems.append(f"{at} max subindex {len(got) - 1}, declared {max_sub}")
    gaps = described = 0
    for sub, ge in enumerate(got):
        if sub not in ents:
            gaps += 1
            if ge.data_type != 0:
                problems.append(f"{at}:{sub:02X} not declared but described")
            continue
        d_type, bits, access, _default, e_name = ents[sub]
        described += 1
        if (ge.name, ge.data_type, ge.bit_length, ge.obj_access) != (name40(e_name), d_type, bits, access):
            problems.append(
                f"{at}:{sub:02X} entry ({ge.name!r}, {ge.data_type:#06x}, {ge.bit_length}, {ge.obj_access:#06x}), "
                f"declared ({e_name!r}, {d_type:#06x}, {bits}, {access:#06x})"
            )
    if len(errors) != gaps:
        problems.append(f"{at}: {len(errors)} SDO Info errors for {gaps} undeclared subindexes")
    return problems, described


def sdo_info(m, i, od):
    s = m.slaves[i]
    t = time.monotonic()
    listed = []

    def object_list():
        listed[:] = [o.index for o in s.od]
        m._collect_mailbox_errors()
        if listed != sorted(od):
            return [f"slave {i + 1}: OD list of {len(listed)} objects, the dictionary shows {len(od)}"]
        return []

    attempt(m, i, "OD list", object_list)
    entries = 0
    objects = s.od
    for o in objects:
        if o.index not in od:
            continue
        found = [o]

        def description():
            # a repeated read needs a fresh object (pysoem keeps what it read)
            if found[0] is None:
                found[0] = next(x for x in s.od if x.index == o.index)
            problems, n = object_problems(m, i, found[0], od)
            found[0] = None
            found.append(n)
            return problems

        attempt(m, i, f"SDO Info of {o.index:04X}h", description)
        entries += found[-1] if len(found) > 1 else 0
    say(f"slave {i + 1}: SDO Info: {len(listed)} objects, {entries} entry descriptions in {time.monotonic() - t:.2f} s")


def pdo_objects(s):
    """(assignment 1C12h, assignment 1C13h, {pdo: [mapping entries]}) read by SDO."""
    assign = {}
    maps = {}
    for a in (0x1C12, 0x1C13):
        n = sdo_u(s, a, 0)
        assign[a] = [sdo_u(s, a, k) for k in range(1, n + 1)]
    for p in list(range(0x1600, 0x1604)) + list(range(0x1A00, 0x1A04)):
        n = sdo_u(s, p, 0)
        maps[p] = [sdo_u(s, p, k) for k in range(1, n + 1)]
    return assign, maps


def default_pdo_objects(od):
    assign = {}
    maps = {}
    for a in (0x1C12, 0x1C13):
        ents = od[a][4]
        assign[a] = [ents[k][3] for k in range(1, ents[0][3] + 1)]
    for p in list(range(0x1600, 0x1604)) + list(range(0x1A00, 0x1A04)):
        ents = od[p][4]
        maps[p] = [ents[k][3] for k in range(1, ents[0][3] + 1)]
    return assign, maps


def fmt_map(entries):
    return " ".join(f"{e >> 16:04X}:{(e >> 8) & 0xFF:02X}/{e & 0xFF}" for e in entries)


# --- 3. refused SDOs ----------------------------------------------------------


def bad_sdos(m, i, od):
    s = m.slaves[i]
    missing = next(x for x in range(0x5FFF, 0x5000, -1) if x not in od)
    cases = [
        (f"read of the non-existent object {missing:04X}h", lambda: s.sdo_read(missing, 0), 0x0602_0000),
        ("read of the non-existent subindex 1018h:09", lambda: s.sdo_read(0x1018, 9), 0x0609_0011),
        ("write of the read-only 1018h:01", lambda: s.sdo_write(0x1018, 1, (0x1234).to_bytes(4, "little")), 0x0601_0002),
        ("write of the read-only 6041h", lambda: s.sdo_write(0x6041, 0, b"\x00\x00"), 0x0601_0002),
    ]
    for what, call, want in cases:

        def abort():
            got = sdo_abort(call)
            shown = "no abort" if got is None else f"{got:08X}h"
            say(f"slave {i + 1}: {what}: {shown}")
            return [] if got == want else [f"slave {i + 1}: {what}: {shown}, expected {want:08X}h"]

        attempt(m, i, what, abort)


# --- 4. remap in Pre-Op -------------------------------------------------------


def entry(index, sub, bits):
    return (index << 16) | (sub << 8) | bits


# axis A: a shorter RxPDO and a different TxPDO; axis B keeps its default
# mapping, and both channels are assigned (the default assigns axis A only)
RX_A = [entry(0x6040, 0, 16), entry(0x6060, 0, 8), entry(0x607A, 0, 32)]
TX_A = [
    entry(0x6041, 0, 16),
    entry(0x6061, 0, 8),
    entry(0x6064, 0, 32),
    entry(0x60F4, 0, 32),
    entry(0x606C, 0, 32),
    entry(0x603F, 0, 16),
]
ASSIGN = {0x1C12: [0x1600, 0x1601], 0x1C13: [0x1A00, 0x1A01]}


def write_map(s, pdo, entries):
    s.sdo_write(pdo, 0, b"\x00")
    for k, e in enumerate(entries, 1):
        s.sdo_write(pdo, k, e.to_bytes(4, "little"))
    s.sdo_write(pdo, 0, bytes([len(entries)]))


def map_one_pdo_each(s, rx, tx):
    """Axis A's process data as one RxPDO (1600h = `rx`) and one TxPDO
    (1A00h = `tx`), assigned alone in 1C12h/1C13h."""
    for a in (0x1C12, 0x1C13):
        s.sdo_write(a, 0, b"\x00")
    write_map(s, 0x1600, rx)
    write_map(s, 0x1A00, tx)
    for a, pdo in ((0x1C12, 0x1600), (0x1C13, 0x1A00)):
        s.sdo_write(a, 1, pdo.to_bytes(2, "little"))
        s.sdo_write(a, 0, b"\x01")


def to_op(m, axis_class):
    """The mapping taken over (config_map), Safe-Op, then Op with the
    process data running: the axis (`axis_class(m)`, cycling the frames)."""
    m.config_map()
    axis = axis_class(m)
    m.state = SAFEOP
    m.write_state()
    axis.cycle(50)
    m.state = OP
    m.write_state()
    for _ in range(300):
        axis.cycle(10)
        if m.read_state() == OP:
            break
    else:
        raise Fatal(f"Op not reached: {state_report(m)}")
    return axis


def remap(s):
    for a in ASSIGN:
        s.sdo_write(a, 0, b"\x00")
    write_map(s, 0x1600, RX_A)
    write_map(s, 0x1A00, TX_A)
    for a, pdos in ASSIGN.items():
        for k, p in enumerate(pdos, 1):
            s.sdo_write(a, k, p.to_bytes(2, "little"))
        s.sdo_write(a, 0, bytes([len(pdos)]))


class Layout:
    """Byte offsets of the mapped objects in one slave's outputs or inputs."""

    def __init__(self, maps, pdos):
        self.at = {}
        off = 0
        for p in pdos:
            for e in maps[p]:
                idx, sub, bits = e >> 16, (e >> 8) & 0xFF, e & 0xFF
                if idx:
                    self.at[(idx, sub)] = (off // 8, bits // 8)
                off += bits
        self.bytes = (off + 7) // 8

    def get(self, data, index, signed=False):
        o, n = self.at[(index, 0)]
        return int.from_bytes(data[o : o + n], "little", signed=signed)

    def put(self, buf, index, value):
        o, n = self.at[(index, 0)]
        buf[o : o + n] = (value & ((1 << (8 * n)) - 1)).to_bytes(n, "little")


# --- 5. refusals at Pre-Op -> Safe-Op ----------------------------------------


class Emcys:
    def __init__(self, m):
        self.seen = {i: [] for i in range(len(m.slaves))}
        for i, s in enumerate(m.slaves):
            s.add_emergency_callback(lambda e, i=i: self.seen[i].append(e))

    def drain(self, m, i, wait_s=0.0):
        """The EMCYs slave i has sent: SOEM reads its send mailbox (an EMCY
        goes to the callback), for up to `wait_s` until there is one."""
        end = time.monotonic() + wait_s
        while True:
            for _ in range(5):
                try:
                    m.slaves[i].mbx_receive()
                except SOEM_ERRORS:
                    pass
            if self.seen[i] or time.monotonic() >= end:
                break
            time.sleep(0.01)
        got, self.seen[i] = self.seen[i], []
        return got


def refusal(m, emcys, i, what, want_code, undo, emcy=True):
    st, code = request(m, i, SAFEOP)
    say(f"slave {i + 1}: {what}: Pre-Op -> Safe-Op gives state {st:#04x}, AL status code {code:04X}h")
    check(st == PREOP | ERR and code == want_code, f"slave {i + 1}: {what}: state {st:#04x} AL {code:04X}h, expected 0x12 and {want_code:04X}h")
    got = emcys.drain(m, i, 0.5 if emcy else 0.0)
    codes = [f"{e.error_code:04X}h" for e in got]
    say(f"slave {i + 1}: EMCY after the refusal: {codes}")
    if emcy:
        # E-028: a refused SyncManager configuration is reported by EMCY A000h
        check(any(e.error_code == 0xA000 for e in got), f"slave {i + 1}: {what}: EMCY A000h expected, got {codes}")
    undo()
    st, code = acknowledge(m, i)
    check(st == PREOP, f"slave {i + 1}: back in Pre-Op after the acknowledge: {st:#04x} {code:04X}h")


def write(m, i, index, sub, data):
    """An SDO download, repeated when SOEM got no answer (see attempt)."""
    attempt(m, i, f"write {index:04X}h:{sub:02X}", lambda: m.slaves[i].sdo_write(index, sub, data) or [])


def refusals(m, emcys, layout_in):
    n = len(m.slaves)
    # the mapping changed behind the master's back: SM2 as SOEM configured it
    # (from the mapping it read) is longer than the mapping now
    write(m, 0, 0x1600, 0, bytes([len(RX_A) - 1]))
    refusal(
        m,
        emcys,
        0,
        f"1600h:00 = {len(RX_A) - 1} after config_map (SM2 length from the previous mapping)",
        0x001D,
        lambda: write(m, 0, 0x1600, 0, bytes([len(RX_A)])),
    )
    # SM3 length register not matching the mapping
    i = 1 % n
    s = m.slaves[i]
    sm3 = s._fprd(0x0818, 8, 20_000)
    length = u(sm3[2:4])
    check(length == layout_in.bytes, f"slave {i + 1}: SOEM programmed SM3 with {length} bytes, the mapping has {layout_in.bytes}")
    s._fpwr(0x0818 + 2, (length + 2).to_bytes(2, "little"), 20_000)
    refusal(m, emcys, i, f"SM3 length {length + 2} for a {length}-byte mapping", 0x001E, lambda: s._fpwr(0x081A, sm3[2:4], 20_000))
    # SYNC0 cycles the drive must refuse (A150 = 1 ms)
    i = 2 % n
    s = m.slaves[i]
    s.dc_sync(True, 1_100_000)
    refusal(m, emcys, i, "SYNC0 cycle 1.1 ms (not a multiple of 250 us)", 0x0035, lambda: s.dc_sync(False, 0), emcy=False)
    s.dc_sync(True, 1_500_000)
    refusal(m, emcys, i, "SYNC0 cycle 1.5 ms (not a multiple of A150 = 1 ms)", 0x0036, lambda: s.dc_sync(False, 0), emcy=False)


# --- 6..8. the cyclic part ---------------------------------------------------


def real_time(on):
    """What SOEM's samples do for their cycle thread (osal_thread_create_rt:
    SCHED_FIFO, priority 40), where permitted, for the cyclic part only. The
    rest stays at normal priority, as the samples' main thread: SOEM waits
    for a frame by polling the socket, and a real-time task that polls for
    long (SDO Info, the SII) is throttled by the kernel for tens of ms
    (sched_rt_runtime_us)."""
    try:
        if on:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(40))
            say("master: cycle at SCHED_FIFO priority 40 (as SOEM's samples)")
        else:
            os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))
    except (OSError, AttributeError) as e:
        say(f"master: no real-time priority ({e}); cycles may be left out under load")


def master_main(args, run, done):
    """Opens SOEM on args.iface, calls run(master, args), closes it; prints the
    failed checks (exit code 1) or `done` (exit code 0)."""
    priority()
    m = pysoem.Master()
    m.open(args.iface)
    with stops_as_checks():
        try:
            run(m, args)
        finally:
            m.close()
    return report(done)


@contextlib.contextmanager
def stops_as_checks():
    """A Fatal or a SOEM error raised inside: a failed check that says what
    stopped the script, which goes on to its report."""
    try:
        yield
    except Fatal as e:
        check(False, f"stopped: {e}")
    except SOEM_ERRORS as e:
        check(False, f"stopped by SOEM: {type(e).__name__} {vars(e)}")


def one_drive_in_preop(m):
    """Scans a line of one drive and checks that it is in Pre-Op; the drive."""
    scan(m, 1)
    check(m.read_state() == PREOP, f"Pre-Op: {state_report(m)}")
    return m.slaves[0]


def enable_sequence(axis):
    """Fault reset, shutdown, switch on, enable operation: each controlword
    on `axis` (its cw, cycle() and sw) until the statusword shows the state
    it leads to, 300 cycles at most (Fatal otherwise)."""
    for cw, want in ((0x80, None), (0x06, READY), (0x07, SWITCHED_ON), (0x0F, ENABLED)):
        axis.cw = cw
        for _ in range(300):
            axis.cycle()
            if want is None or sw_is(axis.sw, want):
                break
        else:
            raise Fatal(f"controlword {cw:#04x}: statusword {axis.sw:#06x}")


def report(done):
    """Prints the failed checks (returns exit code 1) or `done` (0)."""
    if failures:
        say(f"\n{len(failures)} check(s) failed:")
        for f in failures:
            say(f"  {f}")
        return 1
    say(f"\n{done}")
    return 0


def script_main(doc, run, done, *options):
    """The main of a script against the line: --iface and `options`
    ((name, add_argument's keywords) each) from the command line, then
    master_main(args, run, done)."""
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--iface", required=True)
    for name, kw in options:
        ap.add_argument(name, **kw)
    return master_main(ap.parse_args(), run, done)


def script(name, doc, run, done, *options):
    """A script's end: when `name` (its __name__) is "__main__", exits with
    script_main(doc, run, done, *options); nothing when another script
    imports it."""
    if name == "__main__":
        sys.exit(script_main(doc, run, done, *options))


def required_float(name, what):
    """An option of script_main: `name`, a float the command line must give."""
    return (name, dict(type=float, required=True, help=what))


def stop(axis, cycles=20):
    """Controlword 0 for `cycles` cycles: the axis disabled at a script's end."""
    axis.cw = 0
    axis.cycle(cycles)


def priority():
    """Timer slack 1 ns; nice -20 where permitted, so that the compile jobs of
    a shared machine do not hold up SOEM's mailbox exchanges (it waits for a
    frame by polling the socket, so not at a real-time priority)."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(29, 1, 0, 0, 0)  # PR_SET_TIMERSLACK
    except OSError:
        pass
    try:
        os.setpriority(os.PRIO_PROCESS, 0, -20)
    except OSError as e:
        say(f"master: nice -20 not permitted ({e})")


class Stall(Exception):
    """A slave left Op or an axis left Operation enabled right after the line
    was stalled longer than the drive tolerates (see Cycle.stall)."""


class Disturbed(Exception):
    """A move the machine disturbed too often to judge the tracking: the
    axes are disabled again and the move is repeated."""


class Cycle:
    """The master's 1 ms cycle, aligned to the DC reference clock the way
    SOEM's samples do (ec_sync in ec_sample.c): a PI on the DC time of the
    last frame moves the next wake-up so that frames reach the reference
    clock FRAME_LEAD_NS before SYNC0.

    Per SYNC0 period it keeps whether the drives got a frame inside their
    window (SYNC0 - A150/2 .. SYNC0, E-118): judged by the DC time the frame
    carries back, i.e. by the drives' own clock, so it counts a master that
    was late, a simulator that answered late and a frame lost on the way."""

    def __init__(self, m):
        self.m = m
        self.expected_wkc = m.expected_wkc
        self.next = time.monotonic_ns() + CYCLE_NS
        self.integral = 0
        self.toff = 0
        self.delta = 0
        self.n = 0
        self.bad_wkc = []
        self.skipped = 0
        self.counting = False
        self.op_cycles = 0
        # frames the drive sees outside its window, largest phase error
        self.outside = 0
        self.max_delta = 0
        # per SYNC0 period: a frame in the window (True) or not (False)
        self.periods = []
        # the SYNC0 period of the last frame that came back, and the entries
        # of `periods` since (slots left out, frames lost)
        self.last_period = None
        self.since_good = 0

    def sync(self, reftime):
        # ec_sync: sync point FRAME_LEAD_NS before SYNC0 (SYNC0 at multiples of the cycle)
        delta = (reftime - (CYCLE_NS - FRAME_LEAD_NS)) % CYCLE_NS
        if delta > CYCLE_NS // 2:
            delta -= CYCLE_NS
        if delta > 0:
            self.integral += 1
        if delta < 0:
            self.integral -= 1
        self.toff = -(delta // 100) - (self.integral // 20)
        self.delta = delta

    def run(self, fill=None):
        """One cycle: wait, send, receive; returns the working counter.
        `fill(slot)`, when given, writes the outputs for the slot the frame
        goes in (counting the slots left out), just before it is sent.

        A master that woke too late for a slot (descheduled on a shared
        machine) leaves it out rather than sending its frame after SYNC0 or
        two frames in one cycle; the slots left out are counted."""
        self.next += CYCLE_NS + self.toff
        while time.monotonic_ns() - self.next > SLOT_LATE_NS:
            self.next += CYCLE_NS
            self.skipped += 1
            self.periods.append(False)
            self.since_good += 1
        if fill:
            fill(self.n + self.skipped)
        while True:
            left = self.next - time.monotonic_ns()
            if left <= 0:
                break
            if left > 120_000:
                time.sleep((left - 100_000) / 1e9)
        t_send = time.monotonic_ns()
        self.m.send_processdata()
        wkc = self.m.receive_processdata(4000)
        t_recv = time.monotonic_ns()
        self.n += 1
        if self.counting:
            self.op_cycles += 1
            if wkc != self.expected_wkc:
                self.bad_wkc.append((self.op_cycles, wkc))
        self.sync(self.m.dc_time)
        inside = -(CYCLE_NS // 2 - FRAME_LEAD_NS) < self.delta < FRAME_LEAD_NS
        if wkc > 0:
            # the periods between this frame and the last one that came back,
            # by the drives' clock: a master that overslept its slot after
            # deciding to send in it (descheduled in the wait) or a frame
            # answered late leaves periods without a frame that no left-out
            # slot or lost frame stands for
            period = -(-self.m.dc_time // CYCLE_NS)
            if self.last_period is not None:
                missing = period - self.last_period - 1 - self.since_good
                self.periods.extend([False] * min(max(missing, 0), 1000))
            self.last_period = period
            self.since_good = 0
        else:
            self.since_good += 1
        self.periods.append(wkc > 0 and inside)
        del self.periods[:-1000]
        if TRACE:
            TRACE.write(f"{self.n} {t_recv} {self.m.dc_time} {self.delta} {self.toff} {self.integral} {wkc} {t_send - self.next} {t_recv - t_send}\n")
        if self.counting:
            self.max_delta = max(self.max_delta, abs(self.delta))
            if not inside:
                self.outside += 1
        return wkc

    def stall(self, last=300):
        """The longest run of SYNC0 periods without a frame in the window
        among the last `last` periods."""
        run = longest = 0
        for ok in self.periods[-last:]:
            run = 0 if ok else run + 1
            longest = max(longest, run)
        return longest


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


def config_map(m, layouts):
    """`m.config_map()` until every slave is mapped with the sizes its PDO
    objects give (`layouts`), three times at most; the IO map's size."""
    for _ in range(3):
        size = m.config_map()
        wrong = [i + 1 for i, s in enumerate(m.slaves) if (len(s.output), len(s.input)) != (layouts[i][0].bytes, layouts[i][1].bytes)]
        if not wrong:
            return size
        say(f"RETRY config_map: slave(s) {wrong} mapped with other sizes than their PDO objects give")
    raise Fatal(f"config_map: slave(s) {wrong} mapped with other sizes than their PDO objects give, 3 times")


def align(cyc):
    """Runs `cyc` (5000 cycles at most) until 190 of the last 200 frames
    came within 100 us of the reference clock; those last frames' verdicts."""
    recent = []
    for _ in range(5000):
        cyc.run()
        recent = (recent + [abs(cyc.delta) < 100_000])[-200:]
        if sum(recent) >= 190:
            break
    return recent


def wait_states(m, cyc, want, max_cycles, every=10):
    """Cycles until every slave shows `want` (read every `every` cycles)."""
    for k in range(max_cycles):
        cyc.run()
        if k % every == every - 1:
            lowest = m.read_state()
            if lowest == want and all(s.state == want for s in m.slaves):
                return True
    return False


def state_report(m):
    m.read_state()
    return ", ".join(f"{s.state:#04x}/{s.al_status:04X}h" for s in m.slaves)


SWITCH_ON_DISABLED = (0x4F, 0x40)
READY = (0x6F, 0x21)
SWITCHED_ON = (0x6F, 0x23)
ENABLED = (0x6F, 0x27)
FAULT = (0x08, 0x08)  # Fault or Fault reaction active


def sw_is(sw, pattern):
    return sw & pattern[0] == pattern[1]


class FreeRunAxis:
    """Axis A of drive 1 in free run, about 1 ms per frame: each frame sends
    `outputs()` packed as the struct format OUT and gives the TxPDO,
    unpacked as IN, to `inputs(*values)` (a subclass sets the three)."""

    OUT = IN = ""

    def __init__(self, m):
        self.m, self.s = m, m.slaves[0]

    def outputs(self):
        raise NotImplementedError

    def inputs(self, *values):
        raise NotImplementedError

    def cycle(self, k=1):
        n = struct.calcsize(self.IN)
        for _ in range(k):
            self.s.output = struct.pack(self.OUT, *self.outputs())
            self.m.send_processdata()
            self.m.receive_processdata(4000)
            if len(self.s.input) >= n:
                self.inputs(*struct.unpack(self.IN, bytes(self.s.input[:n])))
            time.sleep(0.001)

    def until(self, pred, frames):
        """Cycles until `pred()` holds (True) or `frames` frames went by (False)."""
        for _ in range(frames):
            self.cycle()
            if pred():
                return True
        return False

class Axis:
    """One CiA 402 axis of one slave in the process data."""

    def __init__(self, slave, base, out_l, in_l):
        self.slave = slave
        self.base = base  # 0 axis A, 0x800 axis B
        self.out_l = out_l
        self.in_l = in_l
        self.name = f"slave {slave + 1} axis {'A' if base == 0 else 'B'}"

    def sw(self, inp):
        return self.in_l.get(inp, 0x6041 + self.base)

    def pos(self, inp):
        return self.in_l.get(inp, 0x6064 + self.base, signed=True)

    def ferr(self, inp):
        return self.in_l.get(inp, 0x60F4 + self.base, signed=True)

    def mode(self, inp):
        return self.in_l.get(inp, 0x6061 + self.base, signed=True)

    def write(self, out, cw, mode, target):
        self.out_l.put(out, 0x6040 + self.base, cw)
        self.out_l.put(out, 0x6060 + self.base, mode)
        self.out_l.put(out, 0x607A + self.base, target)


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
