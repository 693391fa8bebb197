#!/usr/bin/env bash
# Type=notify: 'replica run' sends READY=1 after its first frame, then WATCHDOG=1 pings from the
# frame loop (WatchdogSec given as $WATCHDOG_USEC, as systemd does), and STOPPING=1 at the end;
# received here on a datagram socket standing in for systemd's $NOTIFY_SOCKET.
#   sd_notify.sh REPLICA WORK_DIR
set -uo pipefail
replica="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work"
python3 - "$replica" "$work" <<'PY'
import os, socket, subprocess, sys
replica, work = sys.argv[1], sys.argv[2]
path = os.path.join(work, "notify.sock")
sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
sock.bind(path)
sock.settimeout(60)
env = dict(os.environ, NOTIFY_SOCKET=path, WATCHDOG_USEC="400000")
env.pop("WATCHDOG_PID", None)
# 90 frames at 60 Hz on the wall clock: 1.5 s, pings due every 0.1 s.
proc = subprocess.Popen([replica, "--log-level", "warn", "run", "--hal", "sim", "--output",
                         "headless", "--size", "16x10", "--frames", "90"], env=env)
messages = []
while True:
    try:
        data = sock.recv(4096).decode()
    except socket.timeout:
        sys.exit("FAIL: no notification within 60 s")
    messages.append(data)
    if "STOPPING=1" in data:
        break
proc.wait()
if proc.returncode != 0:
    sys.exit(f"FAIL: replica exited {proc.returncode}")
first = messages[0].split("\n")
if "READY=1" not in first:
    sys.exit(f"FAIL: the first notification is not READY=1: {messages[0]!r}")
pings = sum("WATCHDOG=1" in m for m in messages[1:])
if pings < 1:
    sys.exit(f"FAIL: no WATCHDOG=1 after READY=1 in 1.5 s: {messages!r}")
status = [l for l in messages[-2].split("\n") if l.startswith("STATUS=")]
print(f"ok: READY=1 first, then {pings} watchdog pings, STOPPING=1 last; {status}")
PY
