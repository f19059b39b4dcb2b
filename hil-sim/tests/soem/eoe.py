#!/usr/bin/env python3
"""EoE through SOEM as a user would: set IP, then ping and the UDP parameter
service of every drive through a Linux TAP interface bridged to EoE.

pysoem has no EoE call, but it gives every slave configured-address register
access (`_fprd`, `_fpwr`). Through it this script is SOEM's EoE:

- the mailbox as SOEM's ecx_mbxsend/ecx_mbxreceive drive it: wait until SM0
  is empty, write the whole SM0 buffer; wait until SM1 is full, read the
  whole SM1 buffer, on a lost read toggle the repeat request (SM1 activate
  bit 1) and wait for the slave's acknowledge;
- the set-IP request byte for byte as ecx_EOEsetIp builds it: only the
  flagged fields, packed, every address a little-endian UINT32 (flags 0Eh,
  IP 10.77.0.k, mask /24, gateway 10.77.0.1); result 0 expected [E-096];
- the Ethernet frames as ecx_EOEsend/ecx_EOErecv fragment and reassemble
  them, between the drives and a TAP interface `eoe0` with 10.77.0.1/24:
  frames from the TAP go to the drive with that MAC (broadcasts to every
  drive), frames from a drive go to the TAP [E-095].

Run by `hil-sim/tests/soem.rs` as root inside the master's network namespace
(the TAP and its address stay inside it). Checks, for every drive:
  - nothing in the send mailbox before the master used EoE [E-098];
  - set IP answered with result 0 [E-096];
  - `ping -c 3` answered, also with 1200-byte pings (5 EoE fragments each
    way) [E-095];
  - the UDP parameter service on port 5011 (docs/eoe.md): `R A166` gives the
    declared default, `M A166` its CoE address, `R 2.A150` the abort code.
No SOEM mailbox call is made here (SOEM keeps its own mailbox counter, this
script another one; the drive drops a message whose counter repeats the
previous one, as the mailbox protocol says).
"""
import argparse
import fcntl
import os
import select
import socket
import struct
import subprocess
import sys
import threading
import time

import pysoem

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import line as L  # noqa: E402  (line.py beside this file: check, say, the report)

check, say = L.check, L.say

PREOP = 0x02
MBX_EOE = 0x02
EOE_FRAG_DATA, EOE_INIT_REQ, EOE_INIT_RESP = 0, 2, 3
# SOEM's timeouts (ethercattype.h): frame, mailbox write, mailbox read
EC_TIMEOUTRET = 2000
EC_TIMEOUTRET3 = 3 * EC_TIMEOUTRET
EC_TIMEOUTRXM = 700_000
NET = "10.77.0"
TAP = "eoe0"
PARAM_PORT = 5011


def ip_le(addr):
    """An IPv4 address as SOEM's EOE_ip_uint32_to_byte writes it: a
    little-endian UINT32, the first octet last (10.77.0.2 -> 02 00 4d 0a)."""
    return bytes(reversed(socket.inet_aton(addr)))


def next_cnt(c):
    """ec_nextmbxcnt: 1..7, never 0."""
    return 1 if c >= 7 else c + 1


class Mailbox:
    """One slave's mailbox, driven through register access as SOEM does."""

    def __init__(self, slave, pos, lock):
        self.s = slave
        self.pos = pos
        self.lock = lock
        sm0 = slave._fprd(0x0800, 8, 20_000)
        sm1 = slave._fprd(0x0808, 8, 20_000)
        self.wo, self.wl = struct.unpack_from("<HH", sm0, 0)
        self.ro, self.rl = struct.unpack_from("<HH", sm1, 0)
        self.cnt = 0
        self.repeats = 0

    def _fprd(self, ado, n, timeout=EC_TIMEOUTRET):
        with self.lock:
            return self.s._fprd(ado, n, timeout)

    def _fpwr(self, ado, data, timeout=EC_TIMEOUTRET):
        with self.lock:
            self.s._fpwr(ado, data, timeout)

    def send(self, mbxtype, body, timeout_us=20_000):
        """ecx_mbxsend: wait for SM0 empty, write the whole buffer; the
        header's counter is the next of ec_nextmbxcnt."""
        self.cnt = next_cnt(self.cnt)
        msg = struct.pack("<HHBB", len(body), 0, 0, mbxtype | (self.cnt << 4)) + body
        if len(msg) > self.wl:
            raise ValueError(f"mailbox message of {len(msg)} bytes, SM0 has {self.wl}")
        end = time.monotonic() + timeout_us / 1e6
        while True:
            try:
                if self._fprd(0x0805, 1)[0] & 0x08 == 0:
                    break
            except pysoem.WkcError:
                pass
            if time.monotonic() > end:
                return False
            time.sleep(0.0002)
        try:
            self._fpwr(self.wo, msg + bytes(self.wl - len(msg)), EC_TIMEOUTRET3)
        except pysoem.WkcError:
            return False
        return True

    def receive(self, timeout_us):
        """ecx_mbxreceive: wait for SM1 full, read the whole buffer; a read
        that got lost is asked again with the repeat request. Returns
        (type, counter, body) or None."""
        end = time.monotonic() + timeout_us / 1e6
        while True:
            try:
                stat = struct.unpack("<H", self._fprd(0x080D, 2))[0]
                if stat & 0x08:
                    break
            except pysoem.WkcError:
                pass
            if time.monotonic() > end:
                return None
            if timeout_us:
                time.sleep(0.0002)
        while True:
            try:
                data = self._fprd(self.ro, self.rl)
                break
            except pysoem.WkcError:
                # the read reached the slave but not us: toggle the repeat request
                self.repeats += 1
                stat ^= 0x0200
                self._fpwr(0x080D, struct.pack("<H", stat))
                while time.monotonic() < end + 1:
                    try:
                        if (self._fprd(0x080F, 1)[0] & 0x02) == ((stat >> 8) & 0x02):
                            break
                    except pysoem.WkcError:
                        pass
                while time.monotonic() < end + 1:
                    try:
                        if struct.unpack("<H", self._fprd(0x080D, 2))[0] & 0x08:
                            break
                    except pysoem.WkcError:
                        pass
                    time.sleep(0.0002)
                if time.monotonic() > end + 1:
                    return None
        length, _addr, _prio, ty = struct.unpack_from("<HHBB", data, 0)
        return ty & 0x0F, (ty >> 4) & 0x07, data[6 : 6 + length]


def set_ip_request(ip, mask, gateway):
    """ecx_EOEsetIp with ip, subnet and default gateway set (the body after
    the mailbox header): frame info 1 = type 2 | last fragment, frame info 2
    = 0, then a 4-byte field whose first byte holds the flags, then the
    flagged fields packed, in order."""
    flags = 0x02 | 0x04 | 0x08  # EOE_PARAM_IP_INCLUDE, _SUBNET_IP_, _DEFAULT_GATEWAY_
    frameinfo1 = EOE_INIT_REQ | (0 << 4) | (1 << 8)
    return struct.pack("<HH", frameinfo1, 0) + bytes([flags, 0, 0, 0]) + ip_le(ip) + ip_le(mask) + ip_le(gateway)


class EoeDrive:
    """ecx_EOEsend / ecx_EOErecv for one drive."""

    txframeno = 0  # static in ecx_EOEsend: one counter for every slave

    def __init__(self, mbx, mac):
        self.mbx = mbx
        self.mac = mac
        self.rx = bytearray()
        self.rx_frag = 0
        self.rx_frameno = None
        self.rx_size = 0
        self.frames_in = self.frames_out = self.fragments_in = self.fragments_out = 0
        self.unexpected = []

    def send_frame(self, frame):
        maxdata = self.mbx.wl - 0x0A  # mailbox size - 6 header - 4 EoE header
        offset = frag = 0
        EoeDrive.txframeno += 1
        while True:
            size = len(frame) - offset
            if size > maxdata:
                size = (maxdata >> 5) << 5  # whole 32-byte blocks
            last = size == len(frame) - offset
            fi1 = (1 << 8) if last else 0  # port 0, last fragment
            fi2 = frag & 0x3F
            fi2 |= ((offset >> 5) if frag else ((len(frame) + 31) >> 5)) << 6
            fi2 |= (EoeDrive.txframeno & 0x0F) << 12
            if not self.mbx.send(MBX_EOE, struct.pack("<HH", fi1, fi2) + frame[offset : offset + size]):
                say(f"drive {self.mbx.pos}: EoE fragment {frag} not placed in SM0")
                return False
            self.fragments_out += 1
            if last:
                self.frames_out += 1
                return True
            offset += size
            frag += 1

    def poll(self):
        """One mailbox read (timeout 0): a received frame, or None."""
        got = self.mbx.receive(0)
        if got is None:
            return None
        ty, _cnt, body = got
        if ty != MBX_EOE or len(body) < 4:
            self.unexpected.append(got)
            say(f"drive {self.mbx.pos}: unexpected mailbox message type {ty}: {body[:16].hex()}")
            return None
        fi1, fi2 = struct.unpack_from("<HH", body, 0)
        if fi1 & 0x0F != EOE_FRAG_DATA:
            self.unexpected.append(got)
            say(f"drive {self.mbx.pos}: unexpected EoE frame type {fi1 & 0x0F}: {body[:16].hex()}")
            return None
        self.fragments_in += 1
        data = body[4:]
        frag, off, frameno = fi2 & 0x3F, (fi2 >> 6) & 0x3F, fi2 >> 12
        if frag == 0:
            self.rx = bytearray()
            self.rx_frag = 0
            self.rx_frameno = frameno
            self.rx_size = off << 5
        elif frag != self.rx_frag or frameno != self.rx_frameno or (off << 5) != len(self.rx):
            say(f"drive {self.mbx.pos}: fragment {frag} (frame {frameno}, offset {off << 5}) out of order, dropped")
            self.rx_frag = -1
            return None
        self.rx += data
        self.rx_frag += 1
        if len(self.rx) > max(self.rx_size, 1536):
            say(f"drive {self.mbx.pos}: EoE frame longer than announced ({len(self.rx)} > {self.rx_size})")
            self.rx_frag = -1
            return None
        if fi1 & (1 << 8):
            if fi1 & (1 << 9):  # time appended
                del self.rx[-4:]
            self.frames_in += 1
            frame, self.rx = bytes(self.rx), bytearray()
            return frame
        return None


def open_tap(name):
    TUNSETIFF, IFF_TAP, IFF_NO_PI = 0x400454CA, 0x0002, 0x1000
    fd = os.open("/dev/net/tun", os.O_RDWR | os.O_NONBLOCK)
    fcntl.ioctl(fd, TUNSETIFF, struct.pack("16sH", name.encode(), IFF_TAP | IFF_NO_PI))
    return fd


class Bridge(threading.Thread):
    """Frames between the TAP and the drives' EoE, until stopped."""

    def __init__(self, tap, drives):
        super().__init__(daemon=True)
        self.tap = tap
        self.drives = drives
        self.stop = False
        self.error = None

    def run(self):
        try:
            while not self.stop:
                r, _, _ = select.select([self.tap], [], [], 0.0005)
                if r:
                    try:
                        frame = os.read(self.tap, 2048)
                    except BlockingIOError:
                        frame = b""
                    if len(frame) >= 14:
                        dst = frame[:6]
                        for d in self.drives:
                            if dst[0] & 1 or dst == d.mac:
                                d.send_frame(frame)
                for d in self.drives:
                    frame = d.poll()
                    if frame is not None:
                        if len(frame) >= 14 and frame[6:12] != d.mac:
                            say(f"drive {d.mbx.pos}: frame from {frame[6:12].hex(':')}, its MAC is {d.mac.hex(':')}")
                        os.write(self.tap, frame)
        except Exception as e:  # noqa: BLE001 - reported by the main thread
            self.error = e


def sh(*cmd):
    subprocess.run(cmd, check=True)


def udp(ip, request, tries=3):
    """One request to the parameter service; UDP may lose a datagram, so it
    is sent again after 2 s without an answer."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as u:
        u.settimeout(2.0)
        for _ in range(tries):
            u.sendto(request.encode(), (ip, PARAM_PORT))
            try:
                answer, peer = u.recvfrom(1500)
            except socket.timeout:
                continue
            if peer[0] == ip:
                return answer.decode(errors="replace").strip()
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--iface", required=True)
    ap.add_argument("--slaves", type=int, default=3)
    ap.add_argument("--a166", type=int, required=True, help="A166's declared default (the dictionary)")
    args = ap.parse_args()
    m = pysoem.Master()
    m.open(args.iface)
    tap = None
    try:
        n = L.config_init(m)
        say(f"config_init: {n} slave(s)")
        if not check(n == args.slaves, f"config_init found {n} slaves, expected {args.slaves}"):
            return 1
        check(m.read_state() == PREOP, "every drive in Pre-Op")
        lock = threading.Lock()
        mbxs = [Mailbox(s, i + 1, lock) for i, s in enumerate(m.slaves)]
        say(f"mailbox: SM0 {mbxs[0].wo:#06x}/{mbxs[0].wl}, SM1 {mbxs[0].ro:#06x}/{mbxs[0].rl}")

        # E-098: nothing unasked before the master uses EoE
        time.sleep(0.5)
        for mb in mbxs:
            got = mb.receive(0)
            check(got is None, f"drive {mb.pos}: mailbox message before the master used EoE: {got}")

        # E-096: set IP, SOEM's request bytes
        drives = []
        for mb in mbxs:
            ip = f"{NET}.{mb.pos + 1}"
            body = set_ip_request(ip, "255.255.255.0", f"{NET}.1")
            say(f"drive {mb.pos}: set IP {ip}/24 gateway {NET}.1: mailbox body {body.hex(' ')}")
            if not check(mb.send(MBX_EOE, body), f"drive {mb.pos}: set-IP request not placed in SM0"):
                continue
            got = mb.receive(EC_TIMEOUTRXM)
            if not check(got is not None, f"drive {mb.pos}: no answer to the set-IP request"):
                continue
            ty, _cnt, resp = got
            fi1, result = struct.unpack_from("<HH", resp, 0) if len(resp) >= 4 else (None, None)
            say(f"drive {mb.pos}: answer type {ty}, frame type {fi1 & 0x0F if fi1 is not None else '-'}, result {result}")
            check(
                ty == MBX_EOE and fi1 is not None and fi1 & 0x0F == EOE_INIT_RESP and result == 0,
                f"drive {mb.pos}: set-IP answer type {ty}, EoE frame type {fi1}, result {result}; expected EoE set-IP response with result 0",
            )
            drives.append((ip, EoeDrive(mb, bytes([0x02, 0, 0, 0, 0, mb.pos]))))

        # the TAP in this namespace, bridged to the drives' EoE
        tap = open_tap(TAP)
        sh("ip", "link", "set", TAP, "up")
        sh("ip", "addr", "add", f"{NET}.1/24", "dev", TAP)
        bridge = Bridge(tap, [d for _, d in drives])
        bridge.start()
        for ip, d in drives:
            for size, count in ((56, 3), (1200, 2)):
                # a machine that stalls the master may lose a ping: then it is pinged once more
                for k in range(2):
                    t = time.monotonic()
                    p = subprocess.run(
                        ["ping", "-c", str(count), "-s", str(size), "-W", "2", "-i", "0.2", ip],
                        capture_output=True,
                        text=True,
                    )
                    summary = [line for line in p.stdout.splitlines() if "transmitted" in line or "rtt" in line]
                    say(f"ping -c {count} -s {size} {ip}: {' / '.join(summary)} ({time.monotonic() - t:.1f} s)")
                    ok = p.returncode == 0 and f"{count} received" in p.stdout
                    if ok or k:
                        break
                    say(f"RETRY ping -s {size} {ip}")
                check(ok, f"ping -s {size} {ip}: {p.stdout.strip()} {p.stderr.strip()}")
            for req, want in (("R A166", f"OK {args.a166}"), ("M A166", "OK 20A6:00"), ("R 2.A150", "ERR 06020000")):
                got = udp(ip, req)
                say(f"udp {ip}:{PARAM_PORT} {req!r} -> {got!r}")
                check(got == want, f"{ip}: {req!r} answered {got!r}, expected {want!r}")
        bridge.stop = True
        bridge.join(2)
        check(bridge.error is None, f"bridge: {bridge.error!r}")
        for ip, d in drives:
            say(
                f"drive {d.mbx.pos} ({ip}): {d.frames_out} frames in {d.fragments_out} fragments to the drive, "
                f"{d.frames_in} frames in {d.fragments_in} fragments from it, {d.mbx.repeats} repeat requests"
            )
            check(not d.unexpected, f"drive {d.mbx.pos}: {len(d.unexpected)} unexpected mailbox messages")
            check(d.fragments_in > d.frames_in and d.fragments_out > d.frames_out, f"drive {d.mbx.pos}: fragmented frames both ways")
    except (pysoem.WkcError, OSError, subprocess.CalledProcessError) as e:
        check(False, f"stopped: {e!r}")
    finally:
        if tap is not None:
            os.close(tap)
        m.close()
    return L.report("all checks passed")


if __name__ == "__main__":
    sys.exit(main())
