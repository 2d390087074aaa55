"""SMPTE linear timecode written into a WAV file from the standard's bit
layout: 80 bits a frame, least significant bit first (frame units and tens,
seconds, minutes, hours in BCD with user bits between, flags, and the sync
word 0011 1111 1111 1101 at bits 64-79), biphase-mark coded: a transition
at every bit cell's start, and one more in its middle for a 1."""
import struct
import wave

RATE = 48000


def frame_bits(h, m, s, f):
    bits = [0] * 80
    def put(at, value, width):
        for i in range(width):
            bits[at + i] = (value >> i) & 1
    put(0, f % 10, 4)
    put(8, f // 10, 2)
    put(16, s % 10, 4)
    put(24, s // 10, 3)
    put(32, m % 10, 4)
    put(40, m // 10, 3)
    put(48, h % 10, 4)
    put(56, h // 10, 2)
    for i, b in enumerate([0, 0] + [1] * 12 + [0, 1]):
        bits[64 + i] = b
    return bits


class LtcWriter:
    def __init__(self, fps):
        self.fps = fps
        self.samples = []
        self.level = 1
        self.cell = RATE / fps / 80.0  # samples per bit
        self.pos = 0.0

    def _half(self, length):
        end = self.pos + length
        while len(self.samples) < round(end):
            self.samples.append(self.level)
        self.pos = end

    def frames(self, start, count):
        """`count` frames from (h, m, s, f)."""
        h, m, s, f = start
        for _ in range(count):
            for bit in frame_bits(h, m, s, f):
                self.level = -self.level
                if bit:
                    self._half(self.cell / 2)
                    self.level = -self.level
                    self._half(self.cell / 2)
                else:
                    self._half(self.cell)
            f += 1
            if f == self.fps:
                f, s = 0, s + 1
                if s == 60:
                    s, m = 0, m + 1
                    if m == 60:
                        m, h = 0, h + 1

    def silence(self, count):
        for _ in range(count):
            self._half_silent(RATE / self.fps)

    def _half_silent(self, length):
        end = self.pos + length
        while len(self.samples) < round(end):
            self.samples.append(0)
        self.pos = end

    def write(self, path):
        with wave.open(path, "wb") as w:
            w.setnchannels(1)
            w.setsampwidth(2)
            w.setframerate(RATE)
            w.writeframes(b"".join(struct.pack("<h", 12000 * v) for v in self.samples))
