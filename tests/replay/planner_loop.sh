#!/usr/bin/env bash
# The planner in the loop (platform/render_plan.h): by default a run draws each lamp with the plan
# shipped with the scene (and records it; --no-planner keeps the fixed rules, a scene without a
# plan keeps them without planning); --planner computes a scene's missing plan once and caches
# it, the matte metamer's plan takes no specular samples, the per-lamp choice is recorded and
# replays bit for bit (also with a different setting for each lamp, across the scenario's lamp
# change), and a malformed plan file is refused with a line that names it.
set -euo pipefail
replica="$1"
work="$2"
scenes="$3"
rm -rf "$work" && mkdir -p "$work/scene" "$work/empty"
# 10 Hz for 3 s of scenario time: lamp 0 confirmed at ~0.4 s, lamp 1 switched on at 2 s.
base=(run --hal sim --output headless --frames 30 --rate 10 --size 64x40 --fast)
# The default: the shipped metamer's own plan (from its scene folder), recorded.
shipped=$(ls "$scenes"/metamer/plan-metamer-*-adaptive_k6.json)
"$replica" --log-level info "${base[@]}" --scene "$scenes/metamer" --plan-cache "$work/empty" \
    --record "$work/default.mcap" --digests "$work/default.json" > "$work/default.log" 2>&1
if ! grep -E "render plan: .*/metamer/$(basename "$shipped")\$" "$work/default.log" > /dev/null; then
    echo "FAIL: the default run did not draw from the plan shipped with the scene" >&2
    cat "$work/default.log" >&2
    exit 1
fi
if [ -n "$(ls -A "$work/empty")" ]; then
    echo "FAIL: the default run wrote a plan although the scene has one" >&2
    exit 1
fi
"$replica" --log-level warn replay "$work/default.mcap" --clock fast --digests "$work/default_replay.json"
if ! cmp -s "$work/default.json" "$work/default_replay.json"; then
    echo "FAIL: the default (planned) run's replay differs from the live run" >&2
    exit 1
fi
# --no-planner: the fixed rules (32 lights where the plan takes 8): other frames, no plan read.
"$replica" --log-level info "${base[@]}" --scene "$scenes/metamer" --no-planner \
    --digests "$work/fixed.json" > "$work/fixed.log" 2>&1
if grep 'render plan' "$work/fixed.log" > /dev/null || cmp -s "$work/fixed.json" "$work/default.json"; then
    echo "FAIL: --no-planner did not draw with the fixed rules" >&2
    exit 1
fi
# A scene nobody planned (a copy without the shipped plan): the default draws the fixed rules
# without planning, and says how to plan; the same frames as --no-planner.
cp -r "$scenes/metamer" "$work/scene/metamer"
rm -f "$work"/scene/metamer/plan-*.json
"$replica" --log-level info "${base[@]}" --scene "$work/scene/metamer" --plan-cache "$work/empty" \
    --digests "$work/unplanned.json" > "$work/unplanned.log" 2>&1
if grep 'planning every lamp' "$work/unplanned.log" > /dev/null ||
    ! grep "replica plan --scene" "$work/unplanned.log" > /dev/null ||
    ! cmp -s "$work/unplanned.json" "$work/fixed.json"; then
    echo "FAIL: the default on a scene without a plan did not keep the fixed rules" >&2
    cat "$work/unplanned.log" >&2
    exit 1
fi
# --planner on that scene: planned now, once, and cached.
common=("${base[@]}" --scene "$work/scene/metamer" --planner --plan-cache "$work/plans")
"$replica" --log-level info "${common[@]}" --record "$work/planned.mcap" \
    --digests "$work/live.json" > "$work/first.log" 2>&1
if ! grep 'planning every lamp now' "$work/first.log" > /dev/null; then
    echo "FAIL: the first planner run did not say it was planning" >&2
    cat "$work/first.log" >&2
    exit 1
fi
plan=$(ls "$work"/plans/plan-metamer-*.json)
# 'replica plan' finds the same cached file (and does not plan again).
said=$("$replica" --log-level warn plan --scene "$work/scene/metamer" --plan-cache "$work/plans")
if [ "$(echo "$said" | head -1)" != "$plan" ]; then
    echo "FAIL: 'replica plan' names another file than the run cached: $said" >&2
    exit 1
fi
# The plan computed here is the one shipped (the same probe, the same choice).
if [ "$(python3 -c 'import json,sys; print({k: (v["lights"], v["specular_samples"], v["horizon_directions"]) for k, v in json.load(open(sys.argv[1]))["lamps"].items()})' "$plan")" != \
    "$(python3 -c 'import json,sys; print({k: (v["lights"], v["specular_samples"], v["horizon_directions"]) for k, v in json.load(open(sys.argv[1]))["lamps"].items()})' "$shipped")" ]; then
    echo "FAIL: planning the metamer again chose otherwise than its shipped plan ($shipped)" >&2
    exit 1
fi
# The metamer is matte: no lamp may pay for a specular sample.
samples=$(grep -o '"specular_samples": [0-9]*' "$plan" | sort -u)
if [ "$samples" != '"specular_samples": 0' ]; then
    echo "FAIL: the matte metamer's plan takes specular samples: $samples" >&2
    exit 1
fi
"$replica" --log-level info replay "$work/planned.mcap" --data-root "$work/scene" --clock fast --digests "$work/replay.json" \
    > "$work/replay.log" 2>&1
if ! cmp -s "$work/live.json" "$work/replay.json"; then
    echo "FAIL: the planned run's replay differs from the live run" >&2
    diff "$work/live.json" "$work/replay.json" | head -5 >&2
    exit 1
fi
if grep 'planning every lamp' "$work/replay.log" > /dev/null; then
    echo "FAIL: the replay planned again instead of taking the recorded choice" >&2
    exit 1
fi
# The second run reads the cache (no planning) and draws the same frames.
"$replica" --log-level info "${common[@]}" --digests "$work/cached.json" > "$work/cached.log" 2>&1
if grep 'planning every lamp' "$work/cached.log" > /dev/null ||
    ! cmp -s "$work/live.json" "$work/cached.json"; then
    echo "FAIL: the second run did not draw from the cached plan" >&2
    exit 1
fi
# A setting of its own for each lamp: 8, 16 and 64 lights. Live == replay across the lamp change,
# and the frames after it differ from the plan's.
python3 - "$plan" <<'PY'
import json, sys
p = json.load(open(sys.argv[1]))
for name, n in zip(sorted(p["lamps"]), (8, 16, 64)):
    p["lamps"][name]["lights"] = n
json.dump(p, open(sys.argv[1], "w"), indent=2)
PY
"$replica" --log-level warn "${common[@]}" --record "$work/mixed.mcap" --digests "$work/mixed.json"
"$replica" --log-level warn replay "$work/mixed.mcap" --data-root "$work/scene" --clock fast --digests "$work/mixed_replay.json"
if ! cmp -s "$work/mixed.json" "$work/mixed_replay.json"; then
    echo "FAIL: the per-lamp settings' replay differs from the live run" >&2
    exit 1
fi
if cmp -s "$work/mixed.json" "$work/live.json"; then
    echo "FAIL: changing the planned lights per lamp changed no frame" >&2
    exit 1
fi
# Malformed plan files: refused with the file's name, exit non-zero.
cp "$plan" "$work/good.json"
check_refused() {
    local what="$1"
    if "$replica" --log-level warn "${common[@]}" > "$work/bad.log" 2>&1; then
        echo "FAIL: a plan file with $what was accepted" >&2
        exit 1
    fi
    if ! grep "$(basename "$plan")" "$work/bad.log" > /dev/null; then
        echo "FAIL: the refusal of $what does not name the plan file" >&2
        cat "$work/bad.log" >&2
        exit 1
    fi
}
echo '{"format": "replica-plan/1", "lamps": ' > "$plan"
check_refused "truncated JSON"
sed 's/"lights": 8/"lights": -3/' "$work/good.json" > "$plan"
check_refused "a negative light count"
sed 's/replica-plan\/1/replica-plan\/9/' "$work/good.json" > "$plan"
check_refused "an unknown format"
echo "PASS: shipped plan by default, --no-planner and unplanned scenes on the fixed rules, plan cached, matte plan without specular samples, live == replay, bad plans refused"
