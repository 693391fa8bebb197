#!/usr/bin/env bash
# Replays every renderer golden (tests/replay/goldens/*.mcap) with --check and --tolerance: bit for
# bit on the Mesa that approved them; elsewhere within $REPLICA_GOLDEN_DE00 (default 1.0: the
# largest CIEDE2000 of any pixel of the reference frames), saying by how much.
set -euo pipefail
replica="$1"
goldens="$2"
work="$3"
tolerance="${REPLICA_GOLDEN_DE00:-1.0}"
rm -rf "$work" && mkdir -p "$work"
count=0
for rec in "$goldens"/*.mcap; do
    name=$(basename "${rec%.mcap}")
    golden="${rec%.mcap}.digests.json"
    [ -f "$golden" ] || { echo "FAIL: $rec has no golden digests" >&2; exit 1; }
    [ -n "$(ls "${rec%.mcap}.frames"/*.exr 2>/dev/null)" ] || { echo "FAIL: $rec has no reference frames" >&2; exit 1; }
    if ! "$replica" --log-level warn replay "$rec" --no-progress --check "$golden" \
        --tolerance "$tolerance" --digests "$work/$name.json" --mismatch-dir "$work/$name.mismatch"; then
        echo "FAIL: $rec is not within ΔE00 $tolerance of its golden (see $work)" >&2
        exit 1
    fi
    count=$((count + 1))
done
[ "$count" -gt 0 ] || { echo "FAIL: no renderer goldens in $goldens" >&2; exit 1; }
# The tolerance path itself: a golden whose frame 30 digest is altered differs bit for bit, so
# frame 30 is measured against its half-float reference frame, which the replayed frame equals
# up to half rounding (ΔE00 max well under 1, above 0). A plain --check fails and prints it;
# --tolerance 1.0 passes, saying by how much; --tolerance 0.00001 fails.
first=$(ls "$goldens"/*.mcap | head -1)
base="${first%.mcap}"
sed '/"frame": 30,/{s/"rgba": "0/"rgba": "Q/;s/"rgba": "[1-9a-f]/"rgba": "0/;s/"rgba": "Q/"rgba": "1/}' \
    "$base.digests.json" > "$work/altered.json"
! cmp -s "$base.digests.json" "$work/altered.json" || { echo "FAIL: could not alter frame 30" >&2; exit 1; }
if "$replica" --log-level warn replay "$first" --no-progress --check "$work/altered.json" \
    --reference "$base.frames" --mismatch-dir "$work/plain" > "$work/plain.txt" 2>&1; then
    echo "FAIL: --check accepted an altered digest" >&2; exit 1
fi
grep -q "^reference frame 30: ΔE00 mean" "$work/plain.txt" || { echo "FAIL: no ΔE00 of reference frame 30:" >&2; cat "$work/plain.txt" >&2; exit 1; }
"$replica" --log-level warn replay "$first" --no-progress --check "$work/altered.json" \
    --reference "$base.frames" --tolerance 1.0 > "$work/within.txt"
grep -q "1 of 62 frames differ .* within the tolerance 1.000 by" "$work/within.txt" \
    || { echo "FAIL: tolerance 1.0 did not pass with a margin:" >&2; cat "$work/within.txt" >&2; exit 1; }
if "$replica" --log-level warn replay "$first" --no-progress --check "$work/altered.json" \
    --reference "$base.frames" --tolerance 0.00001 > /dev/null 2> "$work/beyond.txt"; then
    echo "FAIL: a tolerance below the half-float rounding passed" >&2; exit 1
fi
grep -q "BEYOND the tolerance" "$work/beyond.txt" || { echo "FAIL: no BEYOND message" >&2; exit 1; }
cat "$work/within.txt"
echo "PASS: $count renderer golden(s) within ΔE00 $tolerance"
