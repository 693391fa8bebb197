#!/usr/bin/env bash
# The kiosk runs with --frames 0 until it is told to stop: SIGTERM (systemd) and SIGINT (Ctrl-C)
# must end it with exit 0 and a closed, complete recording that replays to the same digests.
set -uo pipefail
replica="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work"
status=0
for sig in TERM INT; do
    rec="$work/endless-$sig.mcap"
    "$replica" run --hal sim --frames 0 --fast --size 96x60 --record "$rec" \
        --digests "$work/live-$sig.json" 2>"$work/run-$sig.log" &
    pid=$!
    # Wait until the loop is drawing (its first line is frame 0's; the recording file itself
    # exists from before the shading passes are built, which under ASan on a loaded machine took
    # over a second), then stop it.
    for _ in $(seq 1 600); do
        grep '\[loop\]' "$work/run-$sig.log" >/dev/null 2>&1 && break
        sleep 0.1
    done
    sleep 1
    kill -"$sig" "$pid"
    wait "$pid"
    code=$?
    if [ "$code" -ne 0 ]; then
        echo "FAIL: SIG$sig ended replica run with exit $code" >&2
        cat "$work/run-$sig.log" >&2
        status=1
        continue
    fi
    if ! grep -q "stop requested" "$work/run-$sig.log"; then
        echo "FAIL: SIG$sig: the loop did not report the stop" >&2
        status=1
    fi
    frames=$("$replica" inspect "$rec" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["frames"])' 2>/dev/null || echo 0)
    if [ "${frames:-0}" -lt 1 ]; then
        echo "FAIL: SIG$sig: the recording holds no frames" >&2
        status=1
        continue
    fi
    if ! "$replica" replay "$rec" --clock fast --digests "$work/replay-$sig.json" \
            --check "$work/live-$sig.json" >/dev/null 2>"$work/replay-$sig.log"; then
        echo "FAIL: SIG$sig: the recording does not replay to the live digests" >&2
        cat "$work/replay-$sig.log" >&2
        status=1
        continue
    fi
    echo "ok: SIG$sig -> exit 0, $frames frames recorded and replayed bit-exactly"
done
# Start-up: a stop signal at any point of it (recovering the sessions a crash left, planning a
# scene that has no plan, the warm-up) ends the run within a second, not after it (52.8 s was
# measured for planning). The scene is the shipped ColorChecker without its plan, so that the
# kiosk plans it; the signal comes after each delay in turn. Bound 5 s (timing noise); the figures
# are printed.
mkdir -p "$work/scene" "$work/sessions"
data="$(cd "$(dirname "$0")/../../data" && pwd)"
cp "$data/scenes/colorchecker/"{scene.json,channels.exr,height.exr,material.exr} "$work/scene/"
cat >"$work/site.toml" <<TOML
[run]
hal = "sim"
[display]
output = "headless"
size = "96x60"
[scene]
dir = "$work/scene"
[render]
planner = true
[recording]
directory = "$work/sessions"
TOML
for delay in 0.5 1.5 4 8; do
    rm -rf "$work/cache"
    REPLICA_PLAN_CACHE="$work/cache" "$replica" run --kiosk --config "$work/site.toml" \
        >"$work/startup-$delay.log" 2>&1 &
    pid=$!
    sleep "$delay"
    t0=$(date +%s.%N)
    kill -TERM "$pid"
    wait "$pid"
    code=$?
    t=$(python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.2f}')" "$t0" "$(date +%s.%N)")
    echo "start-up, SIGTERM after ${delay} s: exit $code ${t} s later" \
        "($(grep -c . "$work/startup-$delay.log") log lines)"
    # 143: the signal's default action, before the handlers were installed (nothing open yet).
    if { [ "$code" -ne 0 ] && [ "$code" -ne 143 ]; } ||
        ! python3 -c "import sys; sys.exit(0 if float(sys.argv[1]) < 5 else 1)" "$t"; then
        echo "FAIL: SIGTERM ${delay} s into start-up: exit $code after ${t} s" >&2
        cat "$work/startup-$delay.log" >&2
        status=1
    fi
done
exit $status
