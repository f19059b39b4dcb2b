"""TIA Portal's start-up of our GSDML, played by a controller of our own on
scapy (tia_lib.py), not profinet-py; one line per result:

    step X: ok: ...              the step did what it should
    step X: FAIL: ...            it did not (the script exits 1 at the end; what
                                 issue 32.4 found missing is a hard check too)
    step X: skipped: ...         the step needs what this run lacks, and why

(a) DCP Identify All finds the device by its MAC;
(b) DCP Set name of station and IP suite (permanent), (c) Identify by name;
(d) the implicit read of I&M0 (little-endian NDR, as a PG/PC sends it) and of
    RealIdentificationData 0xF000;
(e) Connect in advanced startup (ARProperties StartupMode 1, RTClass 2
    IOCRs, FrameIDs 0x8000-0xBBFF), the PDev write-multiple as TIA sends it
    (PDInterfaceAdjust 0x8071, PDPortDataCheck 0x802B, PDPortDataAdjust
    0x802F in one IODWriteMultiple), PrmEnd, the device's ApplicationReady
    answered;
(f) --cyclic-seconds of cyclic data: every input frame's DataStatus, IOPS
    and IOCS good;
(g) reads of 0xF000, 0xF840, 0xF841, 0x8072, 0x802B, 0x802A, 0x8080 in the AR,
    and of the diagnosis records 0x800A (port 1) and 0xE00C (the AR);
(h) I&M1-4 written and read back, I&M0 read;
(i) a 4,068-byte record in 1,024-byte RPC fragments ("invalid index", no
    RPC fault) and a 4,069-byte one ("write length error");
(j) an alarm burst (three faults raised and reset 250 ms apart through
    serve's control FIFO), each alarm acknowledged 500 ms late: all
    confirmed, in rising sequence, the last one "disappears"; skipped without
    --control (a firmware image in QEMU); then, needing no simulator, a burst
    of port alarms: step e's topology check on port 1 withdrawn and set
    again (five writes of 0x802B 400 ms apart), the same checks;
(k) a second controller's Connect refused (out of AR resources) while the
    first AR keeps running;
(l) netload as the ART tester runs it: DCP, ARP, LLDP, RPC and malformed UDP
    floods at bounded rates from another station; the AR survives and the
    device answers DCP and RPC afterwards;
(m) Release; (n) Connect in legacy startup (RTClass 1, 0xC000-0xF7FF),
    PrmEnd, ApplicationReady, cyclic data, Release; (o) release/reconnect rounds;
(w) with --pcap: the recording (dumpcap on --iface) through tshark: no
    malformed frame and no expert warning from the device, no malformed frame
    but the netload's.
"""

import argparse
import atexit
import multiprocessing
import os
import queue
import random
import signal
import socket
import struct
import subprocess
import sys
import time
import uuid

from scapy.contrib.pnio import ProfinetIO
from scapy.contrib.pnio_dcp import ProfinetDCP
from scapy.contrib.pnio_rpc import IM1Block, IM2Block, IM3Block, IM4Block
from scapy.layers.inet import IP, UDP
from scapy.layers.l2 import ARP, Ether

import tia_lib as t
from pnargs import device_arguments
from steps import failures, report, run

NETLOAD_MAC = "02:4e:4c:00:00:01"
NETLOAD_IP = "192.168.0.99"
NOT_SERVED = "not served yet (issue 32.4)"


def expected_fail(step, text):
    # issue 32.4 is served now: what was an expected failure is a failure
    report(step, False, text.replace(NOT_SERVED, "issue 32.4 says the device serves it"))


def dcp_request(link, dst, fid, service, blocks, xid, delay=0):
    pdu = struct.pack(">BBIHH", service, 0, xid, delay, len(blocks)) + blocks
    frame = t.Ether(dst=dst, src=t.mac_text(link.mac), type=t.PNIO) / ProfinetIO(frameID=fid) / pdu
    link.send(frame)


def dcp_answers(link, xid, timeout, first=False):
    out, end = [], time.monotonic() + timeout
    while time.monotonic() < end:
        try:
            src, fid, p = link.dcp.get(timeout=max(0.01, end - time.monotonic()))
        except Exception:  # noqa: BLE001 - queue.Empty
            break
        if len(p) >= 10 and struct.unpack(">I", p[2:6])[0] == xid:
            out.append((t.mac_text(src), ProfinetDCP(p), p))
            if first:
                break
    return out


def dcp_fields(pkt):
    d = {}
    for b in pkt.dcp_blocks:
        n = b.__class__.__name__
        if n == "DCPNameOfStationBlock":
            d["name"] = b.name_of_station.decode(errors="replace")
        elif n == "DCPIPBlock":
            d["ip"] = b.ip
        elif n == "DCPDeviceIDBlock":
            d["vendor"], d["device"] = b.vendor_id, b.device_id
    return d


def dcp_set(link, mac, option, sub, value, xid):
    body = struct.pack(">BBHH", option, sub, len(value) + 2, 1) + value
    body += bytes(len(body) % 2)
    dcp_request(link, mac, 0xFEFD, 4, body, xid)
    got = dcp_answers(link, xid, 2.0, first=True)
    if not got:
        return None
    p = got[0][2]
    # the Control/Response block: option 5 suboption 4, (option, suboption, BlockError)
    at = 10
    while at + 4 <= len(p):
        o, s, n = p[at], p[at + 1], t.be16(p, at + 2)
        if (o, s) == (5, 4) and n >= 3:
            return p[at + 6]
        at += 4 + n + n % 2
    return None


def main():
    ap = device_arguments(argparse.ArgumentParser())
    ap.add_argument("--cyclic-seconds", type=float, default=10.0)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--netload-seconds", type=float, default=10.0)
    ap.add_argument("--control", help="serve's control FIFO (without it step j is skipped, e.g. QEMU)")
    ap.add_argument("--pcap", help="record the run with dumpcap on --iface and check it with tshark")
    a = ap.parse_args()
    mods = t.gsdml_modules(a.gsdml)
    rec = None
    if a.pcap:
        rec = subprocess.Popen(["dumpcap", "-q", "-i", a.iface, "-w", a.pcap], stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
        atexit.register(rec.terminate)  # also when a step raises past its runner
        time.sleep(1.0)
    t.tx_checksum_offload_off(a.iface)
    link = t.Link(a.iface)
    dev = a.device_mac.lower()
    print(f"scapy controller on {a.iface} ({t.mac_text(link.mac)}), device {dev}", flush=True)

    # (a) Identify All
    info = {}

    def identify_all():
        xid = random.getrandbits(32)
        dcp_request(link, "01:0e:cf:00:00:00", 0xFEFE, 5, struct.pack(">BBH", 0xFF, 0xFF, 0), xid, delay=1)
        found = {m: dcp_fields(p) for m, p, _ in dcp_answers(link, xid, 1.5)}
        d = found.get(dev)
        report("a", d is not None, f"Identify All: {dev} {'found: ' + str(d) if d else 'not among ' + str(list(found))}")
        if d:
            info.update(d)

    run("a", identify_all)

    def set_name_ip():
        e1 = dcp_set(link, dev, 2, 2, a.name.encode(), random.getrandbits(32))
        ip = b"".join(int(x).to_bytes(1, "big") for y in (a.ip, "255.255.255.0", "0.0.0.0") for x in y.split("."))
        e2 = dcp_set(link, dev, 1, 2, ip, random.getrandbits(32))
        report("b", e1 == 0 and e2 == 0, f"DCP Set name {a.name!r} (permanent): BlockError {e1}; IP {a.ip}: BlockError {e2}")

    run("b", set_name_ip)

    def identify_name():
        xid = random.getrandbits(32)
        name = a.name.encode()
        dcp_request(link, "01:0e:cf:00:00:00", 0xFEFE, 5, struct.pack(">BBH", 2, 2, len(name)) + name, xid, delay=1)
        got = [(m, dcp_fields(p)) for m, p, _ in dcp_answers(link, xid, 1.5)]
        ok = len(got) == 1 and got[0][0] == dev and got[0][1].get("ip") == a.ip
        report("c", ok, f"Identify by name {a.name!r}: {got}")
        if got:
            info.update(got[0][1])

    run("c", identify_name)
    vendor, device = info.get("vendor", 0xFEFE), info.get("device", 1)
    obj = uuid.UUID(f"dea00000-6c97-11d1-8271-0001{device:04x}{vendor:04x}")
    rpc = t.Rpc(a.ip)

    # (d) implicit reads
    def implicit():
        st, data = t.read_answer(*rpc.call(t.OP_READ_IMPLICIT, t.read_req(0xAFF0), object_uuid=obj, little=True))
        v = t.be16(data, 6) if len(data) >= 8 else None
        report("d", st == 0 and v == vendor, f"implicit read of I&M0 (little-endian NDR): status 0x{st:08X}, "
               f"{len(data)} bytes, vendor {v and hex(v)}, order {data[8:28].decode(errors='replace').strip()!r}")
        st, data = t.read_answer(*rpc.call(t.OP_READ_IMPLICIT, t.read_req(0xF000, 0, 1), object_uuid=obj))
        report("d", st == 0 and len(data) > 6 and t.be16(data, 0) == 0x0013,
               f"implicit read of RealIdentificationData 0xF000: status 0x{st:08X}, {len(data)} bytes, "
               f"block 0x{t.be16(data, 0) if len(data) >= 2 else 0:04X}")

    run("d", implicit)

    m1, m2 = mods[a.out_module], mods[a.in_module]
    subs = t.dap_submodules() + [
        t.Submodule(1, 1, m1[0], 1, inp=m1[1], out=m1[2]),
        t.Submodule(2, 1, m2[0], 1, inp=m2[1], out=m2[2]),
    ]

    def port_check(peer=True):
        """PDPortDataCheck of port 1 (0x8001): CheckPeers with the
        controller's port and name, CheckMAUType 100BASE-TX FD, CheckLinkState
        up; without `peer` no sub-block (the check withdrawn)."""
        subs = b""
        if peer:
            peer_port, peer_name = b"port-001", b"plc-1"
            body = bytes([1, len(peer_port)]) + peer_port + bytes([len(peer_name)]) + peer_name
            peers = t.block(0x020A, body + bytes(-(6 + len(body)) % 4))  # padded to 4 octets
            mau = t.block(0x020C, struct.pack(">H", 0x0010))
            link_state = t.block(0x021C, struct.pack(">H", 0x0001))
            subs = peers + mau + link_state
        return t.block(0x0200, bytes(2) + struct.pack(">HH", 0, 0x8001) + subs)

    def bring_up(ar, step, pdev=False):
        st = ar.connect()
        if st != 0:
            report(step, False, f"{ar.startup} Connect refused: 0x{st:08X}")
            return False
        lo, hi = (0x8000, 0xBBFF) if ar.startup == "advanced" else (0xC000, 0xF7FF)
        ok = all(f is not None and lo <= f <= hi for f in (ar.input_fid, ar.output_fid))
        report(step, ok, f"{ar.startup} startup Connect: input FrameID 0x{ar.input_fid or 0:04X}, output "
               f"FrameID 0x{ar.output_fid or 0:04X} (0x{lo:04X}-0x{hi:04X})")
        if pdev:
            pdev_write(ar, step)
        ar.start_cyclic()
        ar.start_acker()
        st, _ = ar.prm_end()
        got = ar.ready.wait(10)
        report(step, st == 0 and got, f"PrmEnd: 0x{st:08X}; ApplicationReady from the device "
               f"{'answered' if got else 'not within 10 s'}")
        return st == 0 and got

    def pdev_write(ar, step):
        """As TIA writes the PDev at start-up: PDInterfaceAdjust (0x8071,
        MultipleInterfaceMode NameOfDevice), PDPortDataCheck (0x802B:
        CheckPeers with the controller's port and name, CheckMAUType
        100BASE-TX FD, CheckLinkState up) and PDPortDataAdjust (0x802F:
        AdjustPeerToPeerBoundary 0) in one IODWriteMultiple."""
        ifadj = t.block(0x0250, bytes(2) + struct.pack(">I", 1))
        check = port_check()
        p2p = t.block(0x0224, bytes(2) + struct.pack(">IH", 0, 0) + bytes(2))
        adjust = t.block(0x0202, bytes(2) + struct.pack(">HH", 0, 0x8001) + p2p)
        st, outer, inner = ar.write_multiple([(0, 0x8000, 0x8071, ifadj), (0, 0x8001, 0x802B, check),
                                              (0, 0x8001, 0x802F, adjust)])
        desc = ", ".join(f"0x{i:04X}: 0x{s:08X}" for i, s in inner)
        by = dict(inner)
        ok = st == 0 and by.get(0x802F) == 0
        report(step, ok, f"PDev IODWriteMultiple: PNIO status 0x{st:08X}, outer 0x{outer or 0:08X}; {desc}")
        for idx in (0x8071, 0x802B):
            if by.get(idx) != 0:
                expected_fail(step, f"write of 0x{idx:04X} refused (0x{by.get(idx) or 0:08X}): {NOT_SERVED}")
        if any(s != 0 for _, s in inner) and (outer or 0) == 0:
            expected_fail(step, f"IODWriteMultiple's outer status OK while a sub-write failed: {NOT_SERVED}")

    ar = t.AR(link, rpc, dev, obj, subs, startup="advanced", ack_delay=0.5)
    up = run("e", lambda: bring_up(ar, "e", pdev=True))
    if not up:
        print("no AR: the remaining steps are not run", flush=True)
        return finish(a, rec, link, rpc, dev)

    def cyclic():
        s0 = dict(ar.stats)
        ar.max_gap = 0.0
        time.sleep(a.cyclic_seconds)
        s = {k: ar.stats[k] - s0[k] for k in ar.stats}
        ok = s["received"] > 0 and s["bad_iops"] == 0 and s["bad_iocs"] == 0 and s["bad_status"] == 0 and ar.abort is None
        report("f", ok, f"{a.cyclic_seconds:g} s of cyclic data at {32 * ar.reduction * 31.25e-3:g} ms: sent {s['sent']} "
               f"received {s['received']}, bad DataStatus {s['bad_status']} IOPS {s['bad_iops']} IOCS {s['bad_iocs']}, "
               f"longest gap {1000 * ar.max_gap:.1f} ms")

    run("f", cyclic)

    def records():
        for index, sub, what, block_type in [
            (0xF000, 1, "RealIdentificationData", 0x0013), (0xF840, 1, "I&M0FilterData", 0x0030),
            (0xF841, 1, "PDRealData", None), (0x8072, 0x8001, "PDPortStatistic", 0x0251),
            (0x802B, 0x8001, "PDPortDataCheck", 0x0200), (0x802A, 0x8001, "PDPortDataReal", 0x020F),
            (0x8080, 0x8000, "PDInterfaceDataReal", 0x0240),
            # the diagnosis step e's topology check raised on port 1 (no LLDP
            # neighbour), as TIA's online diagnostics reads it
            (0x800A, 0x8001, "the diagnosis of port 1", 0x0010), (0xE00C, 1, "the AR's diagnosis", 0x0010)]:
            st, data = ar.read(index, 0, sub)
            bt = t.be16(data, 0) if len(data) >= 2 else None
            text = f"read of {what} 0x{index:04X} (subslot 0x{sub:04X}): status 0x{st:08X}, {len(data)} bytes, first block {bt and hex(bt)}"
            ok = st == 0 and (block_type is None or bt == block_type or (index == 0x802B and len(data) == 0))
            if index == 0x802B and st == 0 and len(data) == 0:
                expected_fail("g", text + f": the check written in step e is not read back: {NOT_SERVED}")
            elif not ok and index in (0xF841, 0x8072, 0x802B):
                expected_fail("g", f"{text}: {NOT_SERVED}")
            else:
                report("g", ok, text)

    run("g", records)

    def im():
        blocks = {0xAFF1: bytes(IM1Block(IMTagFunction=b"axis 1".ljust(32), IMTagLocation=b"cabinet 3".ljust(22))),
                  0xAFF2: bytes(IM2Block(IMDate=b"2026-12-05 18:00")),
                  0xAFF3: bytes(IM3Block(IMDescriptor=b"scapy tia.py".ljust(54))),
                  0xAFF4: bytes(IM4Block(IMSignature=bytes(range(54))))}
        for index, b in blocks.items():
            st, ws = ar.write(index, b)
            st2, back = ar.read(index)
            report("h", st == 0 and st2 == 0 and back == b,
                   f"I&M{index - 0xAFF0} written (0x{st:08X}) and read back (0x{st2:08X}): {'same' if back == b else back.hex()}")
        st, data = ar.read(0xAFF0)
        report("h", st == 0 and len(data) >= 60 and t.be16(data, 0) == 0x0020, f"I&M0 in the AR: 0x{st:08X}, {len(data)} bytes")

    run("h", im)

    def big_records():
        for n, want in [(4068, 0xDF80B000), (4069, 0xDF80B100)]:
            st, res = ar.write(0x7FF0, bytes(k % 251 for k in range(n)), 1, 1, frag=1024)
            report("i", st & 0xFFFFFF00 == want and res is not None and res & 0xFFFFFF00 == want,
                   f"{n}-byte record in 1,024-byte RPC fragments: PNIO status 0x{st:08X}, IODWriteRes 0x{res or 0:08X}")

    run("i", big_records)

    def burst():
        before = len(ar.alarms)
        for ev in (44, 45, 46):
            for cmd in (f"fault A {ev} 1", "reset A"):
                with open(a.control, "w") as f:
                    f.write(cmd + "\n")
                time.sleep(0.25)
        end = time.monotonic() + 10
        while time.monotonic() < end and not (ar.alarms[before:] and ar.alarms[-1][:3] == (0x000C, 0, 1) and ar.ack_q.empty()):
            time.sleep(0.1)
        # the drive's (slot 0, subslot 1); a port's diagnosis (0x802B) is not this step's
        got = [x for x in ar.alarms[before:] if (x[1], x[2]) == (0, 1)]
        types = [f"0x{x[0]:04X}@{x[1]}/{x[2]:#x}#{x[3]}{'' if x[4] else ' (ACK not confirmed)'}" for x in got]
        # the device may fold a change into an alarm still queued: every one
        # acknowledged, numbered in sequence, the last one "disappears"
        seqs = [x[3] for x in got]
        # (with the port's topology diagnosis sharing the low-priority alarm
        # channel, as few as two remain: the first "appears", the last "disappears")
        ok = (len(got) >= 2 and got[0][0] == 0x0001 and all(x[4] for x in got) and got[-1][0] == 0x000C
              and all(b > a for a, b in zip(seqs, seqs[1:])) and ar.abort is None)
        report("j", ok, f"alarm burst: {len(got)} alarms acknowledged 500 ms late each: {', '.join(types)}; "
               f"AR {'aborted ' + ar.abort if ar.abort else 'up'}")

    def topology_burst():
        """A burst of port alarms that needs no simulator: the topology check
        of step e (a peer this controller does not play: port 1 carries the
        diagnosis "no peer detected") withdrawn and set again, five writes
        400 ms apart, each alarm acknowledged 500 ms late."""
        before = len(ar.alarms)
        sts = []
        for peer in (False, True, False, True, False):
            st, _ = ar.write(0x802B, port_check(peer), 0, 0x8001)
            sts.append(st)
            time.sleep(0.4)
        end = time.monotonic() + 10
        while time.monotonic() < end and not (ar.alarms[before:] and ar.alarms[-1][:3] == (0x000C, 0, 0x8001)
                                              and ar.ack_q.empty()):
            time.sleep(0.1)
        got = [x for x in ar.alarms[before:] if (x[1], x[2]) == (0, 0x8001)]
        types = [f"0x{x[0]:04X}#{x[3]}{'' if x[4] else ' (ACK not confirmed)'}" for x in got]
        seqs = [x[3] for x in got]
        # appears (0x0001) and disappears (0x000C) alternate; changes still
        # queued may fold, but the first is the step-e diagnosis disappearing
        # and the last one too
        ok = (all(s == 0 for s in sts) and len(got) >= 2 and all(x[4] for x in got) and got[0][0] == 0x000C
              and got[-1][0] == 0x000C and any(x[0] == 0x0001 for x in got)
              and all(b > a for a, b in zip(seqs, seqs[1:])) and ar.abort is None)
        report("j", ok, f"topology alarm burst on port 1 (0x802B withdrawn and set, 5 writes: "
               f"{', '.join(f'0x{s:08X}' for s in sts)}): {len(got)} alarms acknowledged 500 ms late each: "
               f"{', '.join(types)}; AR {'aborted ' + ar.abort if ar.abort else 'up'}")

    if a.control:
        run("j", burst)
    else:
        print("step j: skipped: the drive-fault burst, no --control (serve's control FIFO raises the drive's "
              "faults; a firmware image has no such channel)", flush=True)
    run("j", topology_burst)

    def second():
        rpc2 = t.Rpc(a.ip, port=0)
        try:
            other = t.AR(link, rpc2, dev, obj, subs, name="plc-2", initiator_mac=bytes.fromhex("020000000abc"),
                         alarm_ref=5)
            before = ar.stats["received"]
            saved = (link.alarm_handler, link.rt_handler, rpc.on_control)
            st = other.connect()
            link.alarm_handler, link.rt_handler, rpc.on_control = saved
            time.sleep(2)
            ok = st == 0xDB814004 and ar.stats["received"] > before and ar.abort is None
            report("k", ok, f"a second controller's Connect: 0x{st:08X} (0xDB814004: out of AR resources); "
                   f"the first AR received {ar.stats['received'] - before} frames since")
        finally:
            rpc2.close()

    run("k", second)

    def netload():
        nl = t.mac_bytes(NETLOAD_MAC)
        s0 = dict(ar.stats)
        ar.max_gap = 0.0
        dip = a.ip
        rates = {"dcp": 50, "arp": 500, "lldp": 50, "rpc": 100, "udp": 300}
        frames = {k: 0 for k in rates}
        rnd = random.Random(32)

        def make(kind):
            if kind == "dcp":
                if rnd.random() < 0.5:
                    pdu = struct.pack(">BBIHH", 5, 0, rnd.getrandbits(32), 1, 4) + b"\xff\xff\x00\x00"
                else:  # malformed: lengths that overrun, unknown options
                    pdu = struct.pack(">BBIHH", rnd.choice([3, 4, 5, 9]), 0, rnd.getrandbits(32), 0, 200) + os.urandom(rnd.randint(0, 30))
                return Ether(dst=rnd.choice(["01:0e:cf:00:00:00", a.device_mac]), src=NETLOAD_MAC, type=t.PNIO) / (
                    struct.pack(">H", rnd.choice([0xFEFE, 0xFEFD])) + pdu)
            if kind == "arp":
                return Ether(dst="ff:ff:ff:ff:ff:ff", src=NETLOAD_MAC) / ARP(op=1, hwsrc=NETLOAD_MAC, psrc=NETLOAD_IP, pdst=dip)
            if kind == "lldp":
                body = os.urandom(rnd.randint(0, 40)) if rnd.random() < 0.5 else bytes.fromhex(
                    "020704024e4c0000010409057065726d2d3106020014") + bytes(2)
                return Ether(dst="01:80:c2:00:00:0e", src=NETLOAD_MAC, type=0x88CC) / body
            if kind == "rpc":
                h = bytes(t.DceRpc4(ptype=rnd.choice([0, 0, 1, 4, 10]), flags1=0x20, object=obj, if_id=t.DEVICE_IF,
                                    act_id=uuid.uuid4(), seqnum=rnd.getrandbits(16), opnum=rnd.randint(0, 9)) / os.urandom(rnd.randint(0, 64)))
                if rnd.random() < 0.3:
                    h = h[: rnd.randint(1, 79)]
                return Ether(dst=a.device_mac, src=NETLOAD_MAC) / IP(src=NETLOAD_IP, dst=dip) / UDP(sport=rnd.randint(1024, 65535), dport=t.RPC_PORT) / h
            u = UDP(sport=rnd.randint(1024, 65535), dport=rnd.choice([t.RPC_PORT, 161, 53, 7, rnd.randint(1, 65535)]))
            p = Ether(dst=a.device_mac, src=NETLOAD_MAC) / IP(src=NETLOAD_IP, dst=dip) / u / os.urandom(rnd.randint(0, 100))
            raw = bytearray(bytes(p))
            if rnd.random() < 0.3:  # a broken UDP length or checksum
                raw[38:40] = rnd.getrandbits(16).to_bytes(2, "big")
            return bytes(raw)

        # the load comes from a process of its own, niced (fork: it has
        # `make` and the frames' seed): built and sent in the controller's
        # own process, scapy's frame building held the interpreter long
        # enough, on a loaded 2-core CI machine, for the AR's cyclic thread
        # to miss the device's 96 ms watchdog now and then; the device
        # rightly aborted, and the test measured the harness. A pool of 600
        # frames built first, sent in turn at the rates.
        def sender(out):
            os.nice(10)
            kinds = rnd.choices(list(rates), weights=list(rates.values()), k=600)
            pool = [(kind, bytes(make(kind))) for kind in kinds]
            sock = socket.socket(socket.AF_PACKET, socket.SOCK_RAW)
            sock.bind((a.iface, 0))
            counts = {k: 0 for k in rates}
            start = time.monotonic()
            n = 0
            total = sum(rates.values())
            while time.monotonic() - start < a.netload_seconds:
                kind, frame = pool[n % len(pool)]
                sock.send(frame)
                counts[kind] += 1
                n += 1
                d = start + n / total - time.monotonic()
                if d > 0:
                    time.sleep(d)
            sock.close()
            out.put((n, counts))

        ctx = multiprocessing.get_context("fork")
        out = ctx.Queue()
        load = ctx.Process(target=sender, args=(out,), daemon=True)
        load.start()
        try:
            sent, frames = out.get(timeout=a.netload_seconds + 60)
        except queue.Empty:
            sent = 0
        load.join(5)
        time.sleep(1.0)
        s = {k: ar.stats[k] - s0[k] for k in ar.stats}
        rate = sent / a.netload_seconds
        ok = ar.abort is None and s["received"] > 0 and s["bad_status"] == 0 and s["bad_iops"] == 0 and s["bad_iocs"] == 0
        report("l", ok, f"netload {a.netload_seconds:g} s, {sent} frames ({rate:.0f}/s: " + ", ".join(f"{k} {v}" for k, v in frames.items())
               + f"): AR {'aborted ' + ar.abort if ar.abort else 'up'}, input frames {s['received']}, bad {s['bad_status'] + s['bad_iops'] + s['bad_iocs']}, "
               f"longest gap {1000 * ar.max_gap:.1f} ms")
        st, data = ar.read(0xAFF0)
        xid = random.getrandbits(32)
        name = a.name.encode()
        dcp_request(link, "01:0e:cf:00:00:00", 0xFEFE, 5, struct.pack(">BBH", 2, 2, len(name)) + name, xid, delay=1)
        found = dcp_answers(link, xid, 1.5)
        report("l", st == 0 and len(found) == 1, f"after the netload: I&M0 read 0x{st:08X}, Identify by name answered {len(found)}x")

    run("l", netload)

    def release():
        st, blocks = ar.release()
        report("m", st == 0 and any(b == 0x8114 for b, _ in blocks), f"Release: 0x{st:08X}")

    run("m", release)
    ar.ack_q.put((None, None, None))

    def legacy():
        lar = t.AR(link, rpc, dev, obj, subs, startup="legacy")
        if bring_up(lar, "n"):
            time.sleep(2)
            s = lar.stats
            report("n", s["received"] > 0 and s["bad_iops"] + s["bad_iocs"] + s["bad_status"] == 0,
                   f"legacy startup cyclic data: received {s['received']}, bad {s['bad_iops'] + s['bad_iocs'] + s['bad_status']}")
            st, _ = lar.release()
            report("n", st == 0, f"Release: 0x{st:08X}")
        lar.ack_q.put((None, None, None))

    run("n", legacy)

    def rounds():
        for k in range(a.rounds):
            r = t.AR(link, rpc, dev, obj, subs, startup="advanced")
            ok = bring_up(r, "o")
            time.sleep(0.5)
            st, _ = r.release()
            r.ack_q.put((None, None, None))
            report("o", ok and st == 0 and r.stats["received"] > 0,
                   f"round {k + 1}: connected, {r.stats['received']} input frames, Release 0x{st:08X}")

    run("o", rounds)
    return finish(a, rec, link, rpc, dev)


def finish(a, rec, link, rpc, dev):
    link.close()
    rpc.close()
    if rec is not None:
        time.sleep(0.5)
        rec.send_signal(signal.SIGINT)
        rec.wait(10)
        run("w", lambda: check_pcap(a.pcap, dev))
    if failures:
        print(f"failed steps: {' '.join(sorted(set(failures)))}", flush=True)
        return 1
    print("all steps passed", flush=True)
    return 0


def tshark(pcap, *args):
    return subprocess.run(["tshark", "-r", pcap, *args], capture_output=True, text=True, check=True).stdout


def check_pcap(pcap, dev):
    bad_dev = tshark(pcap, "-Y", f"eth.src == {dev} && (_ws.malformed || _ws.expert.severity >= warning)")
    # known: a refused request is answered with ArgsLength 0 and no header (issue 32)
    known = [x for x in bad_dev.splitlines() if "ArgsLength invalid" in x]
    other = [x for x in bad_dev.splitlines() if x.strip() and "ArgsLength invalid" not in x]
    report("w", not other, f"tshark: frames of the device flagged malformed or warning: {len(other)}"
           + "".join("\n  " + x for x in other[:20]))
    if known:
        expected_fail("w", f"{len(known)} answers to garbage with ArgsLength 0 and no header, malformed for "
                      f"Wireshark, e.g. {known[0].strip()}: not fixed yet (issue 32)")
    bad = tshark(pcap, "-Y", f"_ws.malformed && eth.src != {NETLOAD_MAC} && eth.src != {dev}")
    report("w", not bad.strip(), f"tshark: malformed frames of the controller: {len(bad.splitlines())}"
           + "".join("\n  " + x for x in bad.splitlines()[:20]))
    protos = tshark(pcap, "-T", "fields", "-e", "frame.protocols").splitlines()
    hist = {}
    for p in protos:
        hist[p] = hist.get(p, 0) + 1
    print(f"tshark: {len(protos)} frames in {pcap}:", flush=True)
    for p, n in sorted(hist.items(), key=lambda x: -x[1])[:15]:
        print(f"  {n:>7} {p}", flush=True)


if __name__ == "__main__":
    sys.exit(main())
