#!/usr/bin/env python3
"""The over-current trip through SOEM on the electrical plant (issue 34;
E-089, C-017).

Run by `hil-sim/tests/soem_electrical.rs` as root inside the master's network
namespace against `hil-sim serve --plant electrical --plant-fault short
--slaves 1` (or by hand): leg a of axis A's inverter is shorted to the DC
link's negative rail through 1 ohm behind its current sensor, so the first
PWM period with the gates on carries some 280 A in that leg (the trip is at
9 A). Free run, one drive, axis A; RxPDO 6040h, 6060h, 6071h; TxPDO 6041h,
6061h, 6077h, 6078h, 606Ch.

  1. Pre-Op, maps, Safe-Op, Op; cst, 6071h = 0.
  2. The enable sequence (0x06, 0x07, 0x0F): Ready to switch on as usual
     (the gates still off: nothing to see); Switch on puts the power stage
     on (CiA 402 Switched on: the gates on, no torque yet), and the axis
     faults within a few frames (at Switched on, or at Enable operation when
     the master's next command came first): statusword Fault,
     603Fh = 2310h, EMCY 2310h with error register bit 1 (current), E82
     event 33 cause 2; 6077h and 6078h 0 in the frames after it (the power
     stage is off: no current).
  3. A fault reset (0x80) gives Switch on disabled (the trip was latched,
     the short needs the gates to show); the enable into it faults again
     with 2310h.

Prints `FAIL: ...` for every check that failed; exit status 0 when none did.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import line as L  # noqa: E402
import motor_protection as MP  # noqa: E402  (its axis and maps)
import torque as T  # noqa: E402

say, check = L.say, L.check
FAULT_BIT = 1 << 3


def enable_into_the_short(m, axis, emcys, what):
    """The enable sequence until the axis faults; returns the command that
    faulted it."""
    emcys.drain(m, 0)
    faulted_at = None
    for cw, want in ((0x06, L.READY), (0x07, L.SWITCHED_ON), (0x0F, L.ENABLED)):
        axis.cw = cw
        for _ in range(300):
            axis.cycle()
            if axis.sw & FAULT_BIT or L.sw_is(axis.sw, want):
                break
        if axis.sw & FAULT_BIT:
            faulted_at = cw
            break
        if cw == 0x0F:
            # enabled: the trip shows within a few frames
            for _ in range(50):
                axis.cycle()
                if axis.sw & FAULT_BIT:
                    faulted_at = cw
                    break
    check(faulted_at in (0x07, 0x0F), f"{what}: the axis faults once Switch on put the gates on, not before: faulted at {faulted_at}, statusword {axis.sw:#06x}")
    axis.cycle(20)
    frames = []
    for _ in range(20):
        axis.cycle()
        frames.append((axis.actual_torque, axis.current))
    check(L.sw_is(axis.sw, L.FAULT), f"{what}: statusword Fault: {axis.sw:#06x}")
    check(all(abs(t) <= 10 and abs(c) <= 10 for t, c in frames), f"{what}: 6077h/6078h 0 (within 1 %) with the power stage off: {frames[:6]}")
    code = L.sdo_u(axis.s, 0x603F, 0)
    check(code == 0x2310, f"{what}: 603Fh = {code:04X}h, expected 2310h (event 33)")
    got = emcys.drain(m, 0, 1.0)
    text = [f"{e.error_code:04X}h/{e.error_reg:02X}h event {e.b1} cause {e.w1 & 0xFF}" for e in got]
    check(any(e.error_code == 0x2310 and e.error_reg & 0x02 and e.b1 == 33 and e.w1 & 0xFF == 2 for e in got), f"{what}: EMCY 2310h, register bit 1, event 33 cause 2: {text}")
    say(f"{what}: Fault after controlword {faulted_at:#04x}, 603Fh {code:04X}h, EMCY {text}, 6077h/6078h after it {frames[-1]}")


def run(m, args):
    s = L.one_drive_in_preop(m)
    emcys = L.Emcys(m)
    L.map_one_pdo_each(s, T.RX, MP.TX)
    axis = L.to_op(m, MP.Axis)
    axis.cw = 0x80
    axis.cycle(5)
    axis.cw = 0
    axis.cycle(5)
    enable_into_the_short(m, axis, emcys, "first enable")
    # the acknowledge: the latched trip clears (the short shows only with the gates on)
    axis.cw = 0
    axis.cycle(2)
    axis.cw = 0x80
    axis.cycle(10)
    check(L.sw_is(axis.sw, L.SWITCH_ON_DISABLED), f"fault reset: Switch on disabled, statusword {axis.sw:#06x}")
    axis.cw = 0
    axis.cycle(2)
    enable_into_the_short(m, axis, emcys, "enable after the reset, the short still there")
    L.stop(axis)


L.script(__name__, __doc__, run, "over-current on the electrical plant: all checks passed")
