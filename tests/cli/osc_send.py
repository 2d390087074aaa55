"""A small OSC 1.0 sender for the serve tests, written from the OSC 1.0
specification: an OSC-string is ASCII, NUL-terminated and padded with NULs
to a multiple of four bytes; int32 and float32 arguments are big-endian; a
message is the address pattern, the type tag string (',' then one letter
per argument) and the arguments; a bundle is "#bundle", a 64-bit time tag
and elements each prefixed by its int32 size.

Usage: osc_send.py PORT SCRIPT, where SCRIPT is lines of:
  send ADDRESS [ARG...]     ints as "i:7", floats as "f:0.5"
  bundle ADDRESS...         one bundle of argument-less messages
  raw HEX...                bytes as they are (a malformed packet)
  burst N ADDRESS...        N messages, cycling over the addresses
  sleep SECONDS
Prints the number of packets sent."""
import socket
import struct
import sys
import time


def osc_string(text):
    data = text.encode("ascii") + b"\0"
    return data + b"\0" * (-len(data) % 4)


def osc_message(address, args=()):
    tags = ","
    payload = b""
    for arg in args:
        kind, value = arg.split(":", 1)
        if kind == "i":
            tags += "i"
            payload += struct.pack(">i", int(value))
        elif kind == "f":
            tags += "f"
            payload += struct.pack(">f", float(value))
        else:
            raise ValueError(arg)
    return osc_string(address) + osc_string(tags) + payload


def osc_bundle(messages):
    data = osc_string("#bundle") + struct.pack(">Q", 1)  # time tag 1: immediately
    for m in messages:
        data += struct.pack(">i", len(m)) + m
    return data


def main():
    port = int(sys.argv[1])
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    target = ("127.0.0.1", port)
    sent = 0
    for line in sys.argv[2].splitlines():
        words = line.split()
        if not words:
            continue
        if words[0] == "send":
            sock.sendto(osc_message(words[1], words[2:]), target)
            sent += 1
        elif words[0] == "bundle":
            sock.sendto(osc_bundle([osc_message(a) for a in words[1:]]), target)
            sent += 1
        elif words[0] == "raw":
            sock.sendto(bytes.fromhex("".join(words[1:])), target)
            sent += 1
        elif words[0] == "burst":
            packets = [osc_message(a) for a in words[2:]]
            for i in range(int(words[1])):
                sock.sendto(packets[i % len(packets)], target)
                sent += 1
                if i % 50 == 49:
                    time.sleep(0.002)  # a desk's burst, not a flood past the socket's buffer
        elif words[0] == "sleep":
            time.sleep(float(words[1]))
        else:
            raise ValueError(line)
    print(sent)


main()
