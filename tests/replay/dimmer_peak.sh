#!/usr/bin/env bash
# The booth dimmer holds the panel's peak it claims: a simulated kiosk session ('replica run
# --kiosk') of each shipped scene (every folder of data/scenes with a scene.json) with the shipped
# site file (its "auto" dimmer, the planner, viewing compensation and flare subtraction as
# shipped; only the sensors simulated, the output headless, the frame small, the rate 10 Hz and
# the recording off; the sim scenario walks the eye 0.4 m either side and tilts the stand from 6
# to 34 degrees). The run's own summary (the display pass's gamut classes counted on every frame,
# independently of the dimmer's estimate) has at most 1 % of the surface above the panel's peak
# on average and at most 5 % in its worst frame, and the dimmer's start-up line reports that
# quantity (the share the display pass counts, viewing gain included).
set -euo pipefail
replica="$1"
work="$2"
site="$3"
scenes="$4"
rm -rf "$work" && mkdir -p "$work"
checked=0
for dir in "$scenes"/*/; do
    scene=$(basename "$dir")
    [ -f "$dir/scene.json" ] || continue
    checked=$((checked + 1))
    sed -e 's/^hal = "live"/hal = "sim"/' -e 's/^output = "kms"/output = "headless"/' \
        -e 's/^size = "960x600"/size = "160x100"/' -e 's/^enabled = true/enabled = false/' \
        -e 's/^warm_up = true/warm_up = false/' -e 's/^rate_hz = 60.0/rate_hz = 10.0/' \
        -e "s|^dir = \"scenes/colorchecker\"|dir = \"$(cd "$dir" && pwd)\"|" \
        "$site" > "$work/$scene.toml"
    # 10 s of scenario time: every lamp, a whole walk, two tilt periods.
    "$replica" --log-level info run --kiosk --config "$work/$scene.toml" --frames 100 --fast \
        --json > "$work/$scene.json" 2> "$work/$scene.log"
    if ! grep -q "booth dimmer (auto) .*surface above the panel's peak (viewing gain included)" \
        "$work/$scene.log"; then
        echo "FAIL: $scene: no start-up line of the automatic dimmer, viewing gain included" >&2
        cat "$work/$scene.log" >&2
        exit 1
    fi
    python3 - "$work/$scene.json" "$scene" <<'PY'
import json, sys
summary = json.load(open(sys.argv[1]))
g = summary["out_of_gamut"]
mean, worst = g["over_peak_mean"], g["over_peak_max"]
print(f"{sys.argv[2]}: {summary['frames']} frames, surface above the panel's peak: mean "
      f"{100 * mean:.2f} %, worst frame {100 * worst:.2f} %")
if summary["frames"] != 100 or not mean <= 0.01 or not worst <= 0.05:
    sys.exit(f"FAIL: {sys.argv[2]}: above the panel's peak mean {mean:.4f} (<= 0.01) and worst "
             f"frame {worst:.4f} (<= 0.05) over {summary['frames']} frames")
PY
done
if [ "$checked" -lt 5 ]; then
    echo "FAIL: $checked scenes with a scene.json under $scenes (the shipped ones are 5 or more)" >&2
    exit 1
fi
