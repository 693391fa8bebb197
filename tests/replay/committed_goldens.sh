#!/usr/bin/env bash
# Replays every committed recording under recordings/samples/ against its golden digests.
set -euo pipefail
replica="$1"
samples="$2"
work="$3"
rm -rf "$work" && mkdir -p "$work"
count=0
for rec in "$samples"/*.mcap; do
    golden="${rec%.mcap}.digests.json"
    if [ ! -f "$golden" ]; then
        echo "FAIL: $rec has no golden digests $golden" >&2
        exit 1
    fi
    name=$(basename "${rec%.mcap}")
    if ! "$replica" --log-level warn replay "$rec" --digests "$work/$name.json" --check "$golden"; then
        echo "FAIL: $rec no longer replays to $golden (see $work/$name.json)" >&2
        exit 1
    fi
    count=$((count + 1))
done
if [ "$count" -eq 0 ]; then
    echo "FAIL: no committed recordings found in $samples" >&2
    exit 1
fi
echo "PASS: $count committed recording(s) replay to their goldens"
