"""SOEM's mailbox as the scripts against the line use it (out of line.py; `import
line as L` still gives every name here as L.<name>): SDO reads and writes,
the abort code of a refused SDO, `attempt` (a mailbox exchange repeated
where SOEM lost its answer on a shared machine), the PDO assignment and
mapping objects by SDO, and the EMCYs a slave sent (`Emcys`).
"""
import time

import pysoem

from soem_report import check, say


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


def write(m, i, index, sub, data):
    """An SDO download, repeated when SOEM got no answer (see attempt)."""
    attempt(m, i, f"write {index:04X}h:{sub:02X}", lambda: m.slaves[i].sdo_write(index, sub, data) or [])


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


def fmt_map(entries):
    return " ".join(f"{e >> 16:04X}:{(e >> 8) & 0xFF:02X}/{e & 0xFF}" for e in entries)


def entry(index, sub, bits):
    return (index << 16) | (sub << 8) | bits


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
