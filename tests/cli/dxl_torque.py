"""An independent Dynamixel Protocol 2.0 client for the CLI tests: opens the
simulated servos' pty, reads Torque Enable (address 64, 1 byte) of each id
with a Read instruction, and prints "id=value" for each, or exits 1 naming
the id that gave no valid answer. The CRC is the CRC-16 of the e-manual
(polynomial 0x8005, initial value 0, no reflection).

usage: /usr/bin/python3 dxl_torque.py PTY BAUD ID...
"""
import sys

import serial


def crc16(data):
    crc = 0
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x8005) if crc & 0x8000 else (crc << 1)
            crc &= 0xFFFF
    return crc


def packet(dev, inst, params=b""):
    body = (bytes([0xFF, 0xFF, 0xFD, 0x00, dev]) + (len(params) + 3).to_bytes(2, "little")
            + bytes([inst]) + params)
    return body + crc16(body).to_bytes(2, "little")


TORQUE_ENABLE = 64
READ = 0x02
STATUS = 0x55


def read_torque_enable(port, dev):
    port.reset_input_buffer()
    port.write(packet(dev, READ, TORQUE_ENABLE.to_bytes(2, "little") + (1).to_bytes(2, "little")))
    reply = port.read(12)  # header 4, id, length 2, 0x55, error, 1 data byte, CRC 2
    if (len(reply) != 12 or reply[:5] != bytes([0xFF, 0xFF, 0xFD, 0x00, dev])
            or reply[7] != STATUS or crc16(reply[:-2]) != int.from_bytes(reply[-2:], "little")):
        return None
    return reply[9]


def main():
    pty, baud, ids = sys.argv[1], int(sys.argv[2]), [int(i) for i in sys.argv[3:]]
    with serial.Serial(pty, baud, timeout=0.2) as port:
        values = []
        for dev in ids:
            value = None
            for _ in range(3):
                value = read_torque_enable(port, dev)
                if value is not None:
                    break
            if value is None:
                print(f"id {dev}: no valid answer to a Read of Torque Enable")
                sys.exit(1)
            values.append(f"{dev}={value}")
    print(" ".join(values))


main()
