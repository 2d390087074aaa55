"""animrt serve under a stand-in for systemd: a unix datagram socket as
NOTIFY_SOCKET, WATCHDOG_USEC set, every message read with its arrival time.

Usage: service_notify.py OUT.txt WATCHDOG_USEC SECONDS [--term-after-ready S] -- COMMAND...
Writes one line per message ("TIME MESSAGE", seconds since the start, and
"exit CODE" when the command ended) until it ended or SECONDS passed (then
it is killed: "killed"). With --term-after-ready, SIGTERM is sent S seconds
after READY=1.
"""

import os
import signal
import socket
import subprocess
import sys
import tempfile
import time

out_path, watchdog_usec, seconds = sys.argv[1], sys.argv[2], float(sys.argv[3])
rest = sys.argv[4:]
term_after = None
if rest[0] == "--term-after-ready":
    term_after = float(rest[1])
    rest = rest[2:]
command = rest[rest.index("--") + 1:]

folder = tempfile.mkdtemp()
path = os.path.join(folder, "notify")
sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
sock.bind(path)
sock.settimeout(0.05)
env = dict(os.environ, NOTIFY_SOCKET=path, WATCHDOG_USEC=watchdog_usec)
start = time.monotonic()
proc = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
lines = []
ready_at = None
termed = False
while True:
    now = time.monotonic() - start
    try:
        data = sock.recv(4096).decode()
        for message in data.split("\n"):
            if message:
                lines.append(f"{now:.3f} {message}")
                if message == "READY=1":
                    ready_at = now
    except socket.timeout:
        pass
    if term_after is not None and ready_at is not None and not termed and now > ready_at + term_after:
        proc.send_signal(signal.SIGTERM)
        lines.append(f"{now:.3f} sent SIGTERM")
        termed = True
    code = proc.poll()
    if code is not None:
        # What was sent before it ended is in the socket still.
        sock.settimeout(0.2)
        try:
            while True:
                for message in sock.recv(4096).decode().split("\n"):
                    if message:
                        lines.append(f"{now:.3f} {message}")
        except socket.timeout:
            pass
        lines.append(f"{now:.3f} exit {code}")
        break
    if now > seconds:
        proc.kill()
        proc.wait()
        lines.append(f"{now:.3f} killed")
        break
with open(out_path, "w") as f:
    f.write("\n".join(lines) + "\n")
os.unlink(path)
os.rmdir(folder)
