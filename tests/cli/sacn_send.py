"""An sACN (ANSI E1.31) data packet sender, written from the standard's
packet layout: root layer, framing layer, DMP layer, all big-endian."""
import socket
import struct

ACN_ID = b"ASC-E1.17\0\0\0"


def data_packet(universe, slots, sequence, priority=100, cid=b"\x11" * 16, options=0,
                start_code=0, count=None):
    slots = bytes(slots)
    count = len(slots) + 1 if count is None else count
    dmp = struct.pack(">HBBHHH", 0x7000 | (10 + len(slots) + 1), 0x02, 0xA1, 0, 1, count)
    dmp += bytes([start_code]) + slots
    name = b"animrt test".ljust(64, b"\0")
    framing_body = struct.pack(">I", 2) + name + struct.pack(">BHBBH", priority, 0,
                                                              sequence & 0xFF, options, universe)
    framing = struct.pack(">H", 0x7000 | (2 + len(framing_body) + len(dmp))) + framing_body
    root_body = struct.pack(">I", 4) + cid + framing + dmp
    root = struct.pack(">H", 0x7000 | (2 + len(root_body))) + root_body
    return struct.pack(">HH", 0x0010, 0) + ACN_ID + root


class Sender:
    def __init__(self, port):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF,
                             socket.inet_aton("127.0.0.1"))
        self.port = port

    def unicast(self, packet):
        self.sock.sendto(packet, ("127.0.0.1", self.port))

    def multicast(self, universe, packet):
        group = "239.255.%d.%d" % (universe >> 8, universe & 0xFF)
        self.sock.sendto(packet, (group, self.port))
