"""Helpers shared by the profinet-py scripts of hil-sim's PROFINET tests
(controller.py, fb.py): profinet-py's log kept, the veth's checksum
offload switched off, serve's control FIFO written, a device named and
addressed through DCP and connected for cyclic data, a scenario's checks
reported as one line (`Scenario`)."""

import ctypes
import fcntl
import gc
import logging
import os
import socket
import struct
import time

from profinet import dcp
from profinet.device import ProfinetDevice
from profinet.gsdml import load_gsdml
from profinet.rpc import IOCRSetup, get_station_info
from profinet.util import ethernet_socket


class Records(logging.Handler):
    """Keeps profinet-py's log records (the RTA ERR PDU is only logged)."""

    def __init__(self):
        super().__init__(logging.DEBUG)
        self.lines = []

    def emit(self, record):
        self.lines.append(f"{record.name}: {record.getMessage()}")


def tx_checksum_offload_off(iface):
    """`ethtool -K IF tx off` (SIOCETHTOOL, ETHTOOL_STXCSUM): a veth leaves
    the UDP checksum of the kernel's datagrams to the receiver (offload), so
    the device, reading raw frames on the other end, would see them as
    corrupt and drop them, as it must."""
    value = ctypes.create_string_buffer(struct.pack("II", 0x17, 0))
    ifr = struct.pack("16sP", iface.encode()[:15], ctypes.addressof(value))
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        fcntl.ioctl(s.fileno(), 0x8946, ifr)


def control(path, command):
    """One line to serve's control FIFO (serve reads it without blocking;
    the open waits for it)."""
    with open(path, "w") as f:
        f.write(command + "\n")


def io_slots(gsdml, out_module, in_module):
    """The expected submodules: the GSDML's DAP, the OUT module in slot 1
    and the IN module in slot 2."""
    gsd = load_gsdml(gsdml)
    return gsd.build_io_slots(slot_assignment={1: out_module, 2: in_module})


def name_and_address(iface, src, mac, name, ip, mask="255.255.255.0"):
    """DCP Set name of station and IP suite (permanent) of the device with
    MAC `mac`, then Identify by name: the device's description."""
    sock = ethernet_socket(iface)
    try:
        ok_name = dcp.set_param(sock, src, mac, "name", name, permanent=True)
        ok_ip = dcp.set_ip(sock, src, mac, ip, mask, "0.0.0.0", permanent=True)
        if not (ok_name and ok_ip):
            raise RuntimeError(f"DCP Set name {name!r}: {ok_name}, IP {ip}: {ok_ip}")
        return get_station_info(sock, src, name, timeout_sec=3, strict_xid=True)
    finally:
        sock.close()


def cyclic_setup(slots, watchdog=50):
    """1 ms = send clock 32 x 31.25 us, reduction ratio 1: profinet-py's
    CyclicController refuses anything shorter. The watchdog (and data hold)
    at `watchdog` cycles keeps a Python sender's scheduling gaps on a
    shared machine from ending the AR."""
    return IOCRSetup(slots=slots, reduction_ratio=1, watchdog_factor=watchdog, data_hold_factor=watchdog)


def real_time(priority=10):
    """SCHED_FIFO for this thread and the threads it starts afterwards
    (profinet-py's sender and receiver), so that a busy machine does not
    hold the cyclic sender for the device's watchdog time; what was
    applied, one line."""
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
        return f"SCHED_FIFO priority {priority}"
    except (OSError, AttributeError) as e:
        return f"no real-time scheduling ({e})"


def quiet_collector():
    """Collects now and moves every object alive into the collector's
    permanent generation (gc.freeze), so that no full collection walks
    them while cyclic data runs. profinet-py's receive thread parses every
    frame with construct, whose contexts are reference cycles: each ~2.4 s
    they set off a full collection that held the GIL for 60 to 110 ms
    (measured with gc.callbacks), the sender stopped as long and the
    device's data hold expired (CI, 2026-12-08). With the freeze the
    longest gap between two output frames was 9 ms."""
    gc.collect()
    gc.freeze()


def start_cyclic(info, iface, src, slots, watchdog=50):
    """Connect, PrmEnd, ApplicationReady and cyclic data at 1 ms:
    (device, controller, OUT slot, IN slot)."""
    quiet_collector()
    dev = ProfinetDevice(info, iface, src, timeout=5.0)
    try:
        ctl = dev.start_cyclic(cyclic_setup(slots, watchdog))
    except Exception:
        dev.close()
        raise
    out_slot = next(s for s in slots if s.output_length > 0)
    in_slot = next(s for s in slots if s.input_length > 0)
    return dev, ctl, out_slot, in_slot


class Scenario:
    """The checks of one scenario, reported as one line."""

    def __init__(self, item):
        self.item = item
        self.parts = []
        self.failed = False
        self.known = []
        self.t0 = time.monotonic()

    def check(self, ok, text, known=None):
        """`known`: the drive's known deviation (spec item, what it does):
        a failed check is then an expected failure."""
        if ok:
            self.parts.append(text)
        elif known is not None:
            self.known.append(f"{text} ({known})")
        else:
            self.parts.append(f"FAIL: {text}")
            self.failed = True
        return ok

    def note(self, text):
        self.parts.append(text)

    def line(self):
        body = "; ".join(self.parts)
        known = " / ".join(self.known)
        if self.failed:
            return f"scenario {self.item}: FAIL: {body}" + (f"; expected-fail: {known}" if known else "")
        if self.known:
            return f"scenario {self.item}: expected-fail: {known}; passed: {body}"
        return f"scenario {self.item}: ok: {body}"


def ms(dt):
    return "not within the limit" if dt is None else f"{1000 * dt:.0f} ms"
