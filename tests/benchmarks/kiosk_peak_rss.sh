#!/usr/bin/env bash
# The kiosk's peak memory, for replica.service's MemoryHigh/MemoryMax (docs/appliance.md,
# "Resource bounds"). For every shipped scene at 960x600 and 1920x1200: 'replica run --kiosk' on a
# site file like the one tests/soak/loss_under_io.sh writes (simulated sensors, headless, recording
# on, the planner, warm_up so the background compile thread and its second GL context run, an error
# probe every 2 s so it runs within the frames), FRAMES frames, under '/usr/bin/time -v'; then a
# crashed session recovered at start (tests/benchmarks/crashed_recording.py: the painting golden's
# records 344 times, 100 MiB, no summary) before the colorchecker at 960x600. Prints a row per run:
# peak RSS (MiB), the most threads seen (/proc, sampled every 0.1 s) and the wall time.
#   kiosk_peak_rss.sh REPLICA WORK [FRAMES=300]
# SCENES and SIZES (space-separated) measure fewer; RECOVER=0 leaves out the crashed session;
# RATE (Hz, default 60) sets rate_hz: 300 frames at 60 Hz on a loaded machine end before the other
# lamps' passes have compiled in the background, 400 at 5 Hz do not (docs/appliance.md).
# Not part of ctest: minutes on a software renderer.
set -euo pipefail
replica="$(realpath "$1")"
work="$2"
frames="${3:-300}"
here="$(cd "$(dirname "$0")" && pwd)"
rm -rf "$work" && mkdir -p "$work"

site() { # SCENE SIZE -> $work/site.toml, an empty $work/sessions
    rm -rf "$work/sessions" && mkdir -p "$work/sessions"
    cat > "$work/site.toml" <<TOML
[scene]
dir = "scenes/$1"
[render]
planner = true
warm_up = true
error_probe = 2
[run]
hal = "sim"
rate_hz = ${RATE:-60}
[display]
output = "headless"
size = "$2"
[recording]
directory = "$work/sessions"
keep_bytes = 1073741824
flush_ms = 500
TOML
    "$replica" config check "$work/site.toml" >/dev/null
}

measure() { # LABEL: runs the kiosk on $work/site.toml, prints LABEL, peak RSS, threads, wall
    /usr/bin/time -v -o "$work/time.txt" "$replica" --log-level warn run --kiosk \
        --config "$work/site.toml" --uncalibrated --frames "$frames" \
        > "$work/run.out" 2> "$work/run.log" &
    local timer=$! threads=0 n pid
    sleep 0.2
    pid=$(pgrep -P "$timer" | head -1 || true)
    while kill -0 "$timer" 2>/dev/null; do
        n=$(sed -n 's/^Threads:\s*//p' "/proc/$pid/status" 2>/dev/null || true)
        [ -n "$n" ] && [ "$n" -gt "$threads" ] && threads=$n
        sleep 0.1
    done
    wait "$timer" || { echo "FAIL: $1: $(tail -3 "$work/run.log")" >&2; return 1; }
    local kb wall
    kb=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$work/time.txt")
    wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$work/time.txt")
    printf '%-52s %6d MiB %3d threads  %s\n' "$1" $((kb / 1024)) "$threads" "$wall"
}

echo "$("$replica" --version 2>/dev/null | head -1), $frames frames at ${RATE:-60} Hz," \
    "$(nproc) cores," \
    "load average $(cut -d' ' -f1-3 /proc/loadavg), $(date -u +%F)"
for size in ${SIZES:-960x600 1920x1200}; do
    for scene in ${SCENES:-colorchecker metamer painting glossy-cylinder}; do
        site "$scene" "$size"
        measure "$scene, $size"
    done
done
[ "${RECOVER:-1}" = 1 ] || exit 0
site colorchecker 960x600
python3 "$here/crashed_recording.py" "$here/../replay/goldens/kiosk-painting.mcap" \
    "$work/sessions/20260101T000000Z.mcap" 344
bytes=$(stat -c %s "$work/sessions/20260101T000000Z.mcap")
measure "colorchecker, 960x600, a crashed $((bytes >> 20)) MiB session recovered"
echo "sessions after it (the crashed one recovered in place, then the new one):"
ls -l "$work/sessions"
