#!/usr/bin/env bash
# Recording failures never stop the display: with a full disk (/dev/full), an unwritable place, or
# the file deleted mid-run, 'replica run --record' goes through every tick (up to the last frame; with
# real-time pacing a late tick is skipped, not rendered), logs exactly one error naming the file, and
# exits 1.
set -uo pipefail
replica="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work"
status=0
expect() { # name, stderr file, digests file, frames, pattern
    local name="$1" err="$2" digests="$3" frames="$4" pattern="$5"
    local errors got
    errors=$(grep -c "\[error\]" "$err")
    # Ticks gone through: the last frame's index + 1 (a late real-time tick is skipped).
    got=$(grep -o '"frame": *[0-9]*' "$digests" 2>/dev/null | grep -o '[0-9]*$' | sort -n | tail -1)
    got=$((${got:--1} + 1))
    if [ "$errors" -ne 1 ]; then
        echo "FAIL: $name: expected one error line, got $errors:" >&2; cat "$err" >&2; status=1
    elif ! grep "\[error\]" "$err" | grep -q "$pattern"; then
        echo "FAIL: $name: the error does not say '$pattern':" >&2; grep "\[error\]" "$err" >&2; status=1
    elif [ "$got" -ne "$frames" ]; then
        echo "FAIL: $name: went through $got ticks, expected $frames" >&2; status=1
    else
        echo "ok: $name: $frames ticks gone through; $(grep "\[error\]" "$err" | sed 's/.*\[error\] //')"
    fi
}
run() { "$replica" --log-level warn run --hal sim --output headless --size 16x10 "$@"; }

run --frames 10 --fast --record /dev/full --digests "$work/full.json" >/dev/null 2>"$work/full.err"
[ $? -eq 1 ] || { echo "FAIL: disk full: exit status not 1" >&2; status=1; }
expect "disk full" "$work/full.err" "$work/full.json" 10 "/dev/full: .*disk full"

mkdir -p "$work/ro" && chmod 555 "$work/ro"
target="$work/ro/x.mcap"
[ "$(id -u)" -eq 0 ] && target=/sys/replica-test.mcap # root ignores directory permissions
run --frames 10 --fast --record "$target" --digests "$work/ro.json" >/dev/null 2>"$work/ro.err"
[ $? -eq 1 ] || { echo "FAIL: read-only: exit status not 1" >&2; status=1; }
expect "read-only" "$work/ro.err" "$work/ro.json" 10 "$target: cannot create recording"
chmod 755 "$work/ro"

# Real-time pacing (90 frames = 1.5 s); the file disappears after about half a second.
run --frames 90 --record "$work/deleted.mcap" --record-flush-ms 100 --digests "$work/del.json" \
    >/dev/null 2>"$work/del.err" &
pid=$!
for _ in $(seq 100); do [ -s "$work/deleted.mcap" ] && break; sleep 0.05; done
sleep 0.5
rm -f "$work/deleted.mcap"
wait $pid
[ $? -eq 1 ] || { echo "FAIL: deleted: exit status not 1" >&2; status=1; }
expect "deleted" "$work/del.err" "$work/del.json" 90 "deleted while recording"
exit $status
