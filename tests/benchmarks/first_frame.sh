#!/usr/bin/env bash
# Process start to the first frame, per scene, on a cold and a warm Mesa shader cache: where the
# start-up goes, from the run's own log (docs/performance.md, "Start-up").
#
#   tests/benchmarks/first_frame.sh REPLICA OUTDIR
#
# Each scene S runs `REPLICA --log-level debug run --hal sim --output headless --scene
# data/scenes/S --rate 30 --frames FRAMES --size 960x600` twice with MESA_SHADER_CACHE_DIR an
# empty folder of its own: cold (a fresh install's first start), then warm (the second start).
# Printed per run, from the run's log (s: since the process started, which the 'first frame
# shown N s' line dates; ms: a step's own time): the plan loaded (the first planner line: data,
# state stage, GL context and scene loaded before it), the GL context's creation, the automatic
# booth dimmer, the booth pass made, the warm-up before the first frame, the renderer (display
# pass) made, the appliance built ('hal:' line), frame 0's work, the first frame shown, the later
# frames that drew a pass for the first time (a lamp switch that compiled), the background
# compile, and each idle-time warm-up. Logs in OUTDIR. The environment may set SCENES
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
echo "| scene | cache | plan loaded s | GL context ms | dimmer ms | booth pass made ms | warm-up before frame 1 ms | renderer ms | built s | frame 0 ms | first frame s | later first draws ms | background ms | idle warm-ups ms |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
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
def ms(pattern, every=False, skip=0):
    found = [m[1] for m in (re.search(pattern, l) for _, l in stamped) if m][skip:]
    if not found:
        return "-"
    return ", ".join(f"{float(x):.0f}" for x in found) if every else f"{float(found[0]):.0f}"
cols = [at(r"\] \[planner\]"), ms(r"output and GL context up in (\d+) ms"),
        ms(r"booth dimmer \(auto\) chosen in (\d+) ms"), ms(r"booth pass made in (\d+) ms"),
        ms(r"warmed up in (\d+) ms"), ms(r"renderer \(display pass\) made in (\d+) ms"),
        at(r"\] hal: "), ms(r"frame 0: ([\d.]+) ms$"), f"{shown:.2f}",
        ms(r"drew its shading pass for the first time: (\d+) ms", every=True, skip=1),
        ms(r"background compile of the other shading passes done in (\d+) ms"),
        ms(r"shading pass \d+ compiled after frame \d+ in (\d+) ms", every=True)]
print(f"| {scene} | {kind} | " + " | ".join(cols) + " |")
PY
    done
    rm -rf "$cache"
done
