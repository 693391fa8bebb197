#!/usr/bin/env bash
# deploy/kiosk/replica-kiosk: runs the live appliance with a fresh session file and keeps only the
# newest recordings, so a long-running gallery never fills its disk.
set -uo pipefail
script="$(realpath "$1")"
work="$2"
rm -rf "$work" && mkdir -p "$work"
for i in 1 2 3 4 5; do
    touch -d "-$i hour" "$work/old$i.mcap"
done
# Names with spaces are one name each: the oldest goes whole, and a file in the current folder
# named like a piece of it ("old") stays; a link named *.mcap is not a session and stays.
touch -d "-6 hour" "$work/old 6.mcap"
ln -s /etc/hostname "$work/link.mcap" && touch -h -d "-7 hour" "$work/link.mcap"
cwd="$work.cwd"
rm -rf "$cwd" && mkdir -p "$cwd" && touch "$cwd/old" "$cwd/6.mcap"
out=$(cd "$cwd" && REPLICA_SESSIONS="$work" REPLICA_KEEP_SESSIONS=3 REPLICA_BIN=/opt/replica "$script" --dry-run)
status=0
if [ ! -e "$cwd/old" ] || [ ! -e "$cwd/6.mcap" ]; then
    echo "FAIL: retention deleted a file in the current folder" >&2
    status=1
fi
if ! bad=$(REPLICA_SESSIONS="$work" REPLICA_KEEP_SESSIONS='3; rm' "$script" --dry-run 2>&1) &&
    printf '%s' "$bad" | grep -q 'not a whole number'; then
    :
else
    echo "FAIL: a non-numeric REPLICA_KEEP_SESSIONS was not refused: $bad" >&2
    status=1
fi
case "$out" in
"/opt/replica run --hal live --output kms --frames 0 --record $work/"*".mcap --record-digests true") ;;
*) echo "FAIL: unexpected command: $out" >&2; status=1 ;;
esac
kept=$(cd "$work" && ls -1 | sort | tr '\n' ' ')
if [ "$kept" != "link.mcap old1.mcap old2.mcap old3.mcap " ]; then
    echo "FAIL: kept '$kept', expected the three newest" >&2
    status=1
fi
[ $status -eq 0 ] && echo "ok: $out; kept $kept"
exit $status
