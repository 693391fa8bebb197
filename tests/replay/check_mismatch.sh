#!/usr/bin/env bash
# 'replica replay --check' on a mismatch: writes the first differing frame and its ΔE00 difference
# image against the reference frame, and prints ΔE00 statistics. Identical images give ΔE00 0;
# a different reference image gives a positive ΔE00.
set -euo pipefail
replica="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work"
"$replica" --log-level warn run --hal sim --output headless --frames 24 --size 64x40 --fast \
    --record "$work/run.mcap" >/dev/null
# Golden digests and reference frames from a replay.
"$replica" --log-level warn replay "$work/run.mcap" --digests "$work/golden.json" \
    --save-frames "$work/golden.frames" >/dev/null
[ -f "$work/golden.frames/frame-000023.pfm" ] || { echo "FAIL: --save-frames wrote no frame 23" >&2; exit 1; }
# Alter the digest of frame 12 only: the image is the same, so ΔE00 must be exactly 0.
sed '/"frame": 12,/{s/"rgba": "0/"rgba": "Q/;s/"rgba": "[1-9a-f]/"rgba": "0/;s/"rgba": "Q/"rgba": "1/}' \
    "$work/golden.json" > "$work/altered.json"
if cmp -s "$work/golden.json" "$work/altered.json"; then
    echo "FAIL: could not alter the golden digests" >&2
    exit 1
fi
if "$replica" --log-level warn replay "$work/run.mcap" --check "$work/altered.json" \
    --reference "$work/golden.frames" --mismatch-dir "$work/same" > "$work/same.txt" 2> "$work/same.err"; then
    echo "FAIL: --check accepted an altered digest" >&2
    exit 1
fi
cat "$work/same.txt"
grep -q "first differing frame 12:" "$work/same.txt" || { echo "FAIL: wrong first differing frame" >&2; exit 1; }
grep -q "mean 0.000, median 0.000, p95 0.000, max 0.000" "$work/same.txt" \
    || { echo "FAIL: identical frames must give ΔE00 0" >&2; exit 1; }
for f in frame-000012.png frame-000012.pfm frame-000012-diff.png; do
    [ -s "$work/same/$f" ] || { echo "FAIL: --check did not write $f" >&2; exit 1; }
done
# A reference frame from later in the walk (the viewer moved): a real difference.
mkdir -p "$work/shifted"
cp "$work/golden.frames/frame-000023.pfm" "$work/shifted/frame-000012.pfm"
if "$replica" --log-level warn replay "$work/run.mcap" --check "$work/altered.json" \
    --reference "$work/shifted" --mismatch-dir "$work/moved" > "$work/moved.txt" 2>/dev/null; then
    echo "FAIL: --check accepted an altered digest" >&2
    exit 1
fi
cat "$work/moved.txt"
max=$(sed -n 's/.*max \([0-9.]*\);.*/\1/p' "$work/moved.txt")
if [ -z "$max" ] || awk -v m="$max" 'BEGIN { exit !(m <= 0) }'; then
    echo "FAIL: a different reference frame must give a positive ΔE00 (got '$max')" >&2
    exit 1
fi
# Without reference frames it still writes the frame and says why there are no statistics.
if "$replica" --log-level warn replay "$work/run.mcap" --check "$work/altered.json" \
    --mismatch-dir "$work/noref" > "$work/noref.txt" 2>/dev/null; then
    echo "FAIL: --check accepted an altered digest" >&2
    exit 1
fi
grep -q "no reference frame" "$work/noref.txt" && [ -s "$work/noref/frame-000012.png" ] \
    || { echo "FAIL: without references --check must still write the frame" >&2; exit 1; }
echo "PASS: --check mismatch reports frame 12 with ΔE00 0 for the same image and max $max for another"
