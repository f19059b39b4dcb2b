#!/usr/bin/env python3
"""Checks in the style of the ETG conformance test tool, written on SOEM's
low-level API (pysoem's register access `_fprd`/`_fpwr`), against `hil-sim
serve` over raw Ethernet (issue 33). Run by `hil-sim/tests/soem_conformance.rs`
as root inside the master's network namespace (or by hand against `serve`).

  --case op-repeat  E-033/E-047: Safe-Op -> Op that cannot succeed (A258 =
                    100 ms, no process data): refused with 002Bh whether the
                    master writes AL control once or every 5 ms (a repeated
                    identical request does not restart the drive's wait).
  --case sm-off     E-025/E-045: a SyncManager switched off by the master
                    (FPWR of its activate register 0x0806 + 8n, bit 0 = 0):
                    SM0/SM1 in Pre-Op, Safe-Op, Op -> Init + ERR 0016h; SM2 in
                    Safe-Op/Op -> Pre-Op + ERR 001Dh, SM3 001Eh; SM2/SM3 in
                    Pre-Op: nothing. After each, SOEM's scan (Init with
                    acknowledge, the SMs again) brings the drive back.
  --case mbx-type   E-027: mailbox requests of a reserved type (6, 14) and
                    of protocols the drive does not speak (AoE 1, SoE 5)
                    written into SM0 by FPWR: the mailbox error reply
                    (type 0) with 0002h "unsupported protocol"; an SDO read
                    through SOEM works afterwards.
  --case id-request E-026 (ETG.1000.6 explicit device identification): an
                    alias written into the SII (word 4, with the words 0-7
                    CRC) and reloaded into 0x0012 by the ESC; AL control Init
                    + ID request (bit 5) -> AL status 0x21 with the alias in
                    0x0134; Pre-Op + ID -> 0x22, the alias; a request without
                    bit 5 clears both; a refused request shows its error.
  --case frames     E-002 (issue 33.3): frames as libethercat and other
                    masters send them, written to the raw socket beside
                    SOEM's: EtherCAT header length 16 bytes larger than the
                    datagrams and unpadded (veth does not pad), smaller than
                    the datagrams, a trailer after the last datagram: `serve`
                    processes each datagram as an ESC does (WKC 1, the AL
                    status); a frame that ends inside a datagram gets no
                    answer (silicon drops it too).

Exit status 0 when every check passed; each failed check is printed.
"""
import os
import socket
import struct
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import line as L  # noqa: E402  (line.py beside this file)
import pysoem  # noqa: E402

say, check = L.say, L.check
INIT, PREOP, SAFEOP, OP, ERR, ACK = L.INIT, L.PREOP, L.SAFEOP, L.OP, L.ERR, L.ACK
AL_CONTROL, AL_STATUS, AL_CODE = 0x0120, 0x0130, 0x0134
A258 = 0x2000 + 258
TIMEOUT_US = 20_000


def rd(s, ado, n):
    """FPRD with SOEM's repetition (a frame lost on a loaded machine)."""
    for _ in range(5):
        try:
            return s._fprd(ado, n, TIMEOUT_US)
        except pysoem.WkcError:
            time.sleep(0.002)
    raise L.Fatal(f"FPRD {ado:#06x}: no answer")


def wr(s, ado, data):
    for _ in range(5):
        try:
            s._fpwr(ado, data, TIMEOUT_US)
            return
        except pysoem.WkcError:
            time.sleep(0.002)
    raise L.Fatal(f"FPWR {ado:#06x}: no answer")


def al(s):
    """(AL status, AL status code) read by one FPRD of 0x0130..0x0135."""
    raw = rd(s, AL_STATUS, 6)
    return raw[0], struct.unpack_from("<H", raw, 4)[0]


def control(s, value):
    wr(s, AL_CONTROL, struct.pack("<H", value))


def to(s, value, want, timeout_s=3.0):
    """AL control `value` written once; the AL status until it shows `want`
    (state bits) or an error; (status, code)."""
    control(s, value)
    end = time.monotonic() + timeout_s
    while True:
        st, code = al(s)
        if (st & 0x0F) == want or st & ERR or time.monotonic() > end:
            return st, code
        time.sleep(0.005)


def to_safeop(m, s):
    """From Pre-Op (after the scan): SOEM's map, Safe-Op."""
    m.manual_state_change = 1
    m.config_map()
    st, code = to(s, SAFEOP, SAFEOP)
    if st != SAFEOP:
        raise L.Fatal(f"Safe-Op not reached: {st:#04x}/{code:04X}h")


def case_op_repeat(m):
    s = m.slaves[0]
    s.sdo_write(A258, 0, struct.pack("<H", 100))
    to_safeop(m, s)
    for every_ms in (None, 5, 1):
        how = "written once" if every_ms is None else f"rewritten every {every_ms} ms"
        t0 = time.monotonic()
        control(s, OP)
        writes, seen = 1, []
        while time.monotonic() - t0 < 3.0:
            if every_ms is not None:
                control(s, OP)
                writes += 1
            st, code = al(s)
            seen.append((time.monotonic() - t0, st, code))
            if st & ERR:
                break
            time.sleep((every_ms or 5) / 1000)
        dt, st, code = seen[-1]
        say(f"Op {how}: {st:#04x}/{code:04X}h after {dt * 1000:.0f} ms, {writes} writes")
        waiting = [x for x in seen if x[0] < 0.15]
        check(all(x[1] == SAFEOP and x[2] == 0 for x in waiting), f"Op {how}: Safe-Op without error while waiting: {waiting[:3]}")
        check((st, code) == (SAFEOP | ERR, 0x002B), f"Op {how}: refused with 002Bh, got {st:#04x}/{code:04X}h")
        # the drive refuses 200 ms after the request; a loaded machine may
        # read it later, never earlier (nor never, as before issue 33)
        check(0.19 <= dt <= 1.5, f"Op {how}: refused {dt * 1000:.0f} ms after the first request")
        st, code = to(s, SAFEOP | ACK, SAFEOP)
        check((st, code) == (SAFEOP, 0), f"acknowledged: {st:#04x}/{code:04X}h")


def case_sm_off(m):
    s = m.slaves[0]
    names = {INIT: "Init", PREOP: "Pre-Op", SAFEOP: "Safe-Op", OP: "Op"}
    cases = [
        (0, PREOP, (INIT, 0x0016)),
        (1, PREOP, (INIT, 0x0016)),
        (2, PREOP, None),
        (3, PREOP, None),
        (0, SAFEOP, (INIT, 0x0016)),
        (1, SAFEOP, (INIT, 0x0016)),
        (2, SAFEOP, (PREOP, 0x001D)),
        (3, SAFEOP, (PREOP, 0x001E)),
        (0, OP, (INIT, 0x0016)),
        (1, OP, (INIT, 0x0016)),
        (2, OP, (PREOP, 0x001D)),
        (3, OP, (PREOP, 0x001E)),
    ]
    mapped = False
    for n, state, want in cases:
        what = f"SM{n} off in {names[state]}"
        # SOEM's map activates SM2/SM3 (in Pre-Op)
        if n >= 2 or state != PREOP:
            if not mapped:
                m.manual_state_change = 1
                m.config_map()
                mapped = True
        if state != PREOP:
            st, code = to(s, SAFEOP, SAFEOP)
            if state == OP and st == SAFEOP:
                # no RxPDO monitoring by default (A258): Op without frames
                st, code = to(s, OP, OP)
            if not check((st, code) == (state, 0), f"{what}: {names[state]} first, got {st:#04x}/{code:04X}h"):
                continue
        act = rd(s, 0x0806 + 8 * n, 1)[0]
        check(act & 1 == 1, f"{what}: SM{n} active before ({act:#04x})")
        wr(s, 0x0806 + 8 * n, bytes([act & 0xFE]))
        end = time.monotonic() + 1.0
        while True:
            st, code = al(s)
            if st & ERR or time.monotonic() > end:
                break
            time.sleep(0.005)
        say(f"{what}: {st:#04x}/{code:04X}h")
        if want is None:
            check((st, code) == (state, 0), f"{what}: stays {names[state]} without error, got {st:#04x}/{code:04X}h")
            wr(s, 0x0806 + 8 * n, bytes([act]))
            continue
        check((st, code) == (want[0] | ERR, want[1]), f"{what}: {names[want[0]]} + ERR {want[1]:04X}h expected, got {st:#04x}/{code:04X}h")
        # SOEM's scan: Init with acknowledge, the mailbox SMs again, Pre-Op
        m.manual_state_change = 0
        L.scan(m, 1)
        st, code = to(s, PREOP, PREOP)
        check((st, code) == (PREOP, 0), f"{what}: Pre-Op again after SOEM's scan, got {st:#04x}/{code:04X}h")
        mapped = False


def mbx_read(s, timeout_s=1.0):
    """The SM1 mailbox content once it is full (None after the timeout)."""
    start, length = struct.unpack("<HH", rd(s, 0x0808, 4))
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        if rd(s, 0x080D, 1)[0] & 0x08:
            return rd(s, start, length)
        time.sleep(0.002)
    return None


def case_mbx_type(m):
    s = m.slaves[0]
    start, length = struct.unpack("<HH", rd(s, 0x0800, 4))
    while mbx_read(s, 0.05) is not None:
        pass  # anything the drive had queued (EMCY)
    for k, ty in enumerate((6, 14, 1, 5)):
        counter = k + 1
        msg = struct.pack("<HHBB", 4, 0, 0, ty | (counter << 4)) + bytes([0x11, 0x22, 0x33, 0x44])
        wr(s, start, msg + bytes(length - len(msg)))
        got = mbx_read(s)
        if not check(got is not None, f"type {ty}: no answer"):
            continue
        kind = got[5] & 0x0F
        etype, detail = struct.unpack_from("<HH", got, 6)
        say(f"mailbox type {ty}: reply type {kind}, {etype:04X}h/{detail:04X}h")
        check((kind, etype, detail) == (0, 0x0001, 0x0002), f"type {ty}: mailbox error 0002h expected")
    # SOEM's own mailbox counter starts again from whatever it holds; an SDO read works
    check(L.u(s.sdo_read(0x1000, 0)) == 0x00020192, "1000h by SDO afterwards")


def crc8(data):
    """The SII words 0-7 checksum (CRC-8, polynomial 0x07, initial 0xFF)."""
    c = 0xFF
    for b in data:
        c ^= b
        for _ in range(8):
            c = ((c << 1) ^ 0x07) & 0xFF if c & 0x80 else (c << 1) & 0xFF
    return c


def case_id_request(m):
    s = m.slaves[0]
    alias = 0x0B0E
    words = b"".join(s.eeprom_read(w)[:2] for w in range(7))
    words = words[:8] + struct.pack("<H", alias) + words[10:14]
    s.eeprom_write(4, struct.pack("<H", alias))
    s.eeprom_write(7, bytes([crc8(words), 0]))
    # the ESC reloads its configuration from the SII (0x0502 command 100b)
    wr(s, 0x0502, struct.pack("<H", 0x0400))
    end = time.monotonic() + 1.0
    while rd(s, 0x0502, 2)[1] & 0x80 and time.monotonic() < end:
        time.sleep(0.002)
    got = struct.unpack("<H", rd(s, 0x0012, 2))[0]
    check(got == alias, f"station alias {got:#06x} after the reload, {alias:#06x} expected")
    for value, want, what in [
        (INIT | 0x20, (INIT | 0x20, alias), "Init + ID request"),
        (PREOP | 0x20, (PREOP | 0x20, alias), "Pre-Op + ID request"),
        (PREOP, (PREOP, 0), "Pre-Op without it"),
        (OP | 0x20, (PREOP | ERR, 0x0011), "Op + ID request from Pre-Op (refused)"),
        (INIT | ACK | 0x20, (INIT | 0x20, alias), "acknowledge + Init + ID request"),
        (INIT, (INIT, 0), "Init without it"),
    ]:
        control(s, value)
        deadline = time.monotonic() + 1.0
        while True:
            raw = rd(s, AL_STATUS, 6)
            st, code = struct.unpack_from("<H", raw, 0)[0] & 0x3F, struct.unpack_from("<H", raw, 4)[0]
            if (st, code) == want or time.monotonic() > deadline:
                break
            time.sleep(0.005)
        say(f"{what}: AL status {st:#04x}, 0x0134 = {code:#06x}")
        check((st, code) == want, f"{what}: {want[0]:#04x}/{want[1]:#06x} expected")


def raw_frame(sock, mac, ado_station, delta, trailer=b"", cut=0):
    """One FPRD of AL status (0x0130, 2 bytes) of `ado_station` with the
    EtherCAT header's length field off by `delta`, `trailer` appended, `cut`
    bytes removed from the end; the answer's (WKC, data) or None."""
    index = 0x5A
    body = struct.pack("<BBHHHH", 0x04, index, ado_station, AL_STATUS, 2, 0) + bytes(2) + b"\x00\x00"
    length = (len(body) + delta) & 0x07FF
    frame = b"\xff" * 6 + mac + b"\x88\xa4" + struct.pack("<H", length | 0x1000) + body + trailer
    frame = frame[: len(frame) - cut]
    sock.send(frame)
    end = time.monotonic() + 0.3
    while time.monotonic() < end:
        try:
            data, addr = sock.recvfrom(2048)
        except socket.timeout:
            return None
        if addr[2] == socket.PACKET_OUTGOING or data[12:14] != b"\x88\xa4" or len(data) < 16 + 14:
            continue
        if data[16] != 0x04 or data[17] != index:
            continue  # SOEM's own traffic
        return struct.unpack_from("<H", data, 16 + 12)[0], data[16 + 10 : 16 + 12]
    return None


def case_frames(m, iface):
    s = m.slaves[0]
    station = struct.unpack("<H", rd(s, 0x0010, 2))[0]  # as SOEM configured it
    want = rd(s, AL_STATUS, 2)
    sock = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.htons(0x88A4))
    sock.bind((iface, 0))
    sock.settimeout(0.3)
    mac = sock.getsockname()[4]
    try:
        for what, delta, trailer in [
            ("header length +16, unpadded (libethercat)", 16, b""),
            ("header length +1, unpadded", 1, b""),
            ("header length -4, padded to 60 bytes", -4, bytes(30)),
            ("a 24-byte trailer after the last datagram", 0, b"\xaa" * 24),
        ]:
            got = None
            for _ in range(3):  # a frame lost on a loaded machine
                got = raw_frame(sock, mac, station, delta, trailer)
                if got is not None:
                    break
            say(f"{what}: answer {got}")
            check(got == (1, want), f"{what}: WKC 1 and AL status {want.hex()} expected")
        got = raw_frame(sock, mac, station, 0, cut=3)
        say(f"frame ending inside its datagram: answer {got}")
        check(got is None, "a frame that ends inside a datagram is dropped")
    finally:
        sock.close()


def run(m, args):
    L.scan(m, 1)
    check(m.read_state() == PREOP, f"Pre-Op after the scan: {L.state_report(m)}")
    if args.case == "frames":
        case_frames(m, args.iface)
    else:
        {"op-repeat": case_op_repeat, "sm-off": case_sm_off, "mbx-type": case_mbx_type, "id-request": case_id_request}[args.case](m)


L.script(__name__, __doc__, run, "all checks passed",
         ("--case", dict(required=True, choices=["op-repeat", "sm-off", "mbx-type", "id-request", "frames"])))
