#!/usr/bin/env bash
# Replay for people and format 4's channels of what was shown:
# - thumbnails never change frames: the same run with none and with 10 Hz thumbnails gives the
#   same digests, and replay reproduces the recorded per-frame display digests;
# - --from/--to replays a slice whose digests are exactly those frames of the whole replay;
# - --frames-out writes one PNG per frame of the slice, and --save-png (its other name) the same;
#   --json summaries of run and replay;
# - progress lines only with --progress when standard error is not a terminal;
# - inspect takes several files and shows the wall-clock start and the lamp timeline;
# - warnings are recorded on /replica/log even when the console shows only errors.
set -euo pipefail
replica="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }
run=(--log-level warn run --hal sim --output headless --frames 75 --size 96x60 --fast --rate 30)
"$replica" "${run[@]}" --record "$work/none.mcap" --thumbnail-hz 0 --digests "$work/none.json" >/dev/null
"$replica" "${run[@]}" --record "$work/thumbs.mcap" --thumbnail-hz 10 --digests "$work/thumbs.json" \
    --json > "$work/run.json"
cmp -s "$work/none.json" "$work/thumbs.json" || fail "thumbnails changed the frames"
grep -q '"thumbnails": [1-9]' "$work/run.json" || fail "run --json reports no thumbnails: $(cat "$work/run.json")"
grep -q '"display_digests": 75' "$work/run.json" || fail "run --json: not 75 display digests"
grep -q '"command": "run"' "$work/run.json" || fail "run --json has no summary"
# The whole replay reproduces what the panel showed, frame for frame.
"$replica" --log-level warn replay "$work/thumbs.mcap" --digests "$work/all.json" --json \
    > "$work/all.out" 2> "$work/all.err"
grep -q '"matched": 75' "$work/all.out" || fail "replay did not match the 75 recorded display digests"
grep -q '"differing": 0' "$work/all.out" || fail "display digests differ"
[ ! -s "$work/all.err" ] || fail "replay wrote to stderr without a terminal: $(head -2 "$work/all.err")"
cmp -s "$work/all.json" "$work/thumbs.json" || fail "replay digests differ from the run's"
# A slice: 1.0 s to 1.5 s at 30 Hz is frames 30 .. 45 (ticks k * 33333333 ns).
"$replica" --log-level warn replay "$work/thumbs.mcap" --from 1 --to 1.5 --digests "$work/slice.json" \
    --frames-out "$work/png" --progress > "$work/slice.out" 2> "$work/slice.err"
want=$(grep '"frame"' "$work/all.json" | sed -n '31,46p' | sed 's/,$//')
got=$(grep '"frame"' "$work/slice.json" | sed 's/,$//')
[ "$want" = "$got" ] || fail "slice digests are not frames 30-45 of the whole replay"
[ "$(ls "$work/png" | wc -l)" -eq 16 ] || fail "--frames-out wrote $(ls "$work/png" | wc -l) PNGs, want 16"
[ -s "$work/png/frame-000030.png" ] && [ -s "$work/png/frame-000045.png" ] || fail "wrong frame names"
# --save-png is the same option under its older name: the same files, byte for byte.
"$replica" --log-level warn replay "$work/thumbs.mcap" --from 1 --to 1.5 --save-png "$work/png-alias" \
    > /dev/null
diff -r "$work/png" "$work/png-alias" > /dev/null || fail "--save-png wrote other files than --frames-out"
grep -q "^replay: frame 45 (46 of 46, 100%)" "$work/slice.err" || fail "--progress printed no final line: $(cat "$work/slice.err")"
# A slice after the end is refused with the recording's span.
if "$replica" --log-level warn replay "$work/thumbs.mcap" --from 100 2> "$work/after.err"; then
    fail "a slice after the end was accepted"
fi
grep -q "no frame between" "$work/after.err" || fail "no clear message for an empty slice"
# inspect: several files, wall-clock start, the decided light.
"$replica" inspect "$work/none.mcap" "$work/thumbs.mcap" > "$work/inspect.txt"
[ "$(grep -c 'replica recording, format 6' "$work/inspect.txt")" -eq 2 ] || fail "inspect did not show both files"
grep -q "started 20[0-9-]*T" "$work/inspect.txt" || fail "inspect shows no wall-clock start"
grep -q "shown: tungsten, 2856 K" "$work/inspect.txt" || fail "inspect shows no decided tungsten lamp at 2856 K"
"$replica" inspect --json "$work/none.mcap" "$work/thumbs.mcap" > "$work/inspect.json"
head -c 1 "$work/inspect.json" | grep -q '\[' || fail "inspect --json of two files is not an array"
# The appliance's warnings reach /replica/log (foxglove.Log): a mis-wired selector is overruled
# after 1.5 s of disagreement, with one warning.
"$replica" --log-level error run --hal sim --output headless --frames 130 --size 32x20 --fast --rate 30 \
    --lamp-selector sim-miswired --record "$work/miswired.mcap" >/dev/null
"$replica" inspect --json "$work/miswired.mcap" > "$work/miswired.json"
grep -A4 '"/replica/log"' "$work/miswired.json" | grep '"count": 1,' >/dev/null \
    || fail "the overruled-selector warning is not in /replica/log"
echo "PASS: thumbnails leave frames alone; replay matches 75 display digests; slice 30-45 equals the whole replay's; 16 PNGs, the same under --save-png; progress; inspect of two files"
