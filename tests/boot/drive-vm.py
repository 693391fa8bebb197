#!/usr/bin/env python3
"""Boots the boot-test guest under qemu and drives it over QMP (tests/boot/README.md).

drive-vm.py WORKDIR TIMEOUT_S -- QEMU_ARGS...
Starts qemu with the given arguments plus a serial log (WORKDIR/serial.log), a second serial port
the guest agent reads the host's word from, and a QMP socket. Prints each "BOOTTEST" line of the
guest as it comes; on "ready for screendump NAME" takes WORKDIR/screen-NAME.png with QMP
screendump and tells the guest to go on; on "done" (or at the timeout) ends qemu with QMP quit. Writes
WORKDIR/timings.json (host seconds from qemu's start to the first frame and to the end) and the
BOOTTEST lines to WORKDIR/report.txt.
Exit status: 0 when the guest said done and no "FAIL" line, 1 otherwise.
"""
import json
import os
import socket
import subprocess
import sys
import time

from PIL import Image


def qmp_connect(path, deadline):
    while True:
        try:
            s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            s.connect(path)
            break
        except OSError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.2)
    f = s.makefile("rw")
    json.loads(f.readline())  # greeting
    f.write(json.dumps({"execute": "qmp_capabilities"}) + "\n")
    f.flush()
    qmp_reply(f)
    return s, f


def qmp_reply(f):
    while True:
        msg = json.loads(f.readline())
        if "return" in msg or "error" in msg:
            return msg


def qmp(f, command, **args):
    f.write(json.dumps({"execute": command, "arguments": args}) + "\n")
    f.flush()
    return qmp_reply(f)


def main():
    work, timeout = sys.argv[1], float(sys.argv[2])
    qemu_args = sys.argv[sys.argv.index("--") + 1:]
    serial = os.path.join(work, "serial.log")
    qmp_sock = os.path.join(work, "qmp.sock")
    ctl_sock = os.path.join(work, "ctl.sock")
    for p in (serial, qmp_sock, ctl_sock):
        if os.path.exists(p):
            os.unlink(p)
    cmd = qemu_args + [
        "-serial", "file:" + serial,
        "-chardev", "socket,id=ctl,path=%s,server=on,wait=off" % ctl_sock,
        "-device", "isa-serial,chardev=ctl",
        "-qmp", "unix:%s,server=on,wait=off" % qmp_sock,
    ]
    start = time.monotonic()
    deadline = start + timeout
    vm = subprocess.Popen(cmd, stdin=subprocess.DEVNULL)
    s, f = qmp_connect(qmp_sock, start + 60)
    ctl = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    ctl.connect(ctl_sock)
    timings = {}
    report = open(os.path.join(work, "report.txt"), "w")
    failed = False
    done = False
    seen = 0
    while time.monotonic() < deadline and vm.poll() is None and not done:
        time.sleep(0.5)
        try:
            with open(serial, "rb") as log:
                log.seek(seen)
                chunk = log.read()
        except FileNotFoundError:
            continue
        # Whole lines only.
        end = chunk.rfind(b"\n")
        if end < 0:
            continue
        seen += end + 1
        for raw in chunk[: end + 1].splitlines():
            line = raw.decode("utf-8", "replace").strip()
            if "BOOTTEST" not in line:
                continue
            line = line[line.index("BOOTTEST"):]
            now = time.monotonic() - start
            print("[%7.1f s] %s" % (now, line), flush=True)
            report.write("[%7.1f s] %s\n" % (now, line))
            report.flush()
            if line.startswith("BOOTTEST FAIL"):
                failed = True
            if "first-frame at" in line:
                timings["host_s_to_first_frame"] = round(now, 1)
            if "ready for screendump" in line:
                # The recording's first frames come before its first light sample and are
                # black: take the screen again until it shows something (at most 5 minutes).
                name = line.split()[-1]
                screen = os.path.join(work, "screen-%s.png" % name)
                for attempt in range(150):
                    reply = qmp(f, "screendump", filename=screen, format="png")
                    if "error" in reply:
                        print("screendump failed: %s" % reply["error"], flush=True)
                        failed = True
                        break
                    if Image.open(screen).convert("RGB").getbbox() is not None:
                        break
                    time.sleep(2)
                taken = round(time.monotonic() - start, 1)
                timings.setdefault("host_s_to_screendump", taken)
                print("[%7.1f s] screendump %s taken (%d black before it)"
                      % (taken, os.path.basename(screen), attempt), flush=True)
                ctl.sendall(b"screendump-taken\n")
            if line.endswith("done"):
                done = True
    if not done:
        print("boot-test: the guest did not finish within %.0f s (serial log: %s)"
              % (timeout, serial), flush=True)
        failed = True
    if vm.poll() is None:
        try:
            qmp(f, "quit")
        except OSError:
            pass
    try:
        vm.wait(timeout=30)
    except subprocess.TimeoutExpired:
        vm.kill()
        vm.wait()
        print("boot-test: qemu did not quit on QMP quit; killed", flush=True)
        failed = True
    timings["host_s_total_vm"] = round(time.monotonic() - start, 1)
    with open(os.path.join(work, "timings.json"), "w") as out:
        json.dump(timings, out)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
