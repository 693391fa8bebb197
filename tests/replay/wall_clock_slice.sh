#!/usr/bin/env bash
# Field staff's time (issue 34): 'replay --from/--to' take wall-clock times against the
# recording's start, and the PNGs replay writes say their colour space and time.
# - an ISO 8601 instant (Z, and an offset) and a time of day (TZ=UTC0, and TZ=<+0530>-5:30) make
#   the same slice as the session seconds they name, with a line saying which second;
# - times outside the recording are refused (exit 2) with its span in both clocks; malformed
#   times (24:00, a day that does not exist, garbage) are refused (exit 2);
# - --frames-out and --snapshot PNGs: every chunk's CRC valid, iCCP a display profile that Little
#   CMS opens (through ctypes), tIME and tEXt "Creation Time" the frame's wall-clock time.
#   wall_clock_slice.sh REPLICA WORK
set -euo pipefail
replica="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }
"$replica" --log-level warn run --hal sim --output headless --frames 75 --size 64x40 --fast \
    --rate 30 --record "$work/rec.mcap" --thumbnail-hz 10 --snapshot "$work/run-snapshot.png" >/dev/null
"$replica" inspect --json "$work/rec.mcap" > "$work/inspect.json"
start=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["wall_clock_start_ns"])' \
    "$work/inspect.json")
# Session second s as an ISO instant ('Z' or '+01:00') or a time of day, to the nanosecond.
when() {
    python3 - "$start" "$1" "$2" <<'EOF'
import datetime, sys
start, s, form = int(sys.argv[1]), float(sys.argv[2]), sys.argv[3]
ns = start + round(s * 1e9)
secs, frac = divmod(ns, 10**9)
zone = {"Z": datetime.timezone.utc, "+01:00": datetime.timezone(datetime.timedelta(hours=1)),
        "utc": datetime.timezone.utc,
        "ist": datetime.timezone(datetime.timedelta(hours=5, minutes=30))}[form]
t = datetime.datetime.fromtimestamp(secs, zone)
if form in ("Z", "+01:00"):
    print(t.strftime("%Y-%m-%dT%H:%M:%S") + ".%09d" % frac + ("Z" if form == "Z" else form))
else:
    print(t.strftime("%H:%M:%S") + ".%09d" % frac)
EOF
}
slice() { # NAME ARGS...: the slice's digests into NAME.json, its stdout into NAME.out
    local name="$1"
    shift
    "$replica" --log-level warn replay "$work/rec.mcap" --no-progress "$@" \
        --digests "$work/$name.json" > "$work/$name.out"
}
slice seconds --from 1 --to 1.5
[ "$(grep -c '"frame"' "$work/seconds.json")" -eq 16 ] || fail "the seconds slice is not 16 frames"
! grep -q "session second" "$work/seconds.out" || fail "plain seconds print a mapping line"
from=$(when 1 Z)
to=$(when 1.5 +01:00)
slice iso --from "$from" --to "$to" --frames-out "$work/png" --snapshot "$work/snapshot.png"
cmp -s "$work/seconds.json" "$work/iso.json" || fail "the ISO slice differs from --from 1 --to 1.5"
grep -q -- "^--from $from is session second 1 (" "$work/iso.out" || fail "no line for --from: $(cat "$work/iso.out")"
grep -q -- "^--to $to is session second 1.5 (" "$work/iso.out" || fail "no line for --to: $(cat "$work/iso.out")"
from=$(when 1 utc)
to=$(when 1.5 utc)
TZ=UTC0 slice utc --from "$from" --to "$to"
cmp -s "$work/seconds.json" "$work/utc.json" || fail "the time-of-day slice (UTC) differs"
grep -q -- "^--from $from is session second 1 (.*+00:00, .*Z)$" "$work/utc.out" || fail "no UTC line: $(cat "$work/utc.out")"
from=$(when 1 ist)
TZ='<+0530>-5:30' slice ist --from "$from" --to 1.5
cmp -s "$work/seconds.json" "$work/ist.json" || fail "the time-of-day slice (+05:30) differs"
grep -q -- "+05:30, " "$work/ist.out" || fail "the line does not say the local time: $(cat "$work/ist.out")"
# Outside the recording, and malformed: exit 2 with a clear line.
refused() { # WHY ARGS...
    local why="$1" rc=0
    shift
    "$replica" --log-level warn replay "$work/rec.mcap" --no-progress "$@" > /dev/null \
        2> "$work/refused.err" || rc=$?
    [ "$rc" -eq 2 ] || fail "$* exited $rc, not 2"
    grep -q -- "$why" "$work/refused.err" || fail "$*: no '$why' in: $(cat "$work/refused.err")"
}
refused "outside the recording: the recording spans session seconds 0 to 2.467, .* to .* (.*Z to .*Z)" \
    --from "$(when -10 Z)"
TZ=UTC0 refused "outside the recording" --to "$(when 30 utc)"
refused "end of a day" --from 24:00
refused "leap second" --from 23:59:60
refused "no day 29" --from 2026-02-29T12:00:00Z
refused "not a time" --from soon
# The PNGs: CRCs, iCCP (Little CMS opens it), tIME and Creation Time.
# Frame 30 at 30 Hz: tick 30 * 33333333 ns.
python3 - "$work/png/frame-000030.png" "$(when 0.99999999 Z | sed 's/\(\.[0-9]\{3\}\)[0-9]*Z/\1Z/')" <<'EOF' ||
import ctypes, ctypes.util, struct, sys, zlib
path, created = sys.argv[1], sys.argv[2]
data = open(path, "rb").read()
assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
pos, chunks = 8, {}
while pos < len(data):
    n, kind = struct.unpack(">I4s", data[pos:pos + 8])
    body = data[pos + 8:pos + 8 + n]
    crc, = struct.unpack(">I", data[pos + 8 + n:pos + 12 + n])
    assert zlib.crc32(kind + body) == crc, f"bad CRC on {kind}"
    chunks.setdefault(kind.decode(), []).append(body)
    pos += 12 + n
for k in ("iCCP", "tIME", "tEXt"):
    assert k in chunks, f"no {k} chunk: {sorted(chunks)}"
name, rest = chunks["iCCP"][0].split(b"\0", 1)
assert rest[0] == 0, "iCCP compression method"
icc = zlib.decompress(rest[1:])
assert struct.unpack(">I", icc[:4])[0] == len(icc) and icc[36:40] == b"acsp", "not an ICC profile"
assert icc[12:16] == b"mntr" and icc[16:20] == b"RGB " and icc[20:24] == b"XYZ ", icc[12:24]
lcms = ctypes.CDLL(ctypes.util.find_library("lcms2") or "liblcms2.so.2")
lcms.cmsOpenProfileFromMem.restype = ctypes.c_void_p
h = lcms.cmsOpenProfileFromMem(icc, len(icc))
assert h, "Little CMS cannot open the iCCP profile"
lcms.cmsCloseProfile(ctypes.c_void_p(h))
texts = dict(t.split(b"\0", 1) for t in chunks["tEXt"])
assert texts[b"Creation Time"].decode() == created, (texts, created)
assert texts[b"Replica frame"].startswith(b"frame 30, session second 0.99999999, recording started "), texts
y, mo, d, h_, mi, s = struct.unpack(">HBBBBB", chunks["tIME"][0])
assert f"{y:04d}-{mo:02d}-{d:02d}T{h_:02d}:{mi:02d}:{s:02d}" == created[:19], (y, mo, d, h_, mi, s)
print(f"{path}: iCCP '{name.decode()}' ({len(icc)} bytes), {texts[b'Creation Time'].decode()}")
EOF
    fail "frame 30's PNG does not carry its colour space and time"
for png in "$work/snapshot.png" "$work/run-snapshot.png"; do
    python3 -c 'import sys; d=open(sys.argv[1],"rb").read(); sys.exit(0 if b"iCCP" in d and b"tIME" in d else 1)' \
        "$png" || fail "$png carries no iCCP and tIME"
done
echo "PASS: ISO and time-of-day slices equal the seconds slice (UTC, +01:00, +05:30) with their lines; outside and malformed times exit 2; PNGs carry iCCP (Little CMS opens it), tIME and Creation Time"
