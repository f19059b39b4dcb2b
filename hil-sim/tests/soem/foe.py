#!/usr/bin/env python3
"""The firmware update as SOEM's `firm_update` sample does it, with the
update files `tools/foe-image` writes by default: one per firmware slot,
named for it (firmware-slot-a.sc6f, firmware-slot-b.sc6f; docs/flashing.md).

For drive 1 of the line: in Pre-Op the master reads the drive's update slot,
object E54 (1 = A, 2 = B: the slot a download goes to, the one the drive did
not start from), and picks that slot's file; then Init, the SyncManagers set
to the bootstrap mailbox read from the SII (as firm_update and pysoem's
examples/firmware_update.py do), Bootstrap, `ecx_FOEwrite` of a file, Init.
SOEM reports an FoE error answer as -5 (EC_ERR_TYPE_FOE_ERROR) and the
error 8001h "not found" as -10 (EC_ERR_TYPE_FOE_FILE_NOTFOUND); a positive
result is the accepted download. Checks:
  - the file for the other slot is refused (the drive: 8004h, at the header);
  - a bit-flipped file and a truncated one are refused (the drive: 800Ch);
  - a file name that does not start with "firmware" is refused (8001h);
  - the file for the update slot is taken, under its own name;
  - the drive comes back to Pre-Op through Init afterwards.

Run by `hil-sim/tests/soem.rs` as root inside the master's namespace.
"""
import argparse
import os
import struct
import sys
import time

import pysoem

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import line as L  # noqa: E402  (line.py beside this file: check, say, the report)

check, say = L.check, L.say

# SOEM's FoE results (ethercattype.h)
EC_ERR_TYPE_FOE_ERROR = 5
EC_ERR_TYPE_FOE_FILE_NOTFOUND = 10
# ecx_srconfirm found no answer to a frame in time (SOEM's EC_NOFRAME)
EC_NOFRAME = -1


def to_state(s, state, what):
    s.state = state
    s.write_state()
    got = s.state_check(state, 3_000_000)
    return check(got == state, f"{what}: state {got:#04x}, AL code {s.al_status:#06x}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--iface", required=True)
    ap.add_argument("--files", required=True, help="the directory with firmware-slot-a.sc6f and firmware-slot-b.sc6f")
    ap.add_argument("--e54", required=True, type=lambda v: int(v, 0), help="the index of E54, the update slot")
    ap.add_argument("--flipped", required=True, help="the update slot's file with one bit of the body flipped")
    ap.add_argument("--truncated", required=True, help="the same without its last 100 bytes")
    args = ap.parse_args()
    files = {k: open(getattr(args, k), "rb").read() for k in ("flipped", "truncated")}
    m = pysoem.Master()
    m.open(args.iface)
    try:
        n = L.config_init(m)
        if not check(n > 0, "config_init found no slave"):
            return 1
        s = m.slaves[0]
        # which file: the drive's update slot, as a user reads it (TwinCAT's
        # CoE online tab, or an SDO upload)
        if not to_state(s, pysoem.PREOP_STATE, "Pre-Op"):
            return 1
        slot = s.sdo_read(args.e54, 0)[0]
        say(f"drive 1: {s.name!r}, update slot E54 ({args.e54:04X}h) = {slot}")
        if not check(slot in (1, 2), f"E54 = {slot}, 1 (A) or 2 (B) expected"):
            return 1
        ours, other = ("firmware-slot-a.sc6f", "firmware-slot-b.sc6f")[:: 1 if slot == 1 else -1]
        files["good"] = open(f"{args.files}/{ours}", "rb").read()
        files["other"] = open(f"{args.files}/{other}", "rb").read()
        check(slot == 1, f"serve's empty drive downloads to slot A, E54 says {slot}")
        say(f"sending {ours} ({len(files['good'])} bytes); {other} must be refused")
        if not to_state(s, pysoem.INIT_STATE, "Init"):
            return 1
        # the bootstrap mailbox from the SII, as firm_update does
        rx_addr, rx_len = struct.unpack("HH", s.eeprom_read(pysoem.SiiOffset.BOOT_RX_MBX))
        tx_addr, tx_len = struct.unpack("HH", s.eeprom_read(pysoem.SiiOffset.BOOT_TX_MBX))
        say(f"bootstrap mailbox: SM0 {rx_addr:#06x}/{rx_len}, SM1 {tx_addr:#06x}/{tx_len}")
        s.amend_mbx(mailbox="out", start_address=rx_addr, size=rx_len)
        s.amend_mbx(mailbox="in", start_address=tx_addr, size=tx_len)
        if not to_state(s, pysoem.BOOT_STATE, "Init -> Bootstrap"):
            return 1
        for name, data, want, what in [
            (other, files["other"], -EC_ERR_TYPE_FOE_ERROR, "the other slot's file (8004h)"),
            (ours, files["flipped"], -EC_ERR_TYPE_FOE_ERROR, "bit-flipped file (800Ch)"),
            (ours, files["truncated"], -EC_ERR_TYPE_FOE_ERROR, "truncated file (800Ch)"),
            ("image.sc6f", files["good"], -EC_ERR_TYPE_FOE_FILE_NOTFOUND, "name without 'firmware' (8001h)"),
            (ours, files["good"], None, "the update slot's file"),
        ]:
            for attempt in range(1, 4):
                t = time.monotonic()
                r = s.foe_write(name, 0, data, timeout=5_000_000)
                dt = time.monotonic() - t
                say(f"ecx_FOEwrite {name!r}, {len(data)} bytes: {r} ({dt:.2f} s) - {what}")
                # EC_NOFRAME: a frame of the transfer came back too late for
                # SOEM (a loaded machine), not an answer of the drive; the
                # drive's answer to it may still wait in SM1 and would answer
                # the next request (SOEM: -7, packet number), so the master
                # ends the session as after any broken transfer: Init (the
                # mailbox and the FoE state are reset), the bootstrap
                # mailbox again, Bootstrap, and a new write request
                if r != EC_NOFRAME:
                    break
                say(f"RETRY {what}: SOEM lost a frame (attempt {attempt}); Init and Bootstrap again")
                to_state(s, pysoem.INIT_STATE, "Bootstrap -> Init (retry)")
                s.amend_mbx(mailbox="out", start_address=rx_addr, size=rx_len)
                s.amend_mbx(mailbox="in", start_address=tx_addr, size=tx_len)
                to_state(s, pysoem.BOOT_STATE, "Init -> Bootstrap (retry)")
            if want is None:
                check(r > 0, f"{what}: accepted (result {r})")
            else:
                check(r == want, f"{what}: result {r}, expected {want}")
        # what a master does after the download
        to_state(s, pysoem.INIT_STATE, "Bootstrap -> Init")
        # the standard mailbox again for Pre-Op (config_init set it up)
        for _ in range(3):
            if m.config_init() > 0:
                break
        to_state(m.slaves[0], pysoem.PREOP_STATE, "Init -> Pre-Op after the download")
    finally:
        m.close()
    return L.report("all checks passed")


if __name__ == "__main__":
    sys.exit(main())
