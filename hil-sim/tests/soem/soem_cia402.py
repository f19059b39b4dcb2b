"""CiA 402 over the process data, as the scripts against the line drive an
axis (out of line.py; `import line as L` still gives every name here as
L.<name>): the statusword patterns and `sw_is`, the enable sequence and the
stop, `FreeRunAxis` (axis A of drive 1 in free run) and `Axis` (one axis of
one slave in the cyclic exchange of line.py's `Line`).
"""
import struct
import time

from soem_report import Fatal


INC_PER_REV = 1 << 20


SWITCH_ON_DISABLED = (0x4F, 0x40)
READY = (0x6F, 0x21)
SWITCHED_ON = (0x6F, 0x23)
ENABLED = (0x6F, 0x27)
FAULT = (0x08, 0x08)  # Fault or Fault reaction active


def sw_is(sw, pattern):
    return sw & pattern[0] == pattern[1]


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


def stop(axis, cycles=20):
    """Controlword 0 for `cycles` cycles: the axis disabled at a script's end."""
    axis.cw = 0
    axis.cycle(cycles)


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
