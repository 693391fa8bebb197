#!/usr/bin/env bash
# The kiosk as shipped, pinned: for each shipped scene, runs 'replica run --kiosk' from the shipped
# site file (tests/replay/goldens/kiosk-site: only the scene, sim sensors, headless 160x100 at 10 Hz
# and the sessions folder changed) exactly as tests/replay/goldens/make recorded kiosk-NAME.mcap,
# and checks the new session's frames against that golden's digests. The planner's plan and the
# dimmer's "auto" value are chosen at start and recorded, so replaying the golden alone would not
# notice a change to either; running the kiosk again does: a planner, dimmer or site-default change
# fails here until the goldens are re-recorded ('tests/replay/goldens/make "REASON" kiosk').
#   kiosk_goldens.sh REPLICA SOURCE_ROOT WORK
set -euo pipefail
replica="$1"
root="$2"
work="$3"
rm -rf "$work" && mkdir -p "$work"
count=0
for golden in "$root"/tests/replay/goldens/kiosk-*.digests.json; do
    name=$(basename "$golden" .digests.json)
    scene=${name#kiosk-}
    sessions="$work/$scene"
    mkdir -p "$sessions"
    "$root/tests/replay/goldens/kiosk-site" "$root/deploy/replica.toml" "$scene" "$sessions" \
        > "$work/$scene.toml"
    "$replica" --log-level warn run --kiosk --config "$work/$scene.toml" --frames 62 --fast \
        --thumbnail-hz 1 --thumbnail-width 80 > "$work/$scene.run.txt"
    files=("$sessions"/*.mcap)
    [ ${#files[@]} -eq 1 ] || { echo "FAIL: the kiosk wrote ${#files[@]} session files for $scene" >&2; exit 1; }
    if ! "$replica" --log-level warn replay "${files[0]}" --no-progress --check "$golden" \
        --reference "${golden%.digests.json}.frames" --mismatch-dir "$work/$scene.mismatch" \
        > "$work/$scene.replay.txt" 2>&1; then
        echo "FAIL: the kiosk's $scene session differs from $name (the planner, dimmer or site" \
             "defaults changed?); re-record with tests/replay/goldens/make \"REASON\" kiosk:" >&2
        cat "$work/$scene.replay.txt" >&2
        exit 1
    fi
    grep -q "^check: all 62 frames match" "$work/$scene.replay.txt" ||
        { echo "FAIL: $scene: no 62-frame match reported:" >&2; cat "$work/$scene.replay.txt" >&2; exit 1; }
    echo "kiosk $scene: 62 frames match $name"
    count=$((count + 1))
done
[ "$count" -ge 3 ] || { echo "FAIL: $count kiosk goldens (one per shipped scene expected)" >&2; exit 1; }

# The check can fail: the same kiosk with the dimmer fixed at 0.5 instead of "auto" must differ.
mkdir -p "$work/dimmed"
"$root/tests/replay/goldens/kiosk-site" "$root/deploy/replica.toml" painting "$work/dimmed" |
    sed 's/^dimmer = "auto"/dimmer = 0.5/' > "$work/dimmed.toml"
grep -q '^dimmer = 0.5' "$work/dimmed.toml" || { echo "FAIL: could not set the dimmer" >&2; exit 1; }
"$replica" --log-level warn run --kiosk --config "$work/dimmed.toml" --frames 62 --fast \
    --thumbnail-hz 1 --thumbnail-width 80 > /dev/null
if "$replica" --log-level warn replay "$work"/dimmed/*.mcap --no-progress \
    --check "$root/tests/replay/goldens/kiosk-painting.digests.json" > "$work/dimmed.txt" 2>&1; then
    echo "FAIL: a kiosk with another dimmer matched the golden" >&2
    exit 1
fi
echo "PASS: $count kiosk goldens reproduced; a changed dimmer fails"
