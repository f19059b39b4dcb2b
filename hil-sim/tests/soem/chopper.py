#!/usr/bin/env python3
"""The DC link and the over-voltage trip through SOEM on the electrical plant
(issue 34; E-090, E-089).

Run by `hil-sim/tests/soem_electrical.rs` as root inside the master's network
namespace against `hil-sim serve --plant electrical --flywheel 0.01
--slaves 1` (or by hand): axis A drives a frictionless flywheel of J =
0.01 kg m^2 the drive does not know. Free run, one drive, axis A; RxPDO 6040h,
6060h, 6071h; TxPDO 6041h, 6061h, 6077h, 6078h, 606Ch.

  1. Pre-Op, the DC-link window by SDO: A38 (chopper threshold) = 800 V (at
     the over-voltage trip A40) and A35 (low voltage limit) = 745 V (above
     A38 - 20 V) are refused with 0609 0031h, A38 = 420 V (20 V above A35)
     with 0609 0032h, each changing nothing; A40 is read only (0601 0002h).
     A21 (brake resistor) = 0: none. G472 = G475 = 90 % of I10 (45 rev/s).
  2. cst: 6071h = +200 % until 606Ch passes 40 rev/s; 6079h reads the link
     at rest (565 V within 2 V). Then 6071h = -200 %: the flywheel brakes
     into the DC link until the drive faults: 603Fh = 3110h, EMCY 3110h with
     error register bit 2 (voltage), event 36; 6079h reads the link at the
     trip (800 V within 2 V). The energy balance:
         1/2 J (w1^2 - w2^2) - 1.5 R i^2 t  =  1/2 C (V2^2 - V1^2)
     with w from 606Ch at the start of the braking and in the frame that
     shows the fault, i the mean of 6078h over the braking, t its duration,
     R = 3.6 ohm (the plant's winding), C = 470 uF (the plant's DC link,
     `plant::DcLinkParams::default_400v`): within 5 % (frames of ~1 ms in
     real time: the speed at the trip is read up to a frame late).

Prints `FAIL: ...` for every check that failed; exit status 0 when none did.
"""
import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import line as L  # noqa: E402
import motor_protection as MP  # noqa: E402  (its Axis and TX layout)
import torque as T  # noqa: E402  (its RX layout, limit_torque)

say, check = L.say, L.check


def a(line):
    return 0x2000 + line


A21, A35, A38, A40 = a(21), a(35), a(38), a(40)
ABORT_READ_ONLY = 0x06010002
REV = 1 << 20
J, C, R = 0.01, 470e-6, 3.6


def window(s):
    for index, value, want, what in (
        (A38, 800, MP.ABORT_TOO_HIGH, "A38 threshold at the over-voltage trip"),
        (A35, 745, MP.ABORT_TOO_HIGH, "A35 low voltage limit above A38 - 20 V"),
        (A38, 420, MP.ABORT_TOO_LOW, "A38 threshold 20 V above A35"),
        (A40, 900, ABORT_READ_ONLY, "A40 over-voltage trip (read only)"),
    ):
        before = L.sdo_u(s, index, 0)
        code = L.sdo_abort(lambda: s.sdo_write(index, 0, value.to_bytes(2, "little")))
        check(code == want, f"{what}: abort {code}, expected {want:#010x}")
        check(L.sdo_u(s, index, 0) == before, f"{what}: {index:04X}h unchanged ({before})")
    s.sdo_write(A21, 0, (0).to_bytes(2, "little"))
    check(L.sdo_u(s, A21, 0) == 0, "A21 = 0: no brake resistor")
    T.limit_torque(s, 900)


def brake(m, axis, emcys):
    emcys.drain(m, 0)
    axis.torque = 2000
    for _ in range(5000):
        axis.cycle()
        if axis.velocity >= 40 * REV:
            break
    check(axis.velocity >= 40 * REV, f"accelerated to 40 rev/s: 606Ch {axis.velocity / REV:.1f} rev/s")
    v1 = L.sdo_u(axis.s, 0x6079, 0) / 1000.0
    check(abs(v1 - 565.0) < 2.0, f"6079h at speed, no current: {v1:.1f} V (565 V)")
    w1 = axis.velocity / REV * 2 * math.pi
    axis.torque = -2000
    currents, frames = [], 0
    for _ in range(3000):
        axis.cycle()
        frames += 1
        if L.sw_is(axis.sw, L.FAULT):
            break
        currents.append(axis.current / 1000.0 * 2.0)  # 6078h in per mille of 6075h = 2 A
    check(L.sw_is(axis.sw, L.FAULT), f"braking without resistor faults: statusword {axis.sw:#06x}")
    w2 = axis.velocity / REV * 2 * math.pi
    axis.torque = 0
    v2 = L.sdo_u(axis.s, 0x6079, 0) / 1000.0
    code = L.sdo_u(axis.s, 0x603F, 0)
    check(code == 0x3110, f"603Fh = {code:04X}h, expected 3110h (event 36)")
    check(abs(v2 - 800.0) < 2.0, f"6079h after the trip: {v2:.1f} V (the 800 V trip)")
    got = emcys.drain(m, 0, 1.0)
    text = [f"{e.error_code:04X}h/{e.error_reg:02X}h event {e.b1}" for e in got]
    check(any(e.error_code == 0x3110 and e.error_reg & 0x04 and e.b1 == 36 for e in got), f"EMCY 3110h, register bit 2, event 36: {text}")
    t = max(len(currents), 1) * 0.001
    # the braking's duration from the speed (the frames' period is the master's, ~1 ms)
    decel = None
    if currents:
        i_sq = sum(i * i for i in currents) / len(currents)
        torque = 0.65 * math.sqrt(i_sq)
        decel = torque / J
        t = (w1 - w2) / decel if decel > 0 else t
        copper = 1.5 * R * i_sq * t
    else:
        copper = 0.0
    kinetic = 0.5 * J * (w1 * w1 - w2 * w2)
    stored = 0.5 * C * (v2 * v2 - v1 * v1)
    err = (kinetic - copper - stored) / stored
    say(f"braked {w1:.1f} -> {w2:.1f} rad/s in {t * 1000:.0f} ms ({frames} frames): 1/2 J (w1^2 - w2^2) {kinetic:.1f} J - copper {copper:.1f} J = {kinetic - copper:.1f} J; 1/2 C (V2^2 - V1^2) {stored:.1f} J ({v1:.1f} -> {v2:.1f} V); error {err * 100:.1f} %; 603Fh {code:04X}h, EMCY {text}")
    check(abs(err) < 0.05, f"energy balance within 5 %: {err * 100:.1f} %")


def run(m, args):
    L.scan(m, 1)
    check(m.read_state() == L.PREOP, f"Pre-Op: {L.state_report(m)}")
    s = m.slaves[0]
    emcys = L.Emcys(m)
    window(s)
    L.map_one_pdo_each(s, T.RX, MP.TX)
    axis = L.to_op(m, MP.Axis)
    axis.enable()
    brake(m, axis, emcys)
    axis.cw = 0
    axis.cycle(20)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--iface", required=True)
    args = ap.parse_args()
    return L.master_main(args, run, "DC link and over-voltage trip on the electrical plant: all checks passed")


if __name__ == "__main__":
    sys.exit(main())
