"""A client that tries to take the dashboard's controls away, for
dashboard_control_path.sh (and, with --bench, for the stop latency in
docs/results/): 50 open event streams read continuously and 50 connections
that send their headers a byte at a time, then a stop with the token and an
empty body. Checks what the server answers; prints the stop's latency."""

import argparse
import json
import select
import socket
import sys
import threading
import time

PATIENCE = 20.0  # a bound for waits, not a timing check


def connect(port):
    s = socket.create_connection(("127.0.0.1", port), timeout=PATIENCE)
    return s


def read_head(s):
    """Status code and headers of a response, from a blocking socket."""
    data = b""
    while b"\r\n\r\n" not in data:
        chunk = s.recv(4096)
        if not chunk:
            raise AssertionError("connection closed before a response: %r" % data)
        data += chunk
    head, _, rest = data.partition(b"\r\n\r\n")
    return int(head.split(b" ", 2)[1]), head.decode("latin-1"), rest


def request(port, method, path, headers, body=None):
    """One request on its own connection: status and body."""
    s = connect(port)
    lines = ["%s %s HTTP/1.1" % (method, path)] + ["%s: %s" % kv for kv in headers.items()]
    lines.append("Connection: close")
    s.sendall(("\r\n".join(lines) + "\r\n\r\n").encode() + (body or b""))
    status, head, rest = read_head(s)
    while True:
        chunk = s.recv(65536)
        if not chunk:
            break
        rest += chunk
    s.close()
    return status, rest


def open_stream(port):
    s = connect(port)
    s.sendall(b"GET /api/stream HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n\r\n" % port)
    status, head, rest = read_head(s)
    return s, status, rest


class Drain(threading.Thread):
    """Reads every open stream as a browser would."""

    def __init__(self, socks):
        super().__init__(daemon=True)
        self.socks = list(socks)
        self.quit = False
        self.bytes = 0

    def run(self):
        for s in self.socks:
            s.setblocking(False)
        while not self.quit and self.socks:
            ready, _, _ = select.select(self.socks, [], [], 0.1)
            for s in ready:
                try:
                    chunk = s.recv(65536)
                except BlockingIOError:
                    continue
                except OSError:
                    chunk = b""
                if not chunk:
                    self.socks.remove(s)
                self.bytes += len(chunk)


class Slow(threading.Thread):
    """Connections that send a request line at once, then its headers a byte
    every `gap` s; notes when the server drops each."""

    HEADERS = b"Host: 127.0.0.1\r\nX-Padding: " + b"a" * 10000

    def __init__(self, port, count, gap):
        super().__init__(daemon=True)
        self.start_t = time.monotonic()
        self.socks = []
        for _ in range(count):
            s = connect(port)
            s.sendall(b"GET /api/state HTTP/1.1\r\n")
            s.setblocking(False)
            self.socks.append(s)
        self.gap = gap
        self.dropped = [None] * count
        self.quit = False

    def run(self):
        i = 0
        while not self.quit and i < len(self.HEADERS) and None in self.dropped:
            for k, s in enumerate(self.socks):
                if self.dropped[k] is not None:
                    continue
                try:
                    s.send(self.HEADERS[i : i + 1])
                    if s.recv(4096) == b"":
                        raise ConnectionResetError
                except BlockingIOError:
                    pass
                except OSError:
                    self.dropped[k] = time.monotonic() - self.start_t
            i += 1
            time.sleep(self.gap)


def stop(port, token, json_body=False):
    """POST /api/stop with the token and no body (no Content-Length), or {}."""
    headers = {"Host": "127.0.0.1:%d" % port, "Authorization": "Bearer " + token}
    if json_body:
        headers.update({"Content-Type": "application/json", "Content-Length": "2"})
    t0 = time.monotonic()
    status, body = request(port, "POST", "/api/stop", headers, b"{}" if json_body else None)
    return status, body, time.monotonic() - t0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("port", type=int)
    ap.add_argument("token")
    ap.add_argument("--streams", type=int, default=50)
    ap.add_argument("--slow", type=int, default=50)
    ap.add_argument("--bench", action="store_true", help="only measure the stop's latency")
    ap.add_argument("--json-body", action="store_true", help="stop with {} as its body")
    a = ap.parse_args()
    port, token = a.port, a.token
    host = "127.0.0.1:%d" % port

    if not a.bench:
        # A page whose DNS name was rebound to 127.0.0.1 sends its own name.
        status, body = request(port, "GET", "/api/state", {"Host": "attacker.example:%d" % port})
        assert status == 403, (status, body[:200])
        assert b"attacker.example" in body, body
        status, _ = request(port, "GET", "/api/state", {"Host": host})
        assert status == 200, status
        status, _ = request(port, "GET", "/api/state", {"Host": "localhost:%d" % port})
        assert status == 200, status

    streams = []
    for _ in range(a.streams):
        s, status, rest = open_stream(port)
        assert status == 200, "stream %d: %d" % (len(streams) + 1, status)
        streams.append(s)
    if not a.bench:
        s, status, rest = open_stream(port)
        assert status == 503, "stream %d beyond the limit: %d" % (a.streams + 1, status)
        assert b"too many open streams" in rest or b"too many" in s.recv(4096), rest
        s.close()
    drain = Drain(streams)
    drain.start()
    slow = Slow(port, a.slow, 0.1) if a.slow else None
    if slow:
        slow.start()
        time.sleep(0.5)  # every slow connection has sent part of its headers

    status, body, latency = stop(port, token, a.json_body)
    print("stop with %d streams and %d slow-header connections: HTTP %d in %.1f ms"
          % (a.streams, a.slow, status, latency * 1000.0))
    assert status == 200, (status, body)
    assert json.loads(body) == {"ok": True}, body

    if slow and not a.bench:
        give_up = time.monotonic() + PATIENCE
        while None in slow.dropped and time.monotonic() < give_up:
            time.sleep(0.1)
        assert None not in slow.dropped, "%d slow-header connections were never dropped" % (
            slow.dropped.count(None))
        print("slow-header connections dropped after %s s"
              % ", ".join("%.1f" % t for t in sorted(slow.dropped)))
    drain.quit = True
    if slow:
        slow.quit = True


if __name__ == "__main__":
    try:
        main()
    except AssertionError as e:
        print("FAIL:", e)
        sys.exit(1)
    except (socket.timeout, ConnectionError) as e:
        print("FAIL: no answer:", e)
        sys.exit(1)
