"""The SOEM master's side of the line outside the cycle (out of line.py; `import
line as L` still gives every name here as L.<name>): the AL states, a
slave's state requested and acknowledged, the scan (`config_init`, `scan`),
the process-data mapping (`config_map`, `Layout`, `to_op`), and the frame of
a script: its command line (`script`, `script_main`, `required_float`), the
master opened and closed with SOEM errors and `Fatal` as failed checks
(`master_main`, `stops_as_checks`), and its priorities (`priority`,
`real_time`).
"""
import argparse
import contextlib
import ctypes
import os
import sys
import time

import pysoem

from soem_mailbox import SOEM_ERRORS
from soem_report import Fatal, check, report, say


INIT, PREOP, SAFEOP, OP = 0x01, 0x02, 0x04, 0x08
ERR = ACK = 0x10


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


def one_drive_in_preop(m):
    """Scans a line of one drive and checks that it is in Pre-Op; the drive."""
    scan(m, 1)
    check(m.read_state() == PREOP, f"Pre-Op: {state_report(m)}")
    return m.slaves[0]


def state_report(m):
    m.read_state()
    return ", ".join(f"{s.state:#04x}/{s.al_status:04X}h" for s in m.slaves)


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
