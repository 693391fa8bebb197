#!/usr/bin/env bash
# A site file the kiosk cannot use: the kiosk refuses it with exit 78 and the problem's file, line
# and key, and shows a service screen through the configured output (headless here: the frame is
# the --snapshot), not black. Run without end (as the service does) it holds the screen, up for
# systemd, until it is stopped, then exits 78, within a second of SIGTERM.
set -uo pipefail
replica="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work"
status=0
cat >"$work/site.toml" <<TOML
[run]
hal = "sim"
[display]
output = "headless"
size = "320x200"
[defaults]
lamp = "sodium"
TOML
"$replica" run --kiosk --config "$work/site.toml" --frames 3 --snapshot "$work/screen.png" \
    >"$work/run.log" 2>&1
code=$?
if [ $code -ne 78 ]; then
    echo "FAIL: exit $code, expected 78" >&2
    cat "$work/run.log" >&2
    status=1
fi
grep -qF "$work/site.toml:7: defaults.lamp: \"sodium\": not a lamp of booth" "$work/run.log" || {
    echo "FAIL: the refusal does not name the file, line and key:" >&2
    cat "$work/run.log" >&2
    status=1
}
# The screen: the frame size the site file gives, the background and lit text (not black, not
# blank), the text in the top part.
python3 - "$work/screen.png" <<'PY' || status=1
import struct, sys, zlib
data = open(sys.argv[1], "rb").read()
assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
pos, idat, w, h, ctype = 8, b"", 0, 0, 0
while pos < len(data):
    n, kind = struct.unpack(">I4s", data[pos:pos + 8])
    body = data[pos + 8:pos + 8 + n]
    if kind == b"IHDR":
        w, h, depth, ctype = struct.unpack(">IIBB", body[:10])
    elif kind == b"IDAT":
        idat += body
    pos += 12 + n
raw = zlib.decompress(idat)
bpp = {2: 3, 6: 4}[ctype]
stride = w * bpp
rows, prev = [], bytearray(stride)
for y in range(h):
    f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
    for i in range(stride):
        a = line[i - bpp] if i >= bpp else 0
        b, c = prev[i], prev[i - bpp] if i >= bpp else 0
        p = a + b - c
        pred = [0, a, b, (a + b) // 2,
                a if abs(p - a) <= abs(p - b) and abs(p - a) <= abs(p - c) else
                (b if abs(p - b) <= abs(p - c) else c)][f]
        line[i] = (line[i] + pred) & 0xFF
    rows.append(line)
    prev = line
bg = tuple(rows[0][:3])
lit = [(x, y) for y in range(h) for x in range(w) if tuple(rows[y][x * bpp:x * bpp + 3]) != bg]
frac = len(lit) / (w * h)
ok = (w, h) == (320, 200) and bg != (0, 0, 0) and 0.01 < frac < 0.5 and min(y for _, y in lit) < 20
print(f"service screen: {w}x{h}, background {bg}, {100 * frac:.1f} % text pixels")
if not ok:
    print("FAIL: the service screen is not a frame of text", file=sys.stderr)
    sys.exit(1)
PY
# Without end: held until SIGTERM, then exit 78 within a second (bound 5 s; the figure printed).
"$replica" run --kiosk --config "$work/site.toml" >"$work/held.log" 2>&1 &
pid=$!
for _ in $(seq 1 300); do
    grep -q "the service screen shows the problem" "$work/held.log" 2>/dev/null && break
    sleep 0.1
done
sleep 0.5
if ! kill -0 "$pid" 2>/dev/null; then
    echo "FAIL: the endless kiosk did not hold its service screen" >&2
    cat "$work/held.log" >&2
    status=1
else
    t0=$(date +%s.%N)
    kill -TERM "$pid"
    wait "$pid"
    code=$?
    t=$(python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.2f}')" "$t0" "$(date +%s.%N)")
    echo "held service screen: exit $code ${t} s after SIGTERM"
    [ $code -eq 78 ] || { echo "FAIL: exit $code after SIGTERM, expected 78" >&2; status=1; }
    python3 -c "import sys; sys.exit(0 if float(sys.argv[1]) < 5 else 1)" "$t" ||
        { echo "FAIL: ${t} s to stop" >&2; status=1; }
fi
[ $status -eq 0 ] && echo "PASS: exit 78 naming file, line and key; a service screen, held until stopped"
exit $status
