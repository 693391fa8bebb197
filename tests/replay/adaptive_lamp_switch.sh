#!/usr/bin/env bash
# A sim run across a lamp change with the adaptive basis (re-encoded on the render thread at the
# frame the classifier confirms each lamp): live and replayed digests are equal bit for bit, the
# recording names its basis, and the rendering is not the fixed basis's.
set -euo pipefail
replica="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work"
# 10 Hz for 3 s of scenario time: lamp 0 confirmed at ~0.4 s, lamp 1 switched on at 2 s.
common=(--log-level warn run --hal sim --output headless --frames 30 --rate 10 --size 64x40 --fast)
"$replica" "${common[@]}" --basis adaptive_k6 --record "$work/adaptive.mcap" \
    --digests "$work/live.json"
"$replica" --log-level info replay "$work/adaptive.mcap" --clock fast --digests "$work/replay.json" \
    > "$work/replay.log" 2>&1
if ! cmp -s "$work/live.json" "$work/replay.json"; then
    echo "FAIL: the adaptive_k6 replay differs from the live run" >&2
    diff "$work/live.json" "$work/replay.json" | head -5 >&2
    exit 1
fi
if ! grep -q 'basis adaptive_k6' "$work/replay.log"; then
    echo "FAIL: the replay did not rebuild the adaptive_k6 renderer from the recording" >&2
    cat "$work/replay.log" >&2
    exit 1
fi
# The default for a new run is adaptive_k6: the same digests without --basis.
"$replica" "${common[@]}" --digests "$work/default.json"
if ! cmp -s "$work/live.json" "$work/default.json"; then
    echo "FAIL: a run without --basis does not render with adaptive_k6" >&2
    exit 1
fi
# The fixed basis renders the same frames differently once a lamp is known.
"$replica" "${common[@]}" --basis replica_k6 --digests "$work/fixed.json"
differing=$(diff <(grep -o '"xyz": "[0-9a-f]*"' "$work/live.json") \
    <(grep -o '"xyz": "[0-9a-f]*"' "$work/fixed.json") | grep -c '^<' || true)
if [ "$differing" -lt 20 ]; then
    echo "FAIL: only $differing of 30 frames differ between adaptive_k6 and replica_k6" >&2
    exit 1
fi
echo "PASS: adaptive_k6 live == replay across a lamp change; $differing of 30 frames differ from replica_k6"
