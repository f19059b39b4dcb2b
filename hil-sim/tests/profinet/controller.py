"""profinet-py (0.6.6) as the IO controller of `hil-sim serve --fieldbus profinet`.

Runs in the controller's network namespace (the device is in another one:
both bind UDP 34964) and goes step by step, one line per result:

    step X: ok: ...              the step did what it should
    step X: FAIL: ...            it did not (the script exits 1 at the end)
    step X: expected-fail: ...   a known problem of the device (see the text)

(a) DCP Identify All finds the device, unnamed, by its MAC, and as many
    drives of ours (vendor ID) on the line as --drives says;
(b) DCP Set name of station (permanent) and IP suite;
(c) DCP Identify by name finds it again with that IP;
(d) RPC read of I&M0 (device-access AR): vendor ID and order number;
(e) Connect (IOCARSingle) with the GSDML's DAP, OUT module in slot 1, IN
    module in slot 2, PrmEnd, the device's ApplicationReady confirmed;
(f) Release (answered);
(g) Connect with a wrong module ident: a ModuleDiff block, then Release;
(h) DCP Identify by name again, Connect, cyclic data at the shortest cycle
    profinet-py runs (1 ms) for --cyclic-seconds through the PROFIdrive
    profile: receive telegram 1 (speed control) of the Example Function
    block, CW1 0x0400 -> 0x0406 -> 0x0407 -> 0x040F answered by ZSW1's
    states, 100 rpm through PNU 1010 and CW1 bits 4-6 seen in the vl
    demand 6043h (a PKW read of a CANopen object) and, with --motor, in PNU
    1101, a PKW read of PNU 964.0 after the 0x00 toggle, the set-point disabled (bit 6) and the drive
    switched off again; prints the figure "DCP identify to first valid
    cyclic data";
(i) a drive fault (event --fault-event, cause --fault-cause on axis A,
    raised through serve's control channel --control) arrives as a
    diagnosis alarm at the drive (slot 0, subslot 1) with ChannelErrorType
    0x1000 + event and ExtChannelErrorType 0x1000 + cause; profinet-py
    acknowledges it; after the fault reset (CW1 bit 7) the diagnosis
    disappears with a "Diagnosis disappears" alarm (which the device sends
    only once the first one was acknowledged);
    (skipped without --control: a device without a control channel, such
    as the firmware image in QEMU, `scripts/cross qemu-net`);
(j) the controller stops sending output frames: the device aborts the AR
    (RTA ERR PDU) and stops its input frames;
(k) Connect in advanced startup as an S7-1500 sends it (ARProperties
    StartupMode = 1, IOCRs of RTClass 2 with FrameIDs 0x8000-0xBBFF), PrmEnd,
    ApplicationReady, Release: the device assigns the output CR's FrameID in
    that range and answers with an ARServerBlockRes naming itself;
(l) in that AR, a write of a 4,068-byte record (MaxSupportedRecordSize)
    to an index the drive does not have, sent in DCE/RPC fragments of 1,024
    bytes (profinet-py sends a request as one datagram, which IP would have
    to fragment; the fragmenting sender is ours): the device reassembles it
    and answers the record's header with "invalid index" (DF 80 B0), not an
    RPC fault; a 4,069-byte one gets "write length error" (DF 80 B1);
(m) in that AR, the PDev records TIA uses: PDPortDataCheck written to port 1
    and read back as written, PDRealData with a MultipleBlockHeader for the
    interface and each port, PDPortStatistic of the interface counting, and
    an IODWriteMultiple with one refused sub-write (CheckLinkState "down")
    answered with its error ("invalid parameter", DF 80 B8) as the outer
    status and OK for the good one.

Steps (a)-(g) use legacy startup (profinet-py's own Connect: RTClass 1,
FrameIDs 0xC000-0xF7FF); with --startup advanced, step (h) connects in
advanced startup (profinet-py 0.6.6 cannot: its AR and IOCR block builders
are wrapped to set StartupMode and RTClass 2 and to propose the input CR's
FrameID 0x8000 + reference).
"""

import argparse
import dataclasses
import logging
import sys
import threading
import time

import profinet
from profinet import dcp, rpc
from profinet.alarms import DiagnosisItem
from profinet.blocks import parse_module_diff_block
from profinet.device import ProfinetDevice
from profinet.gsdml import load_gsdml
from profinet.rpc import IOCRSetup, RPCCon, get_station_info
from profinet.dcp import (
    DCP_IDENTIFY_REQUEST_FRAME_ID,
    DCP_MULTICAST_MAC,
    PROFINET_ETHERTYPE,
    EthernetHeader,
    PNDCPBlock,
    PNDCPBlockRequest,
    PNDCPHeader,
)
from profinet.exceptions import DCPDeviceNotFoundError
from profinet.util import ethernet_socket, get_mac, mac2s, s2mac

from pnargs import device_arguments
from pnctl import Records, cyclic_setup, quiet_collector, real_time, tx_checksum_offload_off
from steps import failures, report, run, verdict


def expected_fail(step, text):
    print(f"step {step}: expected-fail: {text}", flush=True)


def release(con):
    """Release, waiting for the device's answer (profinet-py's own
    disconnect() sends it and does not wait)."""
    block = rpc.PNBlockHeader(0x0114, 28, 0x01, 0x00)
    req = rpc.PNIODReleaseBlock(
        block_header=bytes(block),
        padding1=0,
        ar_uuid=con.ar_uuid,
        session_key=con.session_key,
        padding2=0,
        control_command=0x0004,
        control_block_properties=0,
        payload=b"",
    )
    pkt = con._create_rpc(rpc.PNRPCHeader.RELEASE, bytes(con._create_nrd(bytes(req))))
    resp = con._send_receive(pkt)
    con.live = None
    nrd = rpc.PNNRDData(resp.payload)
    body = bytes(nrd.payload)
    block_type = int.from_bytes(body[0:2], "big") if len(body) >= 2 else 0
    return nrd.args_maximum_status, block_type


class AdvancedStartup:
    """profinet-py's Connect in advanced startup while active: its ARBlockReq
    gets StartupMode (ARProperties bit 30), its IOCRBlockReqs RTClass 2 and,
    for the input CR, FrameID 0x8000 + reference instead of 0xC000 +
    reference (the output CR stays 0xFFFF: the device assigns it)."""

    def __enter__(self):
        self.ar, self.iocr = rpc.PNARBlockRequest, rpc.PNIOCRBlockReqHeader
        ar, iocr = self.ar, self.iocr

        # subclasses, so that the builders' class attributes (fmt_size, …) stay
        class ar_block(ar):
            def __new__(cls, *args, **kw):
                if len(args) > 6:  # building, not parsing
                    args = list(args)
                    args[6] |= 1 << 30  # ARProperties: StartupMode advanced
                return ar.__new__(cls, *args, **kw)

        class iocr_block(iocr):
            def __new__(cls, *args, **kw):
                if "iocr_properties" in kw:
                    kw["iocr_properties"] = (kw["iocr_properties"] & ~0xF) | 2  # RTClass 2
                    if kw["frame_id"] != 0xFFFF:
                        kw["frame_id"] = 0x8000 + kw["iocr_reference"]
                return iocr.__new__(cls, *args, **kw)

        rpc.PNARBlockRequest, rpc.PNIOCRBlockReqHeader = ar_block, iocr_block
        return self

    def __exit__(self, *exc):
        rpc.PNARBlockRequest, rpc.PNIOCRBlockReqHeader = self.ar, self.iocr
        return False


def fragmented_write(con, slot, subslot, index, data, frag=1024, timeout=5.0):
    """An IODWrite in DCE/RPC fragments of `frag` body bytes over profinet-py's
    AR and socket; returns (NDR PNIO status, the IODWriteRes's status)."""
    block = rpc.PNBlockHeader(0x0008, 60, 0x01, 0x00)
    iod = rpc.PNIODHeader(
        bytes(block), 0, con.ar_uuid, 0, slot, subslot, 0, index, len(data), bytes(16), bytes(8),
        payload=bytes(data),
    )
    whole = bytes(con._create_rpc(rpc.PNRPCHeader.WRITE, bytes(con._create_nrd(bytes(iod)))))
    head, body = whole[:80], whole[80:]  # big-endian drep (profinet-py's)
    seq = head[64:68]
    chunks = [body[k : k + frag] for k in range(0, len(body), frag)]
    for n, c in enumerate(chunks):
        h = bytearray(head)
        h[2] = 0x20 | 0x04 | (0x02 if n == len(chunks) - 1 else 0)  # idempotent, frag, last
        h[74:76] = len(c).to_bytes(2, "big")
        h[76:78] = n.to_bytes(2, "big")
        con._socket.sendto(bytes(h) + c, con.peer)
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        con._socket.settimeout(max(0.01, end - time.monotonic()))
        try:
            d = con._socket.recvfrom(65535)[0]
        except TimeoutError:
            break
        if len(d) < 80 or d[64:68] != seq:
            continue
        if d[1] == 3:  # fault
            raise RuntimeError(f"RPC fault 0x{int.from_bytes(d[80:84], 'big'):08X}")
        if d[1] == 2:  # response
            b = d[80:]
            res = b[20:]
            return int.from_bytes(b[0:4], "big"), int.from_bytes(res[44:48], "big") if len(res) >= 48 else None
    raise RuntimeError("no answer to the fragmented write")


def blocks_of(payload):
    """The PNIO blocks of an NRD payload: [(type, bytes with header)]."""
    out = []
    off = 0
    while off + 4 <= len(payload):
        t = int.from_bytes(payload[off : off + 2], "big")
        n = int.from_bytes(payload[off + 2 : off + 4], "big")
        out.append((t, payload[off : off + 4 + n]))
        off += 4 + n
    return out


def keep_answers(con):
    """The list `con` (an RPCCon) appends each RPC answer it receives to, from
    now on: the raw answers (profinet-py parses only part of them)."""
    answers = []
    plain = con._send_receive

    def keep(pkt):
        r = plain(pkt)
        answers.append(r)
        return r

    con._send_receive = keep
    return answers


def main():
    ap = device_arguments(argparse.ArgumentParser())
    ap.add_argument("--vendor-id", type=lambda s: int(s, 0), required=True)
    ap.add_argument("--order", required=True)
    ap.add_argument("--mask", default="255.255.255.0")
    ap.add_argument("--cyclic-seconds", type=float, default=12.0)
    ap.add_argument(
        "--control",
        help="serve's control FIFO; without it step (i) is skipped (a device without "
        "fault injection, e.g. the firmware in QEMU)",
    )
    ap.add_argument("--drives", type=int, default=1, help="drives serve runs on the line")
    ap.add_argument(
        "--motor",
        action="store_true",
        help="the device has motors (hil-sim serve): step (h) also checks the actual velocity",
    )
    ap.add_argument("--fault-event", type=int, default=44)
    ap.add_argument("--fault-cause", type=int, default=1)
    ap.add_argument(
        "--startup",
        choices=["legacy", "advanced"],
        default="legacy",
        help="startup mode of step (h)'s AR (steps (a)-(g) use legacy startup)",
    )
    a = ap.parse_args()

    records = Records()
    logging.getLogger("profinet").addHandler(records)
    logging.getLogger("profinet").setLevel(logging.DEBUG)
    print(f"profinet-py {profinet.__version__} on {a.iface}", flush=True)

    iface = a.iface
    tx_checksum_offload_off(iface)
    print(f"{iface}: tx checksum offload off (UDP checksums computed by the kernel)", flush=True)
    src = get_mac(iface)
    want_mac = a.device_mac.lower()
    sock = ethernet_socket(iface)

    # (a) Identify All with profinet-py's response delay factor 0x80 (answers
    # spread over 1.28 s: the device answers after its MAC's share of it).
    def identify_all(delay):
        xid = dcp.send_discover(sock, src, response_delay=delay)
        found = dcp.read_response(sock, src, timeout_sec=3, expected_xid=xid, strict_xid=True)
        return [dcp.DCPDeviceDescription(mac, blocks) for mac, blocks in found.items()]

    def step_a():
        found = identify_all(0x0080)
        d = next((x for x in found if x.mac == want_mac), None)
        if d is None:
            report("a", False, f"Identify All: {want_mac} not among {[x.mac for x in found]}")
            return
        ok = d.name == "" and d.ip == "0.0.0.0" and d.vendor_id == a.vendor_id
        report(
            "a",
            ok,
            f"Identify All: {d.mac} name {d.name!r} ip {d.ip} vendor 0x{d.vendor_id:04X} "
            f"device 0x{d.device_id:04X} type {d.device_type!r} roles {d.device_roles}",
        )
        ours = sorted(x.mac for x in found if x.vendor_id == a.vendor_id)
        report(
            "a",
            len(ours) == a.drives and len(set(ours)) == len(ours),
            f"Identify All: {len(ours)} drive(s) of ours on the line ({', '.join(ours)}), {a.drives} expected",
        )

    run("a", step_a)

    # (b) Set name (permanent) and IP
    def set_name_and_ip():
        ok_name = dcp.set_param(sock, src, want_mac, "name", a.name, permanent=True)
        ok_ip = dcp.set_ip(sock, src, want_mac, a.ip, a.mask, "0.0.0.0", permanent=True)
        report(
            "b",
            ok_name and ok_ip,
            f"DCP Set name {a.name!r} (permanent): {ok_name}; IP {a.ip}/{a.mask} (permanent): {ok_ip}",
        )

    run("b", set_name_and_ip)

    # (c) Identify by name: profinet-py's get_station_info (delay 0x80)
    def identify_by_name():
        try:
            d = get_station_info(sock, src, a.name, timeout_sec=3, strict_xid=True)
        except DCPDeviceNotFoundError as e:
            report("c", False, f"get_station_info({a.name!r}): {e}")
            return None
        ok = d.mac == want_mac and d.ip == a.ip and d.netmask == a.mask and d.name == a.name
        report("c", ok, f"Identify by name {a.name!r}: {d.mac} ip {d.ip} mask {d.netmask} name {d.name!r}")
        return d

    info = run("c", identify_by_name)
    sock.close()
    if info is None:
        print("no device to connect to: the RPC steps are not run", flush=True)
        return 1

    # (d) I&M0 through a device-access AR
    def im0():
        dev = ProfinetDevice(info, iface, src, timeout=5.0)
        try:
            m = dev.read_im0()
        finally:
            dev.close()
        order = m.order_id.strip() if isinstance(m.order_id, str) else m.order_id.decode().strip()
        serial = m.im_serial_number
        serial = serial.strip() if isinstance(serial, str) else serial.decode().strip()
        ok = m.vendor_id == a.vendor_id and order == a.order
        report("d", ok, f"I&M0: vendor 0x{m.vendor_id:04X} order {order!r} serial {serial!r}")

    run("d", im0)

    gsd = load_gsdml(a.gsdml)
    slots = gsd.build_io_slots(slot_assignment={1: a.out_module, 2: a.in_module})
    for s in slots:
        print(
            f"  expected: slot {s.slot} subslot 0x{s.subslot:04X} module 0x{s.module_ident:08X} "
            f"submodule 0x{s.submodule_ident:08X} in {s.input_length} out {s.output_length}",
            flush=True,
        )

    # (e) Connect, PrmEnd, ApplicationReady; (f) Release
    def connect_ready_release():
        setup = IOCRSetup(slots=slots)
        con = RPCCon(info, timeout=5.0)
        try:
            res = con.connect(src, iocr_setup=setup)
            con.prm_end()
            con.application_ready(timeout=10.0)
            report(
                "e",
                True,
                f"Connect: input FrameID 0x{res.input_frame_id:04X}, output FrameID "
                f"0x{res.output_frame_id:04X}, alarm ref {res.device_alarm_ref}; PrmEnd; "
                f"ApplicationReady confirmed",
            )
            status, block = release(con)
            report("f", status == 0 and block == 0x8114, f"Release: status 0x{status:08X} block 0x{block:04X}")
        finally:
            con.close()

    run("e", connect_ready_release)

    # (g) a wrong module ident: ModuleDiff, then Release
    def module_diff():
        wrong = [
            dataclasses.replace(s, module_ident=s.module_ident ^ 0x0000_7F00) if s.slot == 1 else s
            for s in slots
        ]
        con = RPCCon(info, timeout=5.0)
        answers = keep_answers(con)
        try:
            con.connect(src, iocr_setup=IOCRSetup(slots=wrong))
            nrd = rpc.PNNRDData(answers[-1].payload)
            found = [b for t, b in blocks_of(bytes(nrd.payload)) if t == 0x8104]
            if not found:
                report("g", False, f"Connect with module 0x{wrong[-2].module_ident:08X}: no ModuleDiff block")
            else:
                diff = parse_module_diff_block(found[0])
                mism = diff.get_mismatches()
                ok = any(slot == 1 for slot, _, _ in mism) and not any(slot == 2 for slot, _, _ in mism)
                report("g", ok, f"Connect with a wrong module ident in slot 1: ModuleDiff {mism}")
            status, block = release(con)
            print(f"  release after the ModuleDiff: status 0x{status:08X} block 0x{block:04X}", flush=True)
            if status != 0:
                report("g", False, f"Release after the ModuleDiff refused: 0x{status:08X}")
        finally:
            con.close()

    run("g", module_diff)

    def control(command):
        # serve reads its FIFO without blocking; the open waits for it
        with open(a.control, "w") as f:
            f.write(command + "\n")

    alarms = []
    alarm_seen = threading.Event()

    def on_alarm(n):
        alarms.append(n)
        alarm_seen.set()

    def wait_alarm(since, timeout):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if len(alarms) > since:
                return alarms[since]
            alarm_seen.wait(0.01)
            alarm_seen.clear()
        return None

    def diagnosis_items(n):
        return [i for i in n.items if isinstance(i, DiagnosisItem)]

    def describe(n):
        items = ", ".join(
            f"ChannelErrorType 0x{i.channel_error_type:04X} ExtChannelErrorType 0x{i.ext_channel_error_type:04X}"
            for i in diagnosis_items(n)
        )
        return (
            f"{n.alarm_type_name} (0x{n.alarm_type:04X}) at {n.location} seq {n.alarm_sequence_number}"
            f"{': ' + items if items else ''}"
        )

    # (h) cyclic data at 1 ms through the profile's telegrams; (i) a drive
    # fault as a diagnosis alarm; (j) the controller goes silent
    def cyclic():
        # 1 ms, profinet-py's shortest cycle (pnctl.cyclic_setup). Python's
        # full collections held the sender for up to 110 ms and ended the AR
        # (pnctl.quiet_collector); as in fb.py, the watchdog and data hold are
        # 100 cycles and the threads run at a real-time priority below serve's.
        quiet_collector()
        print(f"  controller threads: {real_time()}", flush=True)
        setup = cyclic_setup(slots, watchdog=100)
        out_slot = next(s for s in slots if s.output_length > 0)
        in_slot = next(s for s in slots if s.input_length > 0)
        n = min(out_slot.output_length, in_slot.input_length)
        # the figure: from the DCP identify by name to the first input
        # frame with valid data (IOPS good) through profinet-py
        sock2 = ethernet_socket(iface)
        t_identify = time.monotonic()
        try:
            found = get_station_info(sock2, src, a.name, timeout_sec=3, strict_xid=True)
        finally:
            sock2.close()
        t_found = time.monotonic()
        dev = ProfinetDevice(found, iface, src, timeout=5.0)
        dev.on_alarm(on_alarm)
        ctl = None
        try:
            if a.startup == "advanced":
                with AdvancedStartup():
                    ctl = dev.start_cyclic(setup)
            else:
                ctl = dev.start_cyclic(setup)
            t_connected = time.monotonic()
            print(
                f"  {a.startup} startup: input FrameID 0x{ctl.input_iocr.frame_id:04X}, "
                f"output FrameID 0x{ctl.output_iocr.frame_id:04X}",
                flush=True,
            )
            while ctl.get_input_data(in_slot.slot, in_slot.subslot) is None:
                if time.monotonic() - t_connected > 5.0:
                    raise RuntimeError("no valid input data within 5 s of the connect")
                time.sleep(0.0002)
            t_first = time.monotonic()
            print(
                f"figure: DCP identify to first valid cyclic data through profinet-py: "
                f"{1000 * (t_first - t_identify):.0f} ms (identify by name "
                f"{1000 * (t_found - t_identify):.0f} ms, connect to PrmEnd and ApplicationReady "
                f"{1000 * (t_connected - t_found):.0f} ms, first valid input frame "
                f"{1000 * (t_first - t_connected):.1f} ms later; profinet-py identifies with response delay "
                f"factor 0x80, so the device answers after its MAC's share of up to 1.28 s)",
                flush=True,
            )
            # the profile (issue 17) on the cyclic data: receive telegram 1
            # (speed control) of the Example Function block, response 0xF1
            def telegram1(cw1, rpm=0, ramps=10_000, pkw=bytes(8)):
                t = bytearray(out_slot.output_length)
                t[0] = 0xE1
                t[2:4] = cw1.to_bytes(2, "big")
                t[4:8] = rpm.to_bytes(4, "big", signed=True)
                t[16:20] = ramps.to_bytes(4, "big")
                t[24:32] = pkw
                return bytes(t)

            def zsw1(r):
                return int.from_bytes(r[2:4], "big")

            def i32(r, at):
                return int.from_bytes(r[at : at + 4], "big", signed=True)

            def send_until(data, pred, timeout=2.0):
                ctl.set_output_data(out_slot.slot, out_slot.subslot, data)
                t0 = time.monotonic()
                while time.monotonic() - t0 < timeout:
                    r = ctl.get_input_data(in_slot.slot, in_slot.subslot)
                    if r is not None and pred(r):
                        return time.monotonic() - t0, r
                    time.sleep(0.0005)
                return None, ctl.get_input_data(in_slot.slot, in_slot.subslot)

            start = time.monotonic()
            results = []

            def expect(what, data, pred, timeout=2.0, show=None):
                dt, r = send_until(data, pred, timeout)
                seen = "nothing" if r is None else (show(r) if show else f"{r[0]:#04x} ZSW1 {zsw1(r):#06x}")
                results.append((dt is not None, f"{what}: {'%.0f ms' % (1000 * dt) if dt is not None else 'not within %.0f s' % timeout} ({seen})"))
                return r

            for cw1, want, name in [
                (0x0400, 0x40, "switching on inhibited"),
                (0x0406, 0x01, "ready for switching on"),
                (0x0407, 0x03, "switched on"),
                (0x040F, 0x07, "operation"),
            ]:
                expect(
                    f"CW1 {cw1:#06x} -> {name}",
                    telegram1(cw1),
                    lambda r, want=want: r[0] == 0xF1 and r[1] == 0x08 and zsw1(r) & 0x47 == want,
                )
            def pkw_read(index, sub):
                return bytes([0x41, index >> 8, index & 0xFF, sub, 0, 0, 0, 0])

            ctl.set_output_data(out_slot.slot, out_slot.subslot, telegram1(0x047F, 100))
            time.sleep(0.5)
            # the vl mode's velocity demand 6043h, a CANopen object through PKW (P-194)
            expect(
                "100 rpm (bits 4-6, PNU 1010) -> vl demand 6043h read through PKW",
                telegram1(0x047F, 100, pkw=pkw_read(0x6043, 0)),
                lambda r: r[24] == 0x41 and abs(i32(r, 28) - 100) <= 1 and zsw1(r) & 0x47 == 0x07,
                show=lambda r: f"code {r[24]:#04x} value {i32(r, 28)}, ZSW1 {zsw1(r):#06x}",
            )
            if a.motor:
                expect(
                    "the motor at 100 rpm -> PNU 1101",
                    telegram1(0x047F, 100, pkw=pkw_read(0x6043, 0)),
                    lambda r: abs(i32(r, 8) - 100) <= 2,
                    timeout=3.0,
                    show=lambda r: f"{i32(r, 8)} rpm",
                )
            # two reads in a row: 0x00 in between, mirrored (P-193)
            expect("PKW toggle 0x00", telegram1(0x047F, 100), lambda r: r[24] == 0x00, show=lambda r: f"code {r[24]:#04x}")
            vendor = a.vendor_id.to_bytes(4, "big")
            expect(
                "PKW read of PNU 964.0",
                telegram1(0x047F, 100, pkw=pkw_read(964, 0)),
                lambda r: r[24] == 0x41 and r[28:32] == vendor,
                show=lambda r: f"code {r[24]:#04x} value {r[28:32].hex()}",
            )
            expect(
                "bit 6 = 0 -> 0 rpm",
                telegram1(0x043F),
                lambda r: abs(i32(r, 8)) <= 2,
                timeout=3.0,
                show=lambda r: f"{i32(r, 8)} rpm",
            )
            expect("CW1 0x0406 -> ready for switching on", telegram1(0x0406), lambda r: zsw1(r) & 0x47 == 0x01)
            # the rest of the time: the response keeps coming
            answered = 0
            while time.monotonic() - start < a.cyclic_seconds:
                r = ctl.get_input_data(in_slot.slot, in_slot.subslot)
                if r is not None and r[0] == 0xF1 and zsw1(r) & 0x47 == 0x01:
                    answered += 1
                time.sleep(0.05)
            elapsed = time.monotonic() - start
            st = ctl.stats
            ok = all(k for k, _ in results) and answered > 0 and ctl.is_running
            report(
                "h",
                ok,
                f"{elapsed:.1f} s of cyclic data at {setup.cycle_time_ms:g} ms with the profile's telegram 1: "
                + "; ".join(t for _, t in results)
                + f"; frames sent {st.frames_sent} received {st.frames_received} missed {st.frames_missed} "
                f"invalid {st.frames_invalid}; state {ctl.state.value}",
            )

            # (i) a drive fault: appears, acknowledged, disappears after the reset
            def fault():
                want_ch = 0x1000 + a.fault_event
                want_ext = 0x1000 + a.fault_cause
                seen = len(alarms)
                control(f"fault A {a.fault_event} {a.fault_cause}")
                t0 = time.monotonic()
                appears = wait_alarm(seen, 5.0)
                if appears is None:
                    report("i", False, f"fault A {a.fault_event} {a.fault_cause}: no alarm within 5 s")
                    return
                t_appears = time.monotonic() - t0
                items = diagnosis_items(appears)
                ok = (
                    appears.alarm_type == 0x0001
                    and (appears.slot_number, appears.subslot_number) == (0, 1)
                    and appears.channel_diagnosis
                    and any(i.channel_error_type == want_ch and i.ext_channel_error_type == want_ext for i in items)
                )
                report("i", ok, f"fault raised: after {1000 * t_appears:.0f} ms {describe(appears)} (acknowledged by profinet-py)")
                # the data keeps flowing while the drive is faulted
                time.sleep(0.3)
                if not ctl.is_running:
                    report("i", False, f"the AR ended after the alarm: {ctl.state.value}")
                    return
                # the acknowledgement: a rising edge of CW1 bit 7 (P-085)
                seen = len(alarms)
                ctl.set_output_data(out_slot.slot, out_slot.subslot, telegram1(0x0406))
                time.sleep(0.05)
                ctl.set_output_data(out_slot.slot, out_slot.subslot, telegram1(0x0486))
                t0 = time.monotonic()
                gone = wait_alarm(seen, 5.0)
                if gone is None:
                    report("i", False, "fault reset: no disappears alarm within 5 s")
                    return
                t_gone = time.monotonic() - t0
                items = diagnosis_items(gone)
                ok = gone.alarm_type == 0x000C and (gone.slot_number, gone.subslot_number) == (0, 1)
                report("i", ok, f"fault reset: after {1000 * t_gone:.0f} ms {describe(gone)}")
                extra = alarms[seen + 1 :]
                if extra:
                    report("i", False, f"more alarms than expected: {[describe(x) for x in extra]}")

            if a.control is not None:
                run("i", fault)
            else:
                print("step i: skipped: no --control (fault injection needs serve's control FIFO)", flush=True)

            # (j) stop sending output frames, keep listening
            before = len(records.lines)
            ctl._tx_cycle = lambda: None
            silent = time.monotonic()
            err = None
            while time.monotonic() - silent < 5.0:
                err = next((l for l in records.lines[before:] if "RTA ERROR PDU" in l), None)
                if err is not None and ctl.state.value == "fault":
                    break
                time.sleep(0.01)
            ok = err is not None and ctl.state.value == "fault"
            report(
                "j",
                ok,
                f"outputs stopped: after {time.monotonic() - silent:.2f} s the alarm listener saw "
                f"{err or 'no RTA ERR PDU'!r}; the controller is in {ctl.state.value} "
                f"({ctl.stats.frames_missed} watchdog timeouts)",
            )
        finally:
            if ctl is not None:
                ctl.stop()
            dev.close()

    run("h", cyclic)

    # (k) advanced startup: Connect, PrmEnd, ApplicationReady, Release
    def advanced_startup():
        con = RPCCon(info, timeout=5.0)
        answers = keep_answers(con)
        try:
            with AdvancedStartup():
                res = con.connect(src, iocr_setup=IOCRSetup(slots=slots))
            nrd = rpc.PNNRDData(answers[0].payload)
            server = [b for t, b in blocks_of(bytes(nrd.payload)) if t == 0x8106]
            name = b""
            if server:
                n = int.from_bytes(server[0][6:8], "big")
                name = server[0][8 : 8 + n]
            con.prm_end()
            con.application_ready(timeout=10.0)
            ok = (
                0x8000 <= res.input_frame_id <= 0xBBFF
                and 0x8000 <= res.output_frame_id <= 0xBBFF
                and name == a.name.encode()
            )
            report(
                "k",
                ok,
                f"advanced startup Connect (RTClass 2): input FrameID 0x{res.input_frame_id:04X}, "
                f"output FrameID 0x{res.output_frame_id:04X}, ARServerBlockRes station {name!r}; "
                f"PrmEnd; ApplicationReady confirmed",
            )
            # (l) records of MaxSupportedRecordSize and one byte more, in fragments
            def big_records():
                for n, want in [(4068, 0xDF80B000), (4069, 0xDF80B100)]:
                    status, res = fragmented_write(con, 1, 1, 0x7FF0, bytes(k % 251 for k in range(n)))
                    report(
                        "l",
                        status & 0xFFFFFF00 == want and res is not None and res & 0xFFFFFF00 == want,
                        f"{n}-byte record in 1,024-byte RPC fragments: PNIO status 0x{status:08X}, "
                        f"IODWriteRes status 0x{res:08X}",
                    )

            run("l", big_records)

            # (m) the PDev records TIA writes at start-up and reads online
            def pdev_records():
                body = bytes.fromhex("01000000" "0000" "8001") + bytes.fromhex(
                    "020c00040100" "0010" "021c00040100" "0001"
                )
                check = (0x0200).to_bytes(2, "big") + len(body).to_bytes(2, "big") + body
                con.write(0, 0, 0x8001, 0x802B, check)
                back = bytes(con.read(0, 0, 0x8001, 0x802B).payload)
                report(
                    "m",
                    back == check,
                    f"PDPortDataCheck (CheckMAUType 100BASE-TX FD, CheckLinkState up) "
                    f"written to port 1 and read back: {len(back)} bytes",
                )
                real = blocks_of(bytes(con.read(0, 0, 1, 0xF841).payload))
                subslots = [int.from_bytes(b[14:16], "big") for t, b in real if t == 0x0400]
                report("m", subslots == [0x8000, 0x8001, 0x8002], f"PDRealData: MultipleBlockHeaders for {[hex(x) for x in subslots]}")
                stat = bytes(con.read(0, 0, 0x8000, 0x8072).payload)
                ins, outs = int.from_bytes(stat[8:12], "big"), int.from_bytes(stat[12:16], "big")
                report(
                    "m",
                    stat[:2] == b"\x02\x51" and ins > 0 and outs > 0,
                    f"PDPortStatistic of the interface: ifInOctets {ins}, ifOutOctets {outs}",
                )
                # a multiple write with one bad sub-write: the whole answer is an error
                try:
                    down = check[:-2] + b"\x00\x02"  # CheckLinkState "down": the device refuses it
                    con.write_multiple([(0, 0x8001, 0x802B, check, 0), (0, 0x8001, 0x802B, down, 0)])
                    report("m", False, "IODWriteMultiple with a bad sub-write answered OK")
                except profinet.exceptions.PNIOError:
                    # profinet-py 0.6.6 byte-swaps a big-endian status in its
                    # exception: read the answer itself (NDR header, outer
                    # IODWriteResHeader, one per sub-write)
                    raw = bytes(answers[-1].payload)
                    status, res = int.from_bytes(raw[0:4], "big"), raw[20:]
                    outer = int.from_bytes(res[44:48], "big")
                    subs = [int.from_bytes(b[44:48], "big") for t, b in blocks_of(res[64:]) if t == 0x8008]
                    ok = (
                        status & 0xFFFFFF00 == 0xDF80B800
                        and outer == status
                        and len(subs) == 2
                        and subs[0] == 0
                        and subs[1] & 0xFFFFFF00 == 0xDF80B800
                    )
                    report(
                        "m",
                        ok,
                        f"IODWriteMultiple with a bad sub-write: PNIO status 0x{status:08X}, outer header "
                        f"0x{outer:08X}, sub-writes {' '.join(f'0x{x:08X}' for x in subs)}",
                    )

            run("m", pdev_records)
            status, block = release(con)
            if status != 0:
                report("k", False, f"Release refused: 0x{status:08X}")
        finally:
            con.close()

    run("k", advanced_startup)

    return verdict(failures, "steps", "all steps passed")


if __name__ == "__main__":
    sys.exit(main())
