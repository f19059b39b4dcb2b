"""Axis parameters through the PROFIdrive parameter access with profinet-py
against `hil-sim serve --fieldbus profinet` (issue 40): the torque-mode
speed limit G472 and the velocity controller's Kp C31 changed by record
0xB02E (P-206; PNU = the object's index, docs/pnu.md), the parameter set
saved by PNU 971 = 1 (P-199), a change after the save, the device
restarted (serve's control channel: powered on again over the same
parameter flash), and both values read back by profinet-py: the saved
values, not the later change and not the defaults.

No cyclic data: a device-access AR (records only), as an engineering tool
connects. One line:

    scenario P-199: ok|FAIL: ...
"""

import argparse
import contextlib
import logging
import sys
import time

import profinet
from profinet.device import ProfinetDevice
from profinet.rpc import get_station_info
from profinet.util import ethernet_socket, get_mac

import pnctl
from pnctl import Scenario

BMP_RECORD = 0xB02E
# parameter_index(group, line) = 0x2000 + group * 0x200 + line
G472 = 0x2000 + 6 * 0x200 + 472  # positive velocity limit torque mode, U16, 0.1 % of I10
C31 = 0x2000 + 2 * 0x200 + 31  # speed controller Kp, U32, uNm*s/rad
PNU_SAVE = 971
FMT_U16, FMT_U32 = 0x06, 0x07
# the declared defaults (docs/object-dictionary.md)
G472_DEFAULT, C31_DEFAULT = 0, 60_000
G472_NEW, C31_NEW, C31_UNSAVED = 500, 90_000, 70_000


def read_request(ref, params):
    """"Request parameter" (0x01), axis 1, value attribute, one element each."""
    b = bytes([ref, 0x01, 0x01, len(params)])
    for pnu in params:
        b += bytes([0x10, 1]) + pnu.to_bytes(2, "big") + (0).to_bytes(2, "big")
    return b


def change_request(ref, changes):
    """"Change parameter" (0x02): the addresses, then the values."""
    b = bytes([ref, 0x02, 0x01, len(changes)])
    for pnu, _, _ in changes:
        b += bytes([0x10, 1]) + pnu.to_bytes(2, "big") + (0).to_bytes(2, "big")
    for _, fmt, value in changes:
        size = 2 if fmt == FMT_U16 else 4
        b += bytes([fmt, 1]) + value.to_bytes(size, "big")
    return b


def parse_values(r, n):
    """The values of a positive read response of n single values; None if
    it is not one."""
    if r is None or len(r) < 4 or r[1] != 0x01 or r[3] != n:
        return None
    out, at = [], 4
    for _ in range(n):
        fmt, count = r[at], r[at + 1]
        size = {FMT_U16: 2, FMT_U32: 4}.get(fmt)
        if size is None or count != 1:
            return None
        out.append(int.from_bytes(r[at + 2:at + 2 + size], "big"))
        at += 2 + size
    return out


class Access:
    """Record 0xB02E on a device-access AR: a request written, its
    response read."""

    def __init__(self, info, iface, src):
        self.dev = ProfinetDevice(info, iface, src, timeout=5.0)
        self.ref = 0

    def exchange(self, make):
        self.ref = (self.ref + 1) & 0xFF
        req = make(self.ref)
        self.dev.write(0, 1, BMP_RECORD, req)
        return self.dev.read(0, 1, BMP_RECORD)

    def read(self, *pnus):
        return parse_values(self.exchange(lambda ref: read_request(ref, pnus)), len(pnus))

    def change(self, *changes):
        r = self.exchange(lambda ref: change_request(ref, changes))
        return r == bytes([self.ref, 0x02, 0x01, len(changes)]), r

    def close(self):
        self.dev.disconnect()
        self.dev.close()


def identify(iface, src, name, timeout):
    """DCP Identify by name until the device answers (it is starting)."""
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        sock = ethernet_socket(iface)
        try:
            return get_station_info(sock, src, name, timeout_sec=1, strict_xid=True)
        except Exception:  # noqa: BLE001 - not up yet
            time.sleep(0.2)
        finally:
            sock.close()
    return None


def check_g472_c31(sc, acc, when, wanted, want):
    """G472 and C31 read through `acc` must be `want` ([G472, C31]), checked
    as "`when`: … (`wanted` …)"."""
    got = acc.read(G472, C31)
    sc.check(got == want, f"{when}: G472 {got and got[0]} C31 {got and got[1]} ({wanted} {want[0]}, {want[1]})")


def p199(sc, a, src):
    info = pnctl.name_and_address(a.iface, src, a.device_mac.lower(), a.name, a.ip)
    with contextlib.closing(Access(info, a.iface, src)) as acc:
        check_g472_c31(sc, acc, "before", "the defaults", [G472_DEFAULT, C31_DEFAULT])
        ok, r = acc.change((G472, FMT_U16, G472_NEW), (C31, FMT_U32, C31_NEW))
        now = acc.read(G472, C31)
        sc.check(ok and now == [G472_NEW, C31_NEW],
                 f"changed by 0xB02E: G472 = {G472_NEW} (50 % of I10), C31 = {C31_NEW}: answer "
                 f"{r.hex() if r else r}, read back {now}")
        ok, r = acc.change((PNU_SAVE, FMT_U16, 1))
        busy = acc.read(PNU_SAVE)
        sc.check(ok and busy == [0], f"PNU 971 = 1: answer {r.hex() if r else r}, PNU 971 then reads {busy} (done)")
        ok, _ = acc.change((C31, FMT_U32, C31_UNSAVED))
        sc.check(ok, f"C31 = {C31_UNSAVED} after the save (not saved)")
    pnctl.control(a.control, "restart")
    time.sleep(0.5)
    info = identify(a.iface, src, a.name, 10.0)
    if not sc.check(info is not None, f"after the restart: identified by name {a.name!r}"):
        return
    with contextlib.closing(Access(info, a.iface, src)) as acc:
        check_g472_c31(sc, acc, "after the restart", "want the saved", [G472_NEW, C31_NEW])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--iface", required=True)
    ap.add_argument("--device-mac", required=True)
    ap.add_argument("--control", required=True, help="serve's control FIFO (the restart)")
    ap.add_argument("--name", default="drive-params")
    ap.add_argument("--ip", default="192.168.0.52")
    a = ap.parse_args()
    logging.getLogger("profinet").addHandler(pnctl.Records())
    print(f"profinet-py {profinet.__version__} on {a.iface}", flush=True)
    pnctl.tx_checksum_offload_off(a.iface)
    src = get_mac(a.iface)
    sc = Scenario("P-199")
    try:
        p199(sc, a, src)
    except Exception as e:  # noqa: BLE001 - the scenario's failure
        sc.check(False, f"{type(e).__name__}: {e}")
    print(sc.line(), flush=True)
    return 1 if sc.failed else 0


if __name__ == "__main__":
    sys.exit(main())
