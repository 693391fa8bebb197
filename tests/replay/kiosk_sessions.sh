#!/usr/bin/env bash
# The kiosk's session files hold what a --record file holds, each rotated file included: display
# digests, thumbnails, the eye and transforms, light decisions, the warnings logged since the
# process started (--uncalibrated's comes before any recording is open), and from the second file
# on the estimators' state at its start. Checked as field staff would: 'replica inspect' lists each
# channel with messages, and 'replica replay' of each file alone matches its own display digests.
set -uo pipefail
replica="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work/sessions"
cat > "$work/site.toml" <<TOML
[run]
hal = "sim"
[display]
output = "headless"
size = "96x60"
[recording]
directory = "$work/sessions"
rotate_bytes = 1048576
rotate_seconds = 10
keep_bytes = 1073741824
TOML
# 1 MiB is about 1000 frames of the sim scenario with thumbnails: two files or more. The loop
# checks the file's size on disk once a second, and the writer compresses on a thread of its own:
# on a loaded machine it can lag the frames so far that the first file is still under 1 MiB at the
# last check (the test once failed so at load 4-6). A run that slow lasts over 10 s, so the age
# rotates it instead: either way the session is two files or more.
if ! "$replica" run --kiosk --config "$work/site.toml" --frames 2200 --fast --uncalibrated \
        > "$work/run.log" 2>&1; then
    echo "FAIL: the kiosk run failed:" >&2
    cat "$work/run.log" >&2
    exit 1
fi
status=0
files=0
for rec in "$work"/sessions/*.mcap; do
    name=$(basename "${rec%.mcap}")
    files=$((files + 1))
    "$replica" inspect "$rec" --json > "$work/$name.inspect.json" 2> "$work/$name.inspect.log"
    "$replica" replay "$rec" --json > "$work/$name.replay.json" 2> "$work/$name.replay.log"
    replayed=$?
    if ! python3 - "$work/$name.inspect.json" "$work/$name.replay.json" "$replayed" "$name" <<'PY'
import json, sys
name = sys.argv[4]
inspect = json.load(open(sys.argv[1]))
channels = {topic: c["count"] for topic, c in inspect["channels"].items()}
bad = []
for topic in ("/replica/display_digest", "/replica/thumbnail", "/replica/eye", "/tf",
              "/replica/light", "/replica/log", "/replica/frame"):
    if channels.get(topic, 0) < 1:
        bad.append(f"{topic}: {channels.get(topic, 0)} messages")
if inspect["frames"] > 0 and inspect["frames"] != inspect["display_digests"]:
    bad.append(f"{inspect['frames']} frames but {inspect['display_digests']} display digests")
if int(sys.argv[3]) != 0:
    bad.append(f"replay exit {sys.argv[3]}")
else:
    shown = json.load(open(sys.argv[2])).get("display_digests", {})
    if shown.get("recorded", 0) < 1 or shown.get("differing", 1) != 0 or \
            shown.get("matched") != shown.get("recorded"):
        bad.append(f"replay against its own display digests: {shown}")
first = inspect.get("first_ns", 0)
if bad:
    print(f"FAIL: {name}: " + "; ".join(bad), file=sys.stderr)
    sys.exit(1)
print(f"{name}: {inspect['frames']} frames, all match their display digests; channels " +
      ", ".join(f"{t} {channels[t]}" for t in sorted(channels) if t.startswith("/replica") or t == "/tf"))
PY
    then
        status=1
        continue
    fi
done
# The warning logged before the recording opened is in every file (rotated ones included): the
# file's chunks unpacked (zstd) and searched for its text.
for rec in "$work"/sessions/*.mcap; do
    if ! python3 - "$rec" "--uncalibrated: driving a nominal" <<'PY'
import struct, subprocess, sys
data = open(sys.argv[1], "rb").read()
pos, found = 8, False
while pos + 9 <= len(data) and not found:
    op, n = data[pos], struct.unpack_from("<Q", data, pos + 1)[0]
    body = data[pos + 9:pos + 9 + n]
    pos += 9 + n
    if op != 0x06:  # a chunk: times, sizes, crc, compression, records
        found = sys.argv[2].encode() in body
        continue
    clen = struct.unpack_from("<I", body, 28)[0]
    compression = body[32:32 + clen].decode()
    records = body[32 + clen + 8:]
    if compression == "zstd":
        records = subprocess.run(["zstd", "-d", "-q", "-c"], input=records,
                                 stdout=subprocess.PIPE, check=True).stdout
    found = sys.argv[2].encode() in records
sys.exit(0 if found else 1)
PY
    then
        echo "FAIL: $(basename "$rec") lacks the --uncalibrated warning logged before it opened" >&2
        status=1
    fi
done
if [ "$files" -lt 2 ]; then
    echo "FAIL: the session did not rotate ($files file(s)); see $work/run.log" >&2
    status=1
fi
# From the second file on, each starts with the estimators' state (it replays alone).
for rec in $(ls "$work"/sessions/*.mcap | tail -n +2); do
    name=$(basename "${rec%.mcap}")
    if ! grep -q "its estimators start from the state it carries" "$work/$name.replay.log"; then
        echo "FAIL: $name (after a rotation) carries no state_at_start" >&2
        status=1
    fi
done
[ $status -eq 0 ] && echo "PASS: $files kiosk session files, each with every channel of a --record file"
exit $status
