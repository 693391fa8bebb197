#!/usr/bin/env bash
# 'replica inspect' on a damaged recording reports the damage and exits 1; 'replica recover' rebuilds
# it (exit 3: something was dropped) into a file that inspects clean and replays.
set -uo pipefail
replica="$1"
sample="$2"
work="$3"
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }
size=$(stat -c %s "$sample")
head -c $((size * 2 / 3)) "$sample" > "$work/cut.mcap"
"$replica" --log-level warn inspect "$work/cut.mcap" > "$work/cut.txt" 2> "$work/cut.err"
[ $? -eq 1 ] || fail "inspect of a truncated file did not exit 1"
grep -q "damage: no Data End record" "$work/cut.txt" || fail "inspect did not name the damage: $(cat "$work/cut.txt")"
grep -q "still readable:" "$work/cut.txt" || fail "inspect did not say what is still readable"
[ "$(grep -c . "$work/cut.err")" -eq 1 ] || fail "inspect printed more than one error line"
"$replica" --log-level warn inspect --json "$work/cut.mcap" > "$work/cut.json" 2>/dev/null
grep -q '"damage_count"' "$work/cut.json" || fail "inspect --json has no damage_count"
"$replica" --log-level warn recover "$work/cut.mcap" "$work/fixed.mcap" > "$work/recover.txt"
code=$?
[ $code -eq 3 ] || fail "recover of a truncated file exited $code, expected 3 (lossy)"
grep -q "kept .* messages" "$work/recover.txt" || fail "recover did not report what it kept"
"$replica" --log-level warn inspect "$work/fixed.mcap" > "$work/fixed.txt" || fail "recovered file does not inspect clean"
grep -q "no damage found" "$work/fixed.txt" || fail "recovered file still reports damage"
"$replica" --log-level warn replay "$work/fixed.mcap" --digests "$work/fixed.json" >/dev/null \
    || fail "recovered file does not replay"
# Recovering a sound file loses nothing.
"$replica" --log-level warn recover "$sample" "$work/same.mcap" >/dev/null
[ $? -eq 0 ] || fail "recover of a sound file did not exit 0"
# Nothing recoverable: exit 1 with one line.
printf 'not an mcap file at all' > "$work/junk.mcap"
"$replica" --log-level warn recover "$work/junk.mcap" "$work/junk-out.mcap" >/dev/null 2>&1
[ $? -eq 1 ] || fail "recover of junk did not exit 1"
echo "PASS: inspect reports damage (exit 1); recover exits 3/0/1 and its output inspects clean and replays"
