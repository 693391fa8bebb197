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
echo "PASS: $count renderer golden(s) within ΔE00 $tolerance"
