#!/usr/bin/env bash
# Frame N from its state alone (issue 20): 'replay --from t --to t' runs the state stage over the
# samples of frames 0..N-1 without drawing them (state/: the light, eye and tilt estimators) and
# draws frame N with a fresh renderer. Its digests must be the golden's for frame N, for every
# committed recording: every 10th frame, and every frame around the lamp selector's turn at 2 s
# (new light, re-encoding, the held tilt re-taken, the diffuse term's sliced refresh after it).
set -euo pipefail
replica="$1"
samples="$2"
work="$3"
rm -rf "$work" && mkdir -p "$work"
checked=0
for rec in "$samples"/*.mcap; do
    golden="${rec%.mcap}.digests.json"
    name=$(basename "${rec%.mcap}")
    # frame, its tick in seconds, xyz, rgba: one line each, the seconds written here rather than
    # by a Python start per frame. (--check writes the digests in the golden's own format
    # version, so that they compare.)
    frames=$(python3 -c '
import json, sys
for f in json.load(open(sys.argv[1]))["frames"]:
    n = f["frame"]
    if n % 10 == 3 or 117 <= n <= 127:
        print(n, repr(f["tick_ns"] / 1e9), f["xyz"], f["rgba"])
' "$golden")
    while read -r n t xyz rgba; do
        out="$work/$name-$n.json"
        if ! "$replica" --log-level error replay "$rec" --from "$t" --to "$t" --digests "$out" \
                --check "$golden" > "$work/$name-$n.log" 2>&1; then
            echo "FAIL: $name frame $n: replay --from $t --to $t failed:" >&2
            cat "$work/$name-$n.log" >&2
            exit 1
        fi
        got=$(python3 -c '
import json, sys
fs = json.load(open(sys.argv[1]))["frames"]
print(len(fs), fs[0]["frame"] if fs else -1, fs[0]["xyz"] if fs else "", fs[0]["rgba"] if fs else "")
' "$out")
        if [ "$got" != "1 $n $xyz $rgba" ]; then
            echo "FAIL: $name frame $n drawn from its state alone: got (frames, frame, xyz," \
                 "rgba) = $got, the whole replay's golden is $n $xyz $rgba" >&2
            exit 1
        fi
        checked=$((checked + 1))
    done <<< "$frames"
done
if [ "$checked" -lt 60 ]; then
    echo "FAIL: only $checked frames checked (committed recordings missing?)" >&2
    exit 1
fi
echo "PASS: $checked frames of the committed recordings drawn from their state alone match the goldens"
