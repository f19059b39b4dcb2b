"""The master's 1 ms cycle aligned to the DC reference clock the way SOEM's
samples do it (out of line.py; `import line as L` still gives every name
here as L.<name>): `Cycle` (ec_sync's PI, slots left out by a late master,
per SYNC0 period whether the drives got a frame in their window), `align`
and `wait_states`. With SOEM_TRACE=FILE every cycle's timing goes to FILE
(`TRACE`, opened once when this module is first imported).
"""
import os
import time


CYCLE_NS = 1_000_000
# frames this long before SYNC0 (DC time), as a DC master places them
FRAME_LEAD_NS = 300_000
# a master this late for its slot leaves the slot out (its frame would reach
# the drive after SYNC0)
SLOT_LATE_NS = 250_000


TRACE = open(os.environ["SOEM_TRACE"], "w") if os.environ.get("SOEM_TRACE") else None


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
