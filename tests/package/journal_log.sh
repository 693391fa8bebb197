#!/usr/bin/env bash
# Logs under systemd: when $JOURNAL_STREAM names the file stderr is (as systemd sets it for a
# service whose stderr is the journal), each line carries its priority for journald; with the
# variable unset, or naming another file, the lines are unchanged ("[time] [area] [level] text").
# 'replica probe' on a machine without the devices logs one error line (half a second of listening for
# opentrack's UDP poses is its run time).
#   journal_log.sh REPLICA WORK_DIR
set -uo pipefail
replica="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work"
fail() {
    echo "FAIL: $*" >&2
    exit 1
}
probe() { "$replica" probe --tracker-wait 0.5 >/dev/null 2>>"$1"; }

# Unset: the terminal's format.
probe "$work/plain.log"
grep -Eq '^\[[0-9]{2}:[0-9]{2}:[0-9]{2}\.[0-9]{3}\] \[replica\] \[error\] probe: ' "$work/plain.log" ||
    fail "without JOURNAL_STREAM the error line is not '[time] [replica] [error] probe: ...': $(cat "$work/plain.log")"
echo "plain: $(grep -m1 'probe:' "$work/plain.log")"

# Naming another file (a child whose stderr was redirected inherits the variable): unchanged.
: >"$work/other"
JOURNAL_STREAM="$(stat -c '%d:%i' "$work/other")" probe "$work/other.log"
grep -Eq '^\[[0-9:.]+\] \[replica\] \[error\] probe: ' "$work/other.log" ||
    fail "JOURNAL_STREAM naming another file changed the format: $(cat "$work/other.log")"

# Naming stderr's own file: the journal's lines.
: >"$work/journal.log"
JOURNAL_STREAM="$(stat -c '%d:%i' "$work/journal.log")" probe "$work/journal.log"
if [ -S /run/systemd/journal/socket ]; then
    # A journald here takes the lines natively (priority and REPLICA_LOGGER as fields): none may
    # reach stderr with the terminal's timestamp.
    if grep -E '^\[[0-9:.]+\] ' "$work/journal.log"; then
        fail "with a journal, lines still went to stderr in the terminal's format"
    fi
    echo "journal: lines sent to this machine's journald (journalctl -t replica REPLICA_LOGGER=replica)"
else
    # No journald socket: the stream's '<PRIORITY>' prefix (sd-daemon(3); error = 3).
    grep -Eq '^<3>\[replica\] probe: .*missing' "$work/journal.log" ||
        fail "with JOURNAL_STREAM the error line is not '<3>[replica] probe: ...': $(cat "$work/journal.log")"
    if grep -Ev '^<[0-7]>\[[a-z.]+\] ' "$work/journal.log"; then
        fail "a line above has no '<PRIORITY>[area] ' prefix"
    fi
    echo "journal stream: $(grep -m1 'probe:' "$work/journal.log")"
fi
echo "ok"
