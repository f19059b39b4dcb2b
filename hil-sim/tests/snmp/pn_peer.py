"""A PROFINET neighbour on interface argv[1] for the SNMP test (P-038), plain
sockets only: it sends the device (IP argv[2]) an LLDPDU as a controller port
would (chassis "plc-1", port "port-001", TTL 120, LLDP_PNIO_DELAY with Rx 444,
Tx 1123 and cable 55 ns, LLDP_PNIO_PORTSTATUS RTClass2 up, the 802.3 MAC/PHY
TLV with auto-negotiation supported but off and MAU type 16, management
address argv[3] on ifIndex 1), then reads PDPortDataReal (0x802A) of port 1
(subslot 0x8001) with an implicit read (DCE/RPC over UDP 34964, big-endian
NDR) and prints what it reports:

    pdportdatareal: mau=16 peer_port=port-001 peer_station=plc-1
"""

import os
import socket
import struct
import sys
import time
import uuid

iface, device_ip, own_ip = sys.argv[1], sys.argv[2], sys.argv[3]


def tlv(t, value):
    return struct.pack(">H", (t << 9) | len(value)) + value


raw = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.htons(0x88CC))
raw.bind((iface, 0x88CC))
src = raw.getsockname()[4]
pnio, dot3 = b"\x00\x0e\xcf", b"\x00\x12\x0f"
lldpdu = (
    tlv(1, b"\x07plc-1")
    + tlv(2, b"\x07port-001")
    + tlv(3, struct.pack(">H", 120))
    + tlv(127, pnio + b"\x01" + struct.pack(">5I", 444, 0, 1123, 0, 55))
    + tlv(127, pnio + b"\x02" + struct.pack(">HH", 2, 0))
    + tlv(127, pnio + b"\x05" + src)
    + tlv(127, dot3 + b"\x01" + struct.pack(">BHH", 0x01, 0x0000, 16))
    + tlv(8, b"\x05\x01" + socket.inet_aton(own_ip) + struct.pack(">BIB", 2, 1, 0))
    + tlv(0, b"")
)
frame = bytes.fromhex("0180c200000e") + src + b"\x88\xcc" + lldpdu
for _ in range(2):
    raw.send(frame.ljust(60, b"\0"))
    time.sleep(0.2)

# IODReadReq: implicit (AR UUID nil), API 0, slot 0, subslot 0x8001, index 0x802A
req = struct.pack(">HHBBH16sIHH2sHI16s8s", 0x0009, 60, 1, 0, 1, bytes(16), 0, 0, 0x8001, bytes(2),
                  0x802A, 4096, bytes(16), bytes(8))
ndr = struct.pack(">IIIII", 4096, len(req), 4096, 0, len(req)) + req
obj = uuid.UUID("dea00000-6c97-11d1-8271-00010001fefe")  # instance 1, device 1, vendor 0xFEFE
iface_uuid = uuid.UUID("dea00001-6c97-11d1-8271-00a02442df7d")
head = struct.pack(">BBBB3sB16s16s16sIIIHHHHHBB", 4, 0, 0x20, 0, b"\x00\x00\x00", 0, obj.bytes,
                   iface_uuid.bytes, os.urandom(16), 0, 1, 0, 5, 0xFFFF, 0xFFFF, len(ndr), 0, 0, 0)
udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
udp.settimeout(2)
answer = None
for _ in range(3):
    udp.sendto(head + ndr, (device_ip, 34964))
    try:
        answer, _ = udp.recvfrom(4096)
        break
    except socket.timeout:
        continue
# a response (PDU type 2) in big-endian NDR, as asked
if answer is None or len(answer) < 80 + 20 + 64 or answer[1] != 2 or answer[4] & 0xF0 != 0:
    print(f"implicit read: no answer ({answer!r})")
    sys.exit(1)
body = answer[80:]
status = struct.unpack(">I", body[:4])[0]
record = body[20 + 64:]
if status != 0 or len(record) < 6 or struct.unpack(">H", record[:2])[0] != 0x020F:
    print(f"implicit read of PDPortDataReal: status 0x{status:08X}, record {record.hex()}")
    sys.exit(1)


def counted(at):
    n = record[at]
    return record[at + 1:at + 1 + n].decode(), at + 1 + n


def pad4(at):
    return at + (-at) % 4


# BlockHeader (6), padding (2), slot, subslot, own port name, number of peers
own, at = counted(12)
peers = record[at]
at = pad4(at + 1)
peer_port = peer_station = ""
if peers:
    peer_port, at = counted(at)
    peer_station, at = counted(at)
    at = pad4(at) + 4 + 6 + 2  # LineDelay, PeerMACAddress, padding
mau = struct.unpack(">H", record[at:at + 2])[0]
print(f"pdportdatareal: mau={mau} peer_port={peer_port} peer_station={peer_station}")
