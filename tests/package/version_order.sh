#!/usr/bin/env bash
# The package version orders builds: in a scratch git repository, the version cmake/
# replica_version.cmake gives each of eleven commits must sort above the one before it for
# 'dpkg --compare-versions' (the count going from 9 to 10 included, where a string comparison
# would fail), above the bare project version and below the next project version; uncommitted
# changes are marked. Nothing here reads the versions the module is expected to print: only dpkg's
# ordering and the commit count that git itself reports.
#   version_order.sh SOURCE_DIR WORK_DIR
set -uo pipefail
src="$1"
work="$2"
fail() {
    echo "FAIL: $*" >&2
    exit 1
}
for tool in git dpkg cmake; do
    command -v "$tool" >/dev/null || { echo "skip: no $tool"; exit 77; }
done
rm -rf "$work" && mkdir -p "$work/repo"
repo="$work/repo"
git -C "$repo" init -q
export GIT_AUTHOR_NAME=t GIT_AUTHOR_EMAIL=t@example.org GIT_COMMITTER_NAME=t
export GIT_COMMITTER_EMAIL=t@example.org
version() { cmake -DSOURCE_DIR="$repo" -DPROJECT_VERSION=0.1.0 -P "$src/cmake/replica_version.cmake" 2>&1; }
previous=0.1.0
for i in $(seq 1 11); do
    echo "$i" >"$repo/file"
    git -C "$repo" add file && git -C "$repo" commit -q -m "commit $i" || fail "git commit $i"
    v=$(version)
    hash=$(git -C "$repo" rev-parse --short=12 HEAD)
    case "$v" in
    *"$hash"*) ;;
    *) fail "version '$v' of commit $i does not name the commit $hash" ;;
    esac
    case "$v" in
    *"git$(git -C "$repo" rev-list --count HEAD)."*) ;;
    *) fail "version '$v' of commit $i does not carry git's commit count" ;;
    esac
    dpkg --compare-versions "$v" gt "$previous" || fail "'$v' (commit $i) does not sort above '$previous'"
    dpkg --compare-versions "$v" lt 0.1.1 || fail "'$v' does not sort below the next release 0.1.1"
    echo "commit $i: $v > $previous"
    previous="$v"
done
echo 12 >"$repo/file"
dirty=$(version)
[ "$dirty" = "$previous.dirty" ] || fail "uncommitted changes give '$dirty', expected '$previous.dirty'"
dpkg --compare-versions "$dirty" gt "$previous" || fail "'$dirty' does not sort above '$previous'"
echo "uncommitted: $dirty"
# A tree without git: the project version.
mkdir -p "$work/plain"
plain=$(cmake -DSOURCE_DIR="$work/plain" -DPROJECT_VERSION=0.1.0 -P "$src/cmake/replica_version.cmake" 2>&1)
[ "$plain" = 0.1.0 ] || fail "a tree without git gives '$plain', expected the project version 0.1.0"
echo "ok"
