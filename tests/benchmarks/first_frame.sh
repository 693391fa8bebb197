#!/usr/bin/env bash
# Process start to the first frame, per scene, on a cold and a warm Mesa shader cache: where the
# start-up goes, from the run's own log (docs/performance.md, "Start-up").
#
#   tests/benchmarks/first_frame.sh REPLICA OUTDIR
#
# Each scene S runs `REPLICA --log-level debug run --hal sim --output headless --scene
# data/scenes/S --rate 30 --frames FRAMES --size 960x600` twice with MESA_SHADER_CACHE_DIR an
# empty folder of its own: cold (a fresh install's first start), then warm (the second start).
# Printed per run, seconds since the process started (the 'first frame shown N s' line dates the
# start): the log's first line (process and logging up), the booth / plan lines (scene, booth and
# plan loaded, GL context up), the booth dimmer's line, the appliance built ('hal:' line), the
# first frame's own draw with its compilation (ms, 'drew its shading pass for the first time'),
# the first frame shown; and the warm-up: before the first frame ('warmed up in') or after it
# ('background compile ... done in'). Logs in OUTDIR. The environment may set SCENES
# ("colorchecker metamer painting glossy-cylinder"), FRAMES (60) and KIOSK=1: the kiosk from the
# shipped site file instead (deploy/replica.toml with hal = "sim", output = "headless", recording
# off and dir = "scenes/S": its automatic booth dimmer and 60 Hz; `REPLICA --log-level debug run
# --kiosk --config SITE --frames FRAMES`).
set -uo pipefail
if [ $# -ne 2 ] || [ "$1" = "-h" ] || [ "$1" = "--help" ]; then
    sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
fi
replica="$1"
out="$2"
mkdir -p "$out"
scenes="${SCENES:-colorchecker metamer painting glossy-cylinder}"
frames="${FRAMES:-60}"
echo "| scene | cache | log up s | booth, plan s | dimmer s | built s | warm-up before frame 1 ms | first frame's draw ms | first frame s | background compile ms |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for s in $scenes; do
    cache=$(mktemp -d "$out/cache-$s-XXXXXX")
    for kind in cold warm; do
        log="$out/$s-$kind.log"
        if [ "${KIOSK:-0}" = 1 ]; then
            site="$out/site-$s.toml"
            sed -e 's/^hal = "live"/hal = "sim"/' -e 's/^output = "kms"/output = "headless"/' \
                -e 's/^enabled = true/enabled = false/' -e "s|^dir = \"scenes/[a-z0-9-]*\"|dir = \"scenes/$s\"|" \
                deploy/replica.toml >"$site"
            MESA_SHADER_CACHE_DIR="$cache" "$replica" --log-level debug run --kiosk --config "$site" \
                --frames "$frames" >"$log" 2>&1
        else
            MESA_SHADER_CACHE_DIR="$cache" "$replica" --log-level debug run --hal sim \
                --output headless --scene "data/scenes/$s" --rate 30 --frames "$frames" \
                --size 960x600 >"$log" 2>&1
        fi
        python3 - "$log" "$s" "$kind" <<'PY'
import re, sys
log, scene, kind = sys.argv[1:]
lines = open(log, errors="replace").read().splitlines()
def secs(line):
    m = re.match(r"\[(\d+):(\d+):(\d+\.\d+)\]", line)
    return int(m[1]) * 3600 + int(m[2]) * 60 + float(m[3]) if m else None
stamped = [(secs(l), l) for l in lines if secs(l) is not None]
start = None
for t, l in stamped:
    m = re.search(r"first frame shown ([\d.]+) s after the process started", l)
    if m:
        start = t - float(m[1])
        shown = float(m[1])
        break
if start is None:
    print(f"| {scene} | {kind} | no first frame: see {log} |")
    sys.exit(0)
def at(pattern):
    for t, l in stamped:
        if re.search(pattern, l):
            return f"{t - start:.2f}"
    return "-"
def ms(pattern):
    for _, l in stamped:
        m = re.search(pattern, l)
        if m:
            return m[1]
    return "-"
cols = [at(r""), at(r"\] \[(planner|booth)\]"), at(r"booth dimmer"), at(r"\] hal: "),
        ms(r"warmed up in (\d+) ms"), ms(r"drew its shading pass for the first time: (\d+) ms"),
        f"{shown:.2f}", ms(r"background compile of the other shading passes done in (\d+) ms")]
print(f"| {scene} | {kind} | " + " | ".join(cols) + " |")
PY
    done
    rm -rf "$cache"
done
