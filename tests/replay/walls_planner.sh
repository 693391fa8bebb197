#!/usr/bin/env bash
# The planner chooses the booth's walls per lamp (issue 33): under a booth whose booth.json
# declares walls, each lamp draws them where leaving them out would cost the ΔE00 budget against
# the reference with the walls.
#  A. 'replica plan --booth' on grey N7 walls and on nearly black walls (2 %): every lamp's plan
#     says "walls"; the black walls are left out for every lamp (they change nothing visible),
#     the grey ones drawn for at least one; what the command prints agrees with the file.
#  B. The kiosk from the site file with [booth] dir = the grey booth and no plan cached: it plans
#     at start, draws each lamp as planned (its log says so), records the choice, and the
#     recording replays bit for bit.
#   walls_planner.sh REPLICA SOURCE_ROOT WORK
set -euo pipefail
replica="$1"
root="$2"
work="$3"
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }

# Booth folders: the shipped booth with walls declared.
walled() { # DIR REFLECTANCE-or-empty
    cp -r "$root/data/booth" "$1"
    python3 - "$1/booth.json" "$2" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
j["walls"] = {"reflectance": [float(sys.argv[2])] * 36} if sys.argv[2] else {}
json.dump(j, open(sys.argv[1], "w"), indent=2)
PY
}
walled "$work/grey" ""
walled "$work/black" 0.02

# plan_walls PLAN_FILE -> "lamp=true|false ..." sorted
plan_walls() {
    python3 - "$1" <<'PY'
import json, sys
lamps = json.load(open(sys.argv[1]))["lamps"]
for k in sorted(lamps):
    v = lamps[k].get("walls")
    if not isinstance(v, bool):
        sys.exit(f"lamp {k}: no boolean 'walls' in the plan")
    print(f"{k}={'true' if v else 'false'}", end=" ")
PY
}

# --- A. replica plan on both booths.
for booth in grey black; do
    "$replica" --log-level warn plan --scene "$root/data/scenes/metamer" --booth "$work/$booth" \
        --plan-cache "$work/plans-$booth" > "$work/plan-$booth.txt" ||
        fail "replica plan --booth $booth failed"
    file=$(head -1 "$work/plan-$booth.txt")
    [ -f "$file" ] || fail "replica plan did not name its plan file: $file"
    said=$(plan_walls "$file") || fail "$file: $said"
    # What the command printed agrees with the file, lamp by lamp.
    for pair in $said; do
        lamp=${pair%%=*}
        want="no walls"
        [ "${pair#*=}" = true ] && want="the walls' light"
        grep -q "^$lamp: .*, $want;" "$work/plan-$booth.txt" ||
            { cat "$work/plan-$booth.txt" >&2; fail "$booth: the printed plan of $lamp does not say '$want'"; }
    done
    echo "$booth: $said"
    eval "walls_$booth=\"$said\""
done
case "$walls_black" in *=true*) fail "walls of 2 % reflectance drawn: $walls_black" ;; esac
case "$walls_grey" in *=true*) ;; *) fail "grey N7 walls drawn for no lamp: $walls_grey" ;; esac
echo "PASS: the planner draws grey walls ($walls_grey) and leaves nearly black ones out"

# --- B. The kiosk on the grey booth, planning at start.
mkdir -p "$work/sessions"
"$root/tests/replay/goldens/kiosk-site" "$root/deploy/replica.toml" metamer "$work/sessions" |
    sed -e "/^\[booth\]/,/^\[scene\]/ s|^# dir = .*|dir = \"$work/grey\"|" > "$work/kiosk.toml"
grep -q "^dir = \"$work/grey\"" "$work/kiosk.toml" || fail "could not set [booth] dir"
"$replica" config check "$work/kiosk.toml" > "$work/check.txt" 2>&1 ||
    { cat "$work/check.txt" >&2; fail "config check refused the kiosk's site file"; }
REPLICA_PLAN_CACHE="$work/kiosk-plans" "$replica" --log-level info run --kiosk \
    --config "$work/kiosk.toml" --frames 30 --fast --no-warm-up --thumbnail-hz 0 \
    --digests "$work/kiosk.json" > "$work/kiosk.log" 2>&1 ||
    { tail -20 "$work/kiosk.log" >&2; fail "the kiosk on a walled booth failed"; }
kplan=$(ls "$work"/kiosk-plans/plan-metamer-*.json 2> /dev/null | head -1)
[ -n "$kplan" ] || { tail -20 "$work/kiosk.log" >&2; fail "the kiosk did not plan the walled booth at start"; }
[ "$(plan_walls "$kplan")" = "$walls_grey" ] ||
    fail "the kiosk planned other walls ($(plan_walls "$kplan")) than 'replica plan' ($walls_grey)"
for pair in $walls_grey; do
    lamp=${pair%%=*}
    want="no walls"
    [ "${pair#*=}" = true ] && want="the walls' light"
    grep -q "lamp $lamp: .*, $want\$" "$work/kiosk.log" ||
        { grep planner "$work/kiosk.log" >&2; fail "the kiosk's log does not say $lamp draws '$want'"; }
done
files=("$work/sessions"/*.mcap)
[ ${#files[@]} -eq 1 ] || fail "the kiosk wrote ${#files[@]} session files"
recorded=$("$replica" inspect --json "${files[0]}" | python3 -c '
import json, sys
lamps = json.load(sys.stdin)["config"]["planned_lamps"]
print(" ".join(k + "=" + str(lamps[k]["walls"]).lower() for k in sorted(lamps)), end=" ")')
[ "$recorded" = "$walls_grey" ] || fail "the recording holds walls $recorded, the plan $walls_grey"
"$replica" --log-level warn replay "${files[0]}" --clock fast --data-root "$work" \
    --digests "$work/replay.json" > "$work/replay.log" 2>&1 || true
cmp -s "$work/kiosk.json" "$work/replay.json" ||
    { tail -5 "$work/replay.log" >&2; fail "the walled kiosk session does not replay bit for bit"; }
echo "PASS: the kiosk plans the walled booth at start, draws and records each lamp's walls, replays bit for bit"
