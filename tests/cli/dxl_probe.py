"""An independent Dynamixel Protocol 2.0 client (no animrt code) for the
kill -9 tests: reads each servo's Bus Watchdog (98), Torque Enable (64),
Moving (122) and Present Position (132), twice, DELAY_S apart.

Usage: dxl_probe.py PORT FIRST_ID LAST_ID [DELAY_S]
Prints one line per servo: "ID WATCHDOG TORQUE MOVING POSITION1 POSITION2".
Packets and the CRC-16 (polynomial 0x8005) follow the ROBOTIS e-manual.
"""

import sys
import time

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
    # No byte stuffing needed: a Read's parameters never hold FF FF FD.
    body = bytes([0xFF, 0xFF, 0xFD, 0x00, dev]) + (len(params) + 3).to_bytes(2, "little")
    body += bytes([inst]) + params
    return body + crc16(body).to_bytes(2, "little")


def read(port, dev, address, length):
    port.reset_input_buffer()
    port.write(packet(dev, 0x02, address.to_bytes(2, "little") + length.to_bytes(2, "little")))
    reply = port.read(11 + length)
    if len(reply) != 11 + length or reply[:5] != bytes([0xFF, 0xFF, 0xFD, 0x00, dev]):
        raise SystemExit("id %d: no valid answer to a read of %d: %r" % (dev, address, reply))
    if reply[7] != 0x55 or crc16(reply[:-2]) != int.from_bytes(reply[-2:], "little"):
        raise SystemExit("id %d: bad status packet %s" % (dev, reply.hex()))
    if reply[8] & 0x7F:
        raise SystemExit("id %d: status error 0x%02x" % (dev, reply[8]))
    return int.from_bytes(reply[9:9 + length], "little", signed=length == 4)


def main():
    # A read returns once its answer is in; the long timeout is for a loaded
    # machine that holds the simulated servos off the CPU.
    port = serial.Serial(sys.argv[1], 1000000, timeout=5)
    ids = range(int(sys.argv[2]), int(sys.argv[3]) + 1)
    delay = float(sys.argv[4]) if len(sys.argv) > 4 else 0.2
    first = {}
    for dev in ids:
        first[dev] = (read(port, dev, 98, 1), read(port, dev, 64, 1), read(port, dev, 122, 1),
                      read(port, dev, 132, 4))
    time.sleep(delay)
    for dev in ids:
        watchdog, torque, moving, position = first[dev]
        print(dev, watchdog, torque, moving, position, read(port, dev, 132, 4))


main()
