#!/usr/bin/env bash
# deploy/kiosk/replica-kiosk: runs the live appliance with a fresh session file and keeps only the
# newest recordings, so a long-running gallery never fills its disk.
set -uo pipefail
script="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work"
for i in 1 2 3 4 5; do
    touch -d "-$i hour" "$work/old$i.mcap"
done
out=$(REPLICA_SESSIONS="$work" REPLICA_KEEP_SESSIONS=3 REPLICA_BIN=/opt/replica "$script" --dry-run)
status=0
case "$out" in
"/opt/replica run --hal live --output kms --frames 0 --record $work/"*".mcap --record-digests true") ;;
*) echo "FAIL: unexpected command: $out" >&2; status=1 ;;
esac
kept=$(cd "$work" && ls -1 | sort | tr '\n' ' ')
if [ "$kept" != "old1.mcap old2.mcap old3.mcap " ]; then
    echo "FAIL: kept '$kept', expected the three newest" >&2
    status=1
fi
[ $status -eq 0 ] && echo "ok: $out; kept $kept"
exit $status
