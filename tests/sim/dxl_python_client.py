"""An independent Protocol 2.0 client (no animrt code) for the simulator test.

Usage: dxl_python_client.py PORT
Sends a Ping and a Read of Present Position to ID 1 with pyserial and prints
"ping MODEL FIRMWARE" and "read ERROR POSITION". Packets and the CRC are built
here from the ROBOTIS e-manual's description, bit by bit.
"""

import struct
import sys

import serial


def crc16(data):
    # CRC-16, polynomial 0x8005, MSB first, initial value 0.
    crc = 0
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x8005) if crc & 0x8000 else (crc << 1)
            crc &= 0xFFFF
    return crc


def stuff(body):
    out = bytearray()
    for b in body:
        out.append(b)
        if len(out) >= 3 and out[-3:] == b"\xff\xff\xfd":
            out.append(0xFD)
    return out


def instruction(dxl_id, inst, params=b""):
    body = stuff(bytes([inst]) + bytes(params))
    packet = bytearray(b"\xff\xff\xfd\x00") + bytes([dxl_id]) + struct.pack("<H", len(body) + 2) + body
    return bytes(packet + struct.pack("<H", crc16(packet)))


def read_status(port):
    header = port.read(7)
    if len(header) != 7 or header[:4] != b"\xff\xff\xfd\x00":
        raise SystemExit("bad header: %r" % header)
    length = struct.unpack("<H", header[5:7])[0]
    rest = port.read(length)
    packet = header + rest
    if len(rest) != length or crc16(packet[:-2]) != struct.unpack("<H", packet[-2:])[0]:
        raise SystemExit("bad status packet: %r" % packet)
    if packet[7] != 0x55:
        raise SystemExit("not a status packet: %r" % packet)
    return packet[4], packet[8], packet[9:-2]


def main():
    port = serial.Serial(sys.argv[1], 1000000, timeout=2)
    port.reset_input_buffer()
    port.write(instruction(1, 0x01))
    dxl_id, error, data = read_status(port)
    model, firmware = struct.unpack("<HB", data)
    print("ping %d %d %d %d" % (dxl_id, error, model, firmware))
    port.write(instruction(1, 0x02, struct.pack("<HH", 132, 4)))
    dxl_id, error, data = read_status(port)
    print("read %d %d %d" % (dxl_id, error, struct.unpack("<i", data)[0]))
    port.close()


if __name__ == "__main__":
    main()
