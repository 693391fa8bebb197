#!/usr/bin/env bash
# Each file of a rotated kiosk session replays alone, bit for bit, to what the panel showed live:
# files 2, 3, ... carry the estimators' state at their head (the run configuration's
# "state_at_start": the classifier's hysteresis, the lamp selector's arbitration, the adaptive
# encoding, the held eye and tilts), which replay restores before their first frame. Without it
# their first frames differed (the classifier started over in direct-sensor mode).
set -euo pipefail
replica="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work/sessions"
cat > "$work/site.toml" <<TOML
[run]
hal = "sim"
rate_hz = 60.0
[display]
output = "headless"
size = "96x60"
[recording]
directory = "$work/sessions"
rotate_bytes = 1048576
rotate_seconds = 3600
keep_bytes = 1073741824
flush_ms = 500
TOML
# 1 MiB is about 1000 frames of the sim scenario: three files or more.
"$replica" --log-level warn run --kiosk --config "$work/site.toml" --frames 2600 --fast \
    --lamp-selector sim --digests "$work/live.json" > "$work/run.log" 2>&1 || {
    echo "FAIL: the kiosk run failed:" >&2
    cat "$work/run.log" >&2
    exit 1
}
files=0
rotated=0
for rec in "$work"/sessions/*.mcap; do
    name=$(basename "${rec%.mcap}")
    if ! "$replica" --log-level info replay "$rec" --digests "$work/$name.json" \
            > "$work/$name.log" 2>&1; then
        echo "FAIL: $rec does not replay alone:" >&2
        cat "$work/$name.log" >&2
        exit 1
    fi
    # Every frame the file holds against the live run's digest of that frame.
    result=$(python3 - "$work/live.json" "$work/$name.json" "$work/$name.log" <<'PY'
import json, sys
live = {f["frame"]: f for f in json.load(open(sys.argv[1]))["frames"]}
got = json.load(open(sys.argv[2]))["frames"]
bad = [f["frame"] for f in got
       if f["frame"] not in live or (f["xyz"], f["rgba"]) != (live[f["frame"]]["xyz"], live[f["frame"]]["rgba"])]
carried = "its estimators start from the state it carries" in open(sys.argv[3]).read()
print(len(got), got[0]["frame"] if got else -1, len(bad), ",".join(map(str, bad[:5])) or "-",
      int(carried))
PY
)
    read -r count first nbad badlist state <<< "$result"
    if [ "$nbad" != "0" ]; then
        echo "FAIL: $name (frames $first.., $count frames) replayed alone differs from the live run" \
             "in $nbad frames, first ones: $badlist" >&2
        exit 1
    fi
    echo "$name: frames $first..$((first + count - 1)) equal to the live run (state at head: $state)"
    files=$((files + 1))
    if [ "$first" -gt 0 ]; then
        rotated=$((rotated + 1))
        if [ "$state" != "1" ]; then
            echo "FAIL: $name starts at frame $first but carries no state_at_start" >&2
            exit 1
        fi
    fi
done
if [ "$rotated" -lt 1 ]; then
    echo "FAIL: the session did not rotate ($files file(s)); see $work/run.log" >&2
    exit 1
fi
echo "PASS: $files session files ($rotated after a rotation) each replay alone to the live frames"
