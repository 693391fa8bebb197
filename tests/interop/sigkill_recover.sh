#!/usr/bin/env bash
# SIGKILLs 'replica run --record' at random moments: every file must recover ('replica recover'),
# open in @mcap/core with counts and values equal to 'replica inspect', and hold every frame older
# than the flush interval (plus scheduling slack) before the kill.
set -euo pipefail
replica="$1"
node_dir="$2"
work="$3"
kills="${4:-4}"
here="$(cd "$(dirname "$0")" && pwd)"
rm -rf "$work" && mkdir -p "$work"
# shellcheck source=need_mcap_core.sh
source "$here/need_mcap_core.sh"
flush_ms=200
slack_ms=1000 # a loaded 2-core CI machine may delay the writer thread
for k in $(seq "$kills"); do
    rec="$work/killed-$k.mcap"
    # Real-time pacing so that the recording's session clock follows the wall clock.
    "$replica" --log-level warn run --hal sim --output headless --frames 100000 --size 32x20 \
        --record "$rec" --record-flush-ms "$flush_ms" >/dev/null 2>&1 &
    pid=$!
    # Wait until the recording exists, then let it run a random 0.6-2.5 s.
    for _ in $(seq 100); do [ -s "$rec" ] && break; sleep 0.05; done
    start_ns=$(date +%s%N)
    sleep "$(awk -v r="$RANDOM" 'BEGIN { printf "%.2f", 0.6 + (r % 190) / 100 }')"
    kill -9 "$pid"
    killed_ns=$(date +%s%N)
    wait "$pid" 2>/dev/null || true
    code=0
    "$replica" --log-level warn recover "$rec" "$work/recovered-$k.mcap" >/dev/null || code=$?
    if [ "$code" -ne 0 ] && [ "$code" -ne 3 ]; then
        echo "FAIL: recover of $rec exited $code" >&2
        exit 1
    fi
    "$replica" --log-level warn inspect --json "$work/recovered-$k.mcap" > "$work/recovered-$k.json"
    node "$here/mcap_core_check.cjs" "$work/recovered-$k.mcap" "$work/recovered-$k.json"
    # The newest recovered frame must be no older than the flush interval plus slack before the kill.
    # Frame tick times are session times; the session started at most (kill - start) before the kill
    # plus the startup, so compare durations: recorded span >= ran - flush - slack.
    last_tick=$(node -e 'const j=require(process.argv[1]); console.log(j.last_frame ? j.last_frame.tick_ns : -1)' \
        "$work/recovered-$k.json")
    ran_ms=$(( (killed_ns - start_ns) / 1000000 ))
    kept_ms=$(( last_tick / 1000000 ))
    if [ "$kept_ms" -lt $(( ran_ms - flush_ms - slack_ms )) ]; then
        echo "FAIL: kill $k after ${ran_ms} ms of recording kept only ${kept_ms} ms of frames" >&2
        exit 1
    fi
    echo "ok: kill $k after ${ran_ms} ms: recovered ${kept_ms} ms of frames"
done
echo "PASS: $kills SIGKILLed recordings recovered and read by @mcap/core"
