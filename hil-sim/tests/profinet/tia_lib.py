"""The controller of tia.py, built on scapy's PROFINET layers (`scapy.contrib.pnio`,
`pnio_rpc`, `pnio_dcp`; scapy 2.8, GPL-2.0, a test tool only): an Ethernet link
with a receiver thread (DCP answers, the input CR's frames, alarms), the
DCE/RPC endpoint on UDP 34964 (requests in fragments, answers reassembled, the
device's ApplicationReady answered), an AR (Connect in advanced or legacy
startup, PrmEnd, records, Release), the provider of the output CR and the
alarm endpoint (transport ACK at once, AlarmAck after a delay), as an S7-1500
with TIA Portal's configuration sends them (IEC 61158-6-10).

Encodings learnt from the standard's tables as Wireshark's PROFINET dissector
and p-net read them; blocks scapy has no class for (PDPortDataCheck,
PDInterfaceAdjust) are packed here by the standard's layout.
"""

import queue
import socket
import struct
import threading
import time
import uuid
import xml.etree.ElementTree as ET

from scapy.contrib.pnio_rpc import (
    AlarmCRBlockReq,
    ARBlockReq,
    ExpectedSubmodule,
    ExpectedSubmoduleAPI,
    ExpectedSubmoduleBlockReq,
    ExpectedSubmoduleDataDescription,
    IOCRAPI,
    IOCRAPIObject,
    IOCRBlockReq,
    IODControlReq,
    IODReadReq,
    IODWriteReq,
    RPC_INTERFACE_UUID,
)
from scapy.layers.dcerpc import DceRpc4
from scapy.layers.l2 import Dot1Q, Ether

ETH_P_ALL = 0x0003
PNIO = 0x8892
RPC_PORT = 34964
DEVICE_IF = RPC_INTERFACE_UUID["UUID_IO_DeviceInterface"]
CONTROLLER_IF = RPC_INTERFACE_UUID["UUID_IO_ControllerInterface"]
OP_CONNECT, OP_RELEASE, OP_READ, OP_WRITE, OP_CONTROL, OP_READ_IMPLICIT = 0, 1, 2, 3, 4, 5
# DCE/RPC connection-less flags1
LASTFRAG, FRAG, NOFACK, IDEMPOTENT = 0x02, 0x04, 0x08, 0x20
# The controller's own object UUID (as TIA gives an S7-1500: instance 1,
# Siemens' vendor ID 0x002A, a device ID of its own)
CONTROLLER_OBJECT = uuid.UUID("dea00000-6c97-11d1-8271-00010104002a")
MAX_ARGS = 16696  # the NDR buffer a controller offers (TIA's value)


def be16(b, at):
    return int.from_bytes(b[at : at + 2], "big")


def be32(b, at):
    return int.from_bytes(b[at : at + 4], "big")


def mac_bytes(m):
    return bytes(int(x, 16) for x in m.split(":"))


def mac_text(b):
    return ":".join(f"{x:02x}" for x in b)


def blocks_of(payload):
    """The PNIO blocks in `payload`: [(type, whole block)]."""
    out, off = [], 0
    while off + 4 <= len(payload):
        t, n = be16(payload, off), be16(payload, off + 2)
        out.append((t, payload[off : off + 4 + n]))
        off += 4 + n
    return out


def block(btype, body, version=(1, 0)):
    """A block: header (type, length counted from the version, version) and body."""
    return struct.pack(">HHBB", btype, len(body) + 2, *version) + body


def pad4(b):
    return b + bytes(-len(b) % 4)


# ---------------------------------------------------------------- GSDML


def gsdml_modules(path):
    """{module ID: (ModuleIdentNumber, input bytes, output bytes)} of the
    GSDML's modules (DataItems summed)."""
    sizes = {"Unsigned8": 1, "Integer8": 1, "Unsigned16": 2, "Integer16": 2, "Unsigned32": 4,
             "Integer32": 4, "Float32": 4, "Unsigned64": 8, "Integer64": 8, "Float64": 8}
    root = ET.parse(path).getroot()
    out = {}
    for el in root.iter():
        if el.tag.split("}")[-1] != "ModuleItem":
            continue
        ident = int(el.get("ModuleIdentNumber"), 0)
        n = {"Input": 0, "Output": 0}
        for io in el.iter():
            kind = io.tag.split("}")[-1]
            if kind in n:
                for item in io:
                    n[kind] += sizes.get(item.get("DataType"), 0)
        out[el.get("ID")] = (ident, n["Input"], n["Output"])
    return out


# ---------------------------------------------------------------- link


def tx_checksum_offload_off(iface):
    """`ethtool -K IF tx off` (SIOCETHTOOL, ETHTOOL_STXCSUM): a veth leaves
    the kernel's UDP checksums to the receiver, and the device reading raw
    frames would drop them as corrupt."""
    import ctypes
    import fcntl

    value = ctypes.create_string_buffer(struct.pack("II", 0x17, 0))
    ifr = struct.pack("16sP", iface.encode()[:15], ctypes.addressof(value))
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        fcntl.ioctl(s.fileno(), 0x8946, ifr)


class Link:
    """A raw socket on the controller's interface and a receiver thread that
    hands DCP answers, the input CR's frames and alarm frames on."""

    def __init__(self, iface):
        self.iface = iface
        self.sock = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.htons(ETH_P_ALL))
        self.sock.bind((iface, 0))
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4 << 20)
        self.mac = self.sock.getsockname()[4][:6]
        self.dcp = queue.Queue()
        self.rt_handler = None  # fn(frame_id, payload, now)
        self.alarm_handler = None  # fn(frame_id, payload)
        self.lock = threading.Lock()
        self.stop = False
        self.thread = threading.Thread(target=self._rx, daemon=True)
        self.thread.start()

    def send(self, frame):
        with self.lock:
            self.sock.send(bytes(frame))

    def _rx(self):
        self.sock.settimeout(0.2)
        while not self.stop:
            try:
                data, addr = self.sock.recvfrom(2048)
            except (TimeoutError, socket.timeout):
                continue
            except OSError:
                return
            if addr[2] == socket.PACKET_OUTGOING or len(data) < 16:
                continue
            et, at = be16(data, 12), 14
            if et == 0x8100:
                et, at = be16(data, 16), 18
            if et != PNIO:
                continue
            fid = be16(data, at)
            payload = data[at + 2 :]
            if fid in (0xFEFD, 0xFEFF):
                self.dcp.put((data[6:12], fid, payload))
            elif fid in (0xFC01, 0xFE01):
                h = self.alarm_handler
                if h:
                    h(fid, data[6:12], payload)
            else:
                h = self.rt_handler
                if h:
                    h(fid, payload, time.monotonic())

    def close(self):
        self.stop = True
        self.thread.join(1)
        self.sock.close()


# ---------------------------------------------------------------- DCE/RPC


class RpcError(Exception):
    pass


class Rpc:
    """The controller's DCE/RPC endpoint (UDP 34964, where the device sends
    its ApplicationReady): requests to the device, its answers reassembled
    from fragments, its requests answered through `on_control`."""

    def __init__(self, device_ip, port=RPC_PORT):
        self.device = (device_ip, RPC_PORT)
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 20)
        self.sock.bind(("", port))
        self.answers = {}
        self.cv = threading.Condition()
        self.seq = 0
        self.act = uuid.uuid4()
        self.on_control = None  # fn(header, ndr body) -> response blocks
        self.device_requests = []
        self.stop = False
        self.thread = threading.Thread(target=self._rx, daemon=True)
        self.thread.start()

    def close(self):
        self.stop = True
        self.thread.join(1)
        self.sock.close()

    def _rx(self):
        self.sock.settimeout(0.2)
        parts = {}
        while not self.stop:
            try:
                data, src = self.sock.recvfrom(65535)
            except (TimeoutError, socket.timeout):
                continue
            except OSError:
                return
            if len(data) < 80 or data[0] != 4:
                continue
            h = DceRpc4(data[:80])
            body = data[80 : 80 + h.len]
            if h.ptype == 0:
                self._serve(h, body, src)
                continue
            if h.ptype not in (2, 3, 6):  # response, fault, reject (not working, nocall, fack)
                continue
            key = (h.act_id, h.seqnum)
            if h.flags1 & FRAG:
                got = parts.setdefault(key, {})
                got[h.fragnum] = body
                if h.flags1 & LASTFRAG:
                    got["last"] = h.fragnum
                last = got.get("last")
                if last is None or any(k not in got for k in range(last + 1)):
                    continue
                body = b"".join(got[k] for k in range(last + 1))
                del parts[key]
            with self.cv:
                self.answers[key] = (h.ptype, h.endian, body)
                self.cv.notify_all()

    def _serve(self, h, body, src):
        """A request of the device (its ApplicationReady or alarm control)."""
        self.device_requests.append((h.opnum, body))
        blocks = self.on_control(h, body) if self.on_control else b""
        e = ">" if h.endian == 0 else "<"
        ndr = bytes(4) + struct.pack(e + "IIII", len(blocks), MAX_ARGS, 0, len(blocks)) + blocks
        resp = DceRpc4(ptype=2, flags1=NOFACK | LASTFRAG, endian=h.endian, object=h.object, if_id=h.if_id,
                       act_id=h.act_id, server_boot=h.server_boot, if_vers=h.if_vers, seqnum=h.seqnum,
                       opnum=h.opnum, ihint=h.ihint, ahint=h.ahint, fragnum=0) / ndr
        self.sock.sendto(bytes(resp), src)

    def call(self, opnum, blocks, *, object_uuid, little=False, frag=None, timeout=5.0, args_max=MAX_ARGS,
             act=None):
        """A request (the NDR header and `blocks`), in fragments of `frag`
        body bytes if given; returns (PNIO status, the answer's blocks). An
        RPC fault or reject raises RpcError."""
        self.seq += 1
        seq = self.seq
        act = act or self.act
        e = "<" if little else ">"
        ndr = struct.pack(e + "IIIII", args_max, len(blocks), args_max, 0, len(blocks)) + blocks
        chunks = [ndr] if frag is None else [ndr[k : k + frag] for k in range(0, len(ndr), frag)]
        for n, c in enumerate(chunks):
            flags = IDEMPOTENT
            if len(chunks) > 1:
                flags |= FRAG | (LASTFRAG if n == len(chunks) - 1 else 0)
            h = DceRpc4(ptype=0, flags1=flags, endian="little" if little else "big", object=object_uuid,
                        if_id=DEVICE_IF, act_id=act, server_boot=0, if_vers=1, seqnum=seq, opnum=opnum,
                        fragnum=n) / c
            self.sock.sendto(bytes(h), self.device)
        end = time.monotonic() + timeout
        key = (act, seq)
        with self.cv:
            while key not in self.answers:
                left = end - time.monotonic()
                if left <= 0:
                    raise RpcError(f"no answer to opnum {opnum} within {timeout:g} s")
                self.cv.wait(left)
            ptype, endian, body = self.answers.pop(key)
        if ptype != 2:
            code = int.from_bytes(body[:4], "little" if endian else "big") if len(body) >= 4 else 0
            raise RpcError(f"RPC {'fault' if ptype == 3 else 'ptype %d' % ptype} 0x{code:08X}")
        if len(body) < 20:
            raise RpcError(f"answer of {len(body)} bytes: no NDR header")
        re = "<" if endian else ">"
        status = be32(body, 0)
        args_len = struct.unpack(re + "I", body[4:8])[0]
        return status, body[20 : 20 + args_len]


# ---------------------------------------------------------------- records


def read_req(index, slot=0, subslot=1, ar_uuid=uuid.UUID(int=0), length=4096, seq=0):
    return bytes(IODReadReq(seqNum=seq, ARUUID=ar_uuid, API=0, slotNumber=slot, subslotNumber=subslot,
                            index=index, recordDataLength=length, RWPadding=bytes(24)))


def write_req(index, data, slot=0, subslot=1, ar_uuid=uuid.UUID(int=0), seq=0):
    return bytes(IODWriteReq(seqNum=seq, ARUUID=ar_uuid, API=0, slotNumber=slot, subslotNumber=subslot,
                             index=index, recordDataLength=len(data), RWPadding=bytes(24))) + bytes(data)


def read_answer(status, blocks):
    """(status, record data) of a read's answer: the IODReadRes header (64
    bytes) and RecordDataLength bytes of data after it."""
    if len(blocks) >= 64 and be16(blocks, 0) == 0x8009:
        return status, blocks[64 : 64 + be32(blocks, 36)]
    return status, b""


def write_statuses(blocks):
    """The PNIO statuses of the IODWriteRes blocks in an answer (the outer
    one of a write-multiple first)."""
    out, off = [], 0
    while off + 64 <= len(blocks):
        t, n = be16(blocks, off), be16(blocks, off + 2)
        if t != 0x8008:
            break
        out.append((be16(blocks, off + 34), be32(blocks, off + 44)))  # (index, status)
        off += 64
        if n != 60:
            break
    return out


# ---------------------------------------------------------------- the AR


class Submodule:
    def __init__(self, slot, subslot, module, submodule, inp=0, out=0):
        self.slot, self.subslot, self.module, self.submodule = slot, subslot, module, submodule
        self.inp, self.out = inp, out


def dap_submodules():
    return [Submodule(0, s, 0x00000001, ident) for s, ident in
            [(1, 0x00000001), (0x8000, 0x00008000), (0x8001, 0x00008001), (0x8002, 0x00008002)]]


class Layout:
    """Where each submodule's data, IOPS and IOCS sit in both CRs (IEC
    61158-6-10: a submodule without I/O data has its IOPS in the input CR
    and its IOCS in the output CR)."""

    def __init__(self, subs):
        self.subs = subs
        self.in_data, self.in_iocs, self.out_data, self.out_iocs = [], [], [], []
        off = 0
        for s in subs:  # input CR: data objects, then IOCS of the outputs
            if s.out == 0:
                self.in_data.append((s, off))
                off += s.inp + 1
        for s in subs:
            if s.out > 0:
                self.in_iocs.append((s, off))
                off += 1
        self.in_len = max(40, off)
        off = 0
        for s in subs:
            if s.out > 0:
                self.out_data.append((s, off))
                off += s.out + 1
        for s in subs:
            if s.out == 0:
                self.out_iocs.append((s, off))
                off += 1
        self.out_len = max(40, off)


def iocr_apis(data, iocs):
    return [IOCRAPI(API=0, IODataObjects=[IOCRAPIObject(SlotNumber=s.slot, SubslotNumber=s.subslot,
                                                        FrameOffset=o) for s, o in data],
                    IOCSs=[IOCRAPIObject(SlotNumber=s.slot, SubslotNumber=s.subslot, FrameOffset=o)
                           for s, o in iocs])]


def expected_blocks(subs):
    out = b""
    for slot in sorted({s.slot for s in subs}):
        here = [s for s in subs if s.slot == slot]
        es = []
        for s in here:
            if s.out > 0 and s.inp > 0:
                typ, dd = 3, [(1, s.inp), (2, s.out)]
            elif s.out > 0:
                typ, dd = 2, [(2, s.out)]
            elif s.inp > 0:
                typ, dd = 1, [(1, s.inp)]
            else:
                typ, dd = 0, [(1, 0)]
            es.append(ExpectedSubmodule(
                SubslotNumber=s.subslot, SubmoduleIdentNumber=s.submodule, SubmoduleProperties_Type=typ,
                DataDescription=[ExpectedSubmoduleDataDescription(DataDescription=d, SubmoduleDataLength=n,
                                                                  LengthIOCS=1, LengthIOPS=1) for d, n in dd]))
        api = ExpectedSubmoduleAPI(API=0, SlotNumber=slot, ModuleIdentNumber=here[0].module, Submodules=es)
        out += bytes(ExpectedSubmoduleBlockReq(APIs=[api]))
    return out


def next_seq(s):
    """RTA sequence numbers: 0xFFFF, then 0 … 0x7FFF modulo 0x8000."""
    return 0 if s == 0xFFFF else (s + 1) & 0x7FFF


class AR:
    """One IOCARSingle of the controller: Connect in advanced (StartupMode 1,
    RTClass 2, FrameIDs 0x8000–0xBBFF) or legacy startup (RTClass 1,
    0xC000–0xF7FF), PrmEnd, the device's ApplicationReady answered, the
    output CR sent every cycle and the input CR checked, alarms
    acknowledged, Release."""

    def __init__(self, link, rpc, device_mac, object_uuid, subs, *, startup="advanced", name="plc-1",
                 reduction=4, watchdog=24, initiator_mac=None, alarm_ref=3, ack_delay=0.0):
        self.link, self.rpc, self.device_mac = link, rpc, mac_bytes(device_mac)
        self.object_uuid, self.subs, self.startup, self.name = object_uuid, subs, startup, name
        self.layout = Layout(subs)
        self.reduction, self.watchdog = reduction, watchdog
        self.initiator_mac = initiator_mac or link.mac
        self.ar_uuid = uuid.uuid4()
        self.session = 1
        self.alarm_ref, self.device_alarm_ref = alarm_ref, None
        self.ready = threading.Event()
        self.input_fid = self.output_fid = None
        self.stats = {"sent": 0, "received": 0, "bad_iops": 0, "bad_iocs": 0, "bad_status": 0, "gap": 0}
        self.max_gap = 0.0
        self.last_rx = None
        self.first_good = None
        self.alarms = []  # (alarm type, slot, subslot, sequence, when acknowledged)
        self.abort = None
        self.ack_delay = ack_delay
        self.ack_q = queue.Queue()
        self.rta = {"exp": 0xFFFF, "exp_o": 0xFFFE, "send": 0xFFFF, "send_o": 0xFFFE}
        self.rta_confirmed = threading.Event()
        self.cyclic = None
        self.running = False

    # -- RPC
    def connect(self):
        l = self.layout
        rt_class = 2 if self.startup == "advanced" else 1
        base = 0x8000 if self.startup == "advanced" else 0xC000
        ar = ARBlockReq(ARType=1, ARUUID=self.ar_uuid, SessionKey=self.session,
                        CMInitiatorMacAdd=mac_text(self.initiator_mac), CMInitiatorObjectUUID=CONTROLLER_OBJECT,
                        ARProperties_PullModuleAlarmAllowed=1 if self.startup == "advanced" else 0,
                        ARProperties_StartupMode=1 if self.startup == "advanced" else 0,
                        ARProperties_ParametrizationServer=1, ARProperties_State=1,
                        CMInitiatorActivityTimeoutFactor=600, CMInitiatorUDPRTPort=PNIO,
                        CMInitiatorStationName=self.name.encode())
        common = dict(LT=PNIO, IOCRProperties_RTClass=rt_class, SendClockFactor=32,
                      ReductionRatio=self.reduction, Phase=1, Sequence=0, FrameSendOffset=0xFFFFFFFF,
                      WatchdogFactor=self.watchdog, DataHoldFactor=self.watchdog, IOCRTagHeader_IOUserPriority=6,
                      IOCRMulticastMACAdd="00:00:00:00:00:00")
        iocr_in = IOCRBlockReq(IOCRType=1, IOCRReference=1, DataLength=l.in_len, FrameID=base + 1,
                               APIs=iocr_apis(l.in_data, l.in_iocs), **common)
        iocr_out = IOCRBlockReq(IOCRType=2, IOCRReference=2, DataLength=l.out_len, FrameID=0xFFFF,
                                APIs=iocr_apis(l.out_data, l.out_iocs), **common)
        alarm = AlarmCRBlockReq(AlarmCRType=1, LT=PNIO, RTATimeoutFactor=1, RTARetries=3,
                                LocalAlarmReference=self.alarm_ref, MaxAlarmDataLength=200,
                                AlarmCRTagHeaderHigh=0xC000, AlarmCRTagHeaderLow=0xA000)
        blocks = bytes(ar) + bytes(iocr_in) + bytes(iocr_out) + expected_blocks(self.subs) + bytes(alarm)
        self.link.alarm_handler = self._alarm
        self.link.rt_handler = self._rt
        self.rpc.on_control = self._control
        status, res = self.rpc.call(OP_CONNECT, blocks, object_uuid=self.object_uuid)
        self.connect_blocks = blocks_of(res)
        for t, b in self.connect_blocks:
            if t == 0x8102:
                typ, fid = be16(b, 6), be16(b, 10)
                if typ == 1:
                    self.input_fid = fid
                else:
                    self.output_fid = fid
            elif t == 0x8103:
                self.device_alarm_ref = be16(b, 8)
        return status

    def block(self, btype):
        return next((b for t, b in self.connect_blocks if t == btype), None)

    def control(self, btype, command):
        req = IODControlReq(block_type=btype, ARUUID=self.ar_uuid, SessionKey=self.session,
                            ControlCommand_PrmEnd=command == 1, ControlCommand_Release=command == 4)
        op = OP_RELEASE if command == 4 else OP_CONTROL
        status, res = self.rpc.call(op, bytes(req), object_uuid=self.object_uuid)
        return status, blocks_of(res)

    def prm_end(self):
        return self.control(0x0110, 1)

    def release(self):
        self.stop_cyclic()
        return self.control(0x0114, 4)

    def _control(self, h, body):
        """The device's request: ApplicationReady (IODControlReq 0x0112)
        answered with Done."""
        blocks = body[20:]
        for t, b in blocks_of(blocks):
            if t in (0x0112, 0x0113) and uuid.UUID(bytes=b[8:24]) == self.ar_uuid:
                self.ready.set()
                return bytes(block(t + 0x8000, bytes(2) + b[8:24] + b[24:26] + bytes(2)
                                   + struct.pack(">HH", 0x0008, 0)))
        return b""

    def read(self, index, slot=0, subslot=1, length=4096):
        status, res = self.rpc.call(OP_READ, read_req(index, slot, subslot, self.ar_uuid, length),
                                    object_uuid=self.object_uuid)
        return read_answer(status, res)

    def write(self, index, data, slot=0, subslot=1, frag=None):
        status, res = self.rpc.call(OP_WRITE, write_req(index, data, slot, subslot, self.ar_uuid),
                                    object_uuid=self.object_uuid, frag=frag)
        ws = write_statuses(res)
        return status, (ws[0][1] if ws else None)

    def write_multiple(self, writes):
        """IODWriteMultiple (index 0xE040): [(slot, subslot, index, data)],
        each write padded to 4 octets; returns (PNIO status, the outer
        IODWriteRes's status, [(index, status)] of the inner ones)."""
        inner = b""
        for k, (slot, subslot, index, data) in enumerate(writes):
            w = write_req(index, data, slot, subslot, self.ar_uuid, seq=k + 1)
            inner += pad4(w) if k + 1 < len(writes) else w
        outer = struct.pack(">HHBBH", 0x0008, 60, 1, 0, 0) + self.ar_uuid.bytes + struct.pack(
            ">IHH2xHI", 0xFFFFFFFF, 0xFFFF, 0xFFFF, 0xE040, len(inner)) + bytes(24)
        status, res = self.rpc.call(OP_WRITE, outer + inner, object_uuid=self.object_uuid)
        ws = write_statuses(res)
        return status, (ws[0][1] if ws else None), ws[1:]

    # -- cyclic data
    def start_cyclic(self, output=None):
        """The output CR's provider: every SendClockFactor x ReductionRatio x
        31.25 us a frame (data IOPS good, the input submodules' IOCS good,
        DataStatus run/valid/primary)."""
        l = self.layout
        sdu = bytearray(l.out_len)
        for s, o in l.out_data:
            if output:
                sdu[o : o + s.out] = output[: s.out]
            sdu[o + s.out] = 0x80
        for _s, o in l.out_iocs:
            sdu[o] = 0x80
        frame = bytes(Ether(dst=mac_text(self.device_mac), src=mac_text(self.link.mac), type=0x8100)
                      / Dot1Q(prio=6, vlan=0, type=PNIO)) + struct.pack(">H", self.output_fid) + bytes(sdu) + bytes(
            [0, 0, 0x35, 0])
        self.template = bytearray(frame)
        self.running = True
        self.cyclic = threading.Thread(target=self._provide, daemon=True)
        self.cyclic.start()

    def _provide(self):
        period = 32 * self.reduction * 31.25e-6
        counter = 0
        t = time.monotonic()
        f = self.template
        n = len(f)
        while self.running:
            counter = (counter + 32 * self.reduction) & 0xFFFF
            f[n - 4 : n - 2] = counter.to_bytes(2, "big")
            try:
                self.link.send(f)
                self.stats["sent"] += 1
            except OSError:
                pass
            t += period
            d = t - time.monotonic()
            if d > 0:
                time.sleep(d)
            elif d < -0.5:
                t = time.monotonic()

    def stop_cyclic(self):
        self.running = False
        if self.cyclic:
            self.cyclic.join(1)
            self.cyclic = None

    def _rt(self, fid, payload, now):
        if fid != self.input_fid:
            return
        l = self.layout
        sdu = payload[: l.in_len]
        status = payload[l.in_len + 2] if len(payload) >= l.in_len + 4 else 0
        self.stats["received"] += 1
        if self.last_rx is not None:
            gap = now - self.last_rx
            self.max_gap = max(self.max_gap, gap)
        self.last_rx = now
        good = True
        # DataStatus: primary (0x01), valid (0x04), run (0x10); the station
        # problem indicator (0x20 = no problem) is not judged here: the
        # topology check written in step e (0x802B, a neighbour this
        # controller does not play) leaves a port diagnosis pending, and the
        # device then rightly shows "problem detected"
        if status & 0x15 != 0x15:
            self.stats["bad_status"] += 1
            good = False
        for s, o in l.in_data:
            if sdu[o + s.inp] != 0x80:
                self.stats["bad_iops"] += 1
                good = False
                break
        for _s, o in l.in_iocs:
            if sdu[o] != 0x80:
                self.stats["bad_iocs"] += 1
                good = False
                break
        if good and self.first_good is None:
            self.first_good = now
        self.last_input = (bytes(sdu), status)

    # -- alarms (RTA, IEC 61158-6-10)
    def _alarm_frame(self, fid, ptype, tack, send, ack, body=b""):
        hdr = struct.pack(">HHBBHHH", self.device_alarm_ref, self.alarm_ref, 0x10 | ptype, (0x10 if tack else 0) | 1,
                          send, ack, len(body))
        prio = 6 if fid == 0xFC01 else 5
        return (Ether(dst=mac_text(self.device_mac), src=mac_text(self.link.mac), type=0x8100)
                / Dot1Q(prio=prio, vlan=0, type=PNIO)
                / (struct.pack(">H", fid) + hdr + body))

    def _alarm(self, fid, src, p):
        if src != self.device_mac or len(p) < 12:
            return
        dst_ep, src_ep, ptype, _flags, send, ack, n = struct.unpack(">HHBBHHH", p[:12])
        if dst_ep != self.alarm_ref:
            return
        r = self.rta
        ptype &= 0x0F
        if ack == r["send"] and self.rta_pending and ptype != 4:
            self.rta_pending = False
            r["send_o"], r["send"] = r["send"], next_seq(r["send"])
            self.rta_confirmed.set()
        if ptype == 4:  # ERR: the device aborts the AR
            self.abort = p[12:16].hex()
            return
        if ptype != 1:
            return
        if send == r["exp"]:
            r["exp_o"], r["exp"] = r["exp"], next_seq(r["exp"])
            self.link.send(self._alarm_frame(fid, 3, False, r["send_o"], r["exp_o"]))
            self.ack_q.put((fid, p[12 : 12 + n], time.monotonic()))
        elif send == r["exp_o"]:  # a repeat: ACK again
            self.link.send(self._alarm_frame(fid, 3, False, r["send_o"], r["exp_o"]))

    rta_pending = False

    def start_acker(self):
        threading.Thread(target=self._acker, daemon=True).start()

    def _acker(self):
        """AlarmAck (block 0x8001/0x8002: AlarmType, API, slot, subslot,
        AlarmSpecifier echoed, PNIOStatus OK) `ack_delay` after the alarm,
        one at a time (window 1), sent again after 100 ms up to 3 times."""
        while True:
            fid, var, t = self.ack_q.get()
            if fid is None:
                return
            wait = t + self.ack_delay - time.monotonic()
            if wait > 0:
                time.sleep(wait)
            btype = be16(var, 0)
            body = var[6:8] + var[8:12] + var[12:14] + var[14:16] + var[24:26] + bytes(4)
            ack = block(btype + 0x8000 if btype < 0x8000 else btype, body)
            self.rta_confirmed.clear()
            self.rta_pending = True
            r = self.rta
            frame = self._alarm_frame(fid, 1, True, r["send"], r["exp_o"], ack)
            for _ in range(4):
                self.link.send(frame)
                if self.rta_confirmed.wait(0.1):
                    break
            self.alarms.append((be16(var, 6), be16(var, 12), be16(var, 14), be16(var, 24) & 0x7FF,
                                self.rta_confirmed.is_set()))
