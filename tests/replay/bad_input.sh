#!/usr/bin/env bash
# replay and inspect on a missing, empty or non-recording file: non-zero exit and a one-line reason
# naming the file.
set -uo pipefail
replica="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work"
: > "$work/empty.mcap"
printf 'wavelength_nm,a\n380,1\n' > "$work/not-a-recording.mcap"
head -c 100 /dev/urandom > "$work/random.mcap" 2>/dev/null || printf '\x01\x02garbage' > "$work/random.mcap"
status=0
for cmd in replay inspect; do
    for f in "$work/missing.mcap" "$work/empty.mcap" "$work/not-a-recording.mcap" "$work/random.mcap"; do
        err=$("$replica" "$cmd" "$f" 2>&1 >/dev/null)
        code=$?
        lines=$(printf '%s\n' "$err" | grep -c .)
        if [ "$code" -eq 0 ]; then
            echo "FAIL: replica $cmd $f exited 0" >&2
            status=1
        elif [ "$lines" -ne 1 ]; then
            echo "FAIL: replica $cmd $f printed $lines lines, expected one: $err" >&2
            status=1
        elif ! grep -q "$(basename "$f")" <<<"$err"; then
            echo "FAIL: replica $cmd $f did not name the file: $err" >&2
            status=1
        else
            echo "ok: replica $cmd $(basename "$f") -> exit $code: $err"
        fi
    done
done
exit $status
