"""DCP Set IP suite (permanent) of the device with MAC argv[2] from interface
argv[1] to argv[3], and its name of station to argv[4] if given, after switching off the interface's UDP checksum offload
(a veth leaves the checksum of the kernel's datagrams to the receiver; the
device reads raw frames and would drop them as corrupt). Plain sockets only:
the SNMP test needs no PROFINET controller library."""

import ctypes
import fcntl
import socket
import struct
import sys
import time

iface, mac, ip = sys.argv[1], bytes.fromhex(sys.argv[2].replace(":", "")), sys.argv[3]
name = sys.argv[4].encode() if len(sys.argv) > 4 else b""
# ETHTOOL_STXCSUM (0x17) = 0 through SIOCETHTOOL
value = ctypes.create_string_buffer(struct.pack("II", 0x17, 0))
ifr = struct.pack("16sP", iface.encode()[:15], ctypes.addressof(value))
with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
    fcntl.ioctl(s.fileno(), 0x8946, ifr)

s = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.htons(0x8892))
s.bind((iface, 0x8892))
src = s.getsockname()[4]
suite = socket.inet_aton(ip) + socket.inet_aton("255.255.255.0") + bytes(4)
# IP / IP parameter, BlockQualifier 1 (permanent)
block = struct.pack(">BBHH", 1, 2, 2 + len(suite), 1) + suite
if name:
    # Device properties / name of station, BlockQualifier 1, padded to an even length
    named = struct.pack(">BBHH", 2, 2, 2 + len(name), 1) + name
    block += named + bytes(len(named) % 2)
# FrameID 0xFEFD, Set request, Xid, ResponseDelay 0, DCPDataLength
pdu = struct.pack(">HBBIHH", 0xFEFD, 4, 0, 0x5E7, 0, len(block)) + block
frame = mac + src + struct.pack(">H", 0x8892) + pdu
s.send(frame.ljust(60, b"\0"))
s.settimeout(2)
deadline = time.time() + 2
while time.time() < deadline:
    r = s.recv(1514)
    if r[6:12] == mac and r[14:16] == b"\xfe\xfd" and r[17] == 1:
        print("dcp set ip: ok")
        sys.exit(0)
print("dcp set ip: no positive answer")
sys.exit(1)
