#!/usr/bin/env bash
# 'replica probe' against a fake IIO accelerometer (tilted back 30 degrees) and a UDP sender
# speaking opentrack's protocol; no spectrometer is attached here and the lamp selector names a GPIO
# chip that does not exist, so the report says so and the exit status is 1.
set -uo pipefail
replica="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work/iio/iio:device0"
dev="$work/iio/iio:device0"
echo lis3dh > "$dev/name"
# Reaction to gravity for a panel leaning back 30 degrees: (0, g cos 30, g sin 30) in panel axes.
python3 - "$dev" <<'PY'
import math, sys
d = sys.argv[1]
scale = 0.001
g = 9.80665
for axis, v in (("x", 0.0), ("y", g * math.cos(math.radians(30))), ("z", g * math.sin(math.radians(30)))):
    open(f"{d}/in_accel_{axis}_raw", "w").write(f"{round(v / scale)}\n")
open(f"{d}/in_accel_scale", "w").write(f"{scale}\n")
PY
# A HID eye tracker's sysfs entry (its report descriptor: Usage Page 0x12, Eye Tracker, head
# position X, Y, Z) without a device node: listed, and reported as not openable.
mkdir -p "$work/hidraw/hidraw7/device"
printf '\x05\x12\x09\x01\xa1\x01\x09\x27\xa1\x00\x09\x21\x09\x22\x09\x23\x75\x10\x95\x03\x81\x02\xc0\xc0' \
    > "$work/hidraw/hidraw7/device/report_descriptor"
printf 'HID_ID=0003:00002104:00000127\nHID_NAME=Acme Eye Tracker\n' > "$work/hidraw/hidraw7/device/uevent"
port=$(python3 -c 'import socket; s=socket.socket(socket.AF_INET, socket.SOCK_DGRAM); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
# The sender runs until the probe is done (python can take a second to start on a busy machine,
# so the probe starts only once the sender is sending).
python3 - "$port" "$work/sender-ready" <<'PY' &
import socket, struct, sys, time
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
end = time.time() + 60.0
first = True
while time.time() < end:
    s.sendto(struct.pack("<6d", 2.0, 45.0, 60.0, 0.0, 0.0, 0.0), ("127.0.0.1", int(sys.argv[1])))
    if first:
        open(sys.argv[2], "w").close()
        first = False
    time.sleep(0.01)
PY
sender=$!
for _ in $(seq 1 300); do
    [ -e "$work/sender-ready" ] && break
    sleep 0.1
done
"$replica" probe --json --iio-root "$work/iio" --tracker-port "$port" --tracker-wait 1 \
    --lamp-gpio replica-no-such-gpiochip:17,27,22 --gpio-dev "$work" --hidraw-sysfs "$work/hidraw" \
    > "$work/probe.json" 2> "$work/probe.log"
code=$?
kill "$sender" 2>/dev/null
wait "$sender" 2>/dev/null
python3 - "$work/probe.json" "$code" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
code = int(sys.argv[2])
fail = []
a = r["accelerometer"]
if not a.get("ok") or abs(a["tilt_deg"] - 30.0) > 0.05:
    fail.append(f"accelerometer: {a}")
t = r["tracker"]
if not t.get("found") or t["poses"] < 10:
    fail.append(f"tracker: {t}")
else:
    eye = t["eye_tracker_m"]
    if abs(eye[0] - 0.02) > 1e-12 or abs(eye[1] - 0.45) > 1e-12 or abs(eye[2] + 0.60) > 1e-12:
        fail.append(f"tracker eye {eye}")
s = r["spectrometer"]
if s.get("found") or "2457:101e" not in s.get("error", ""):
    fail.append(f"spectrometer: {s}")
l = r["lamp_selector"]
if (not l["configured"] or l.get("found") or l["chips"] != []
        or "'replica-no-such-gpiochip' not found" not in l.get("error", "")):
    fail.append(f"lamp selector: {l}")
h = r["hid_trackers"]
if (len(h) != 1 or h[0]["node"] != "/dev/hidraw7" or h[0]["id"] != "2104:0127"
        or h[0]["name"] != "Acme Eye Tracker" or h[0]["ok"] or "/dev/hidraw7" not in h[0]["error"]):
    fail.append(f"hid trackers: {h}")
if r["all_found"] or code != 1:
    fail.append(f"all_found {r['all_found']} exit {code}")
if fail:
    print("FAIL: " + "; ".join(fail), file=sys.stderr)
    sys.exit(1)
print(f"ok: tilt {a['tilt_deg']:.3f} deg, {t['poses']} poses, spectrometer and lamp selector chip reported missing, exit {code}")
PY
