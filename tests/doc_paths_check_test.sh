#!/usr/bin/env bash
# Shows tests/doc_paths_check.sh failing on a doc that names a missing file, and only on that one:
# a minimal tree whose docs name an existing file, a {h,cpp} pair, a glob, a build output (not
# checked: a fresh clone has no build/) and a missing file.
set -uo pipefail
src="$1"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/docs" "$tmp/state" "$tmp/pipeline/render"
touch "$tmp/state/lamp_arbiter.h" "$tmp/state/lamp_arbiter.cpp" "$tmp/pipeline/render/renderer.h"
printf '%s\n' '# Planted' 'The arbiter (`state/lamp_arbiter.{h,cpp}`, `state/lamp_arbiter.*`),' \
    'the renderer (`render/renderer.h`, `pipeline/render/renderer.h`),' \
    'a build output (`build/default/Testing/Temporary/CTestCostData.txt`),' \
    'a template (`DIR/patch.txt`) and a file that is gone (`pipeline/render/planted_gone.h`).' \
    >"$tmp/docs/planted.md"
out=$(bash "$src/tests/doc_paths_check.sh" "$tmp" 2>&1)
rc=$?
want='docs/planted.md:5: `pipeline/render/planted_gone.h` names no file'
if [ $rc -eq 0 ] || ! grep -qF -- "$want" <<<"$out" || [ "$(grep -c '^FAIL' <<<"$out")" -ne 1 ]; then
    echo "FAIL: expected exit 1 and exactly one failure, '$want'; got exit $rc:" >&2
    echo "$out" >&2
    exit 1
fi
echo "PASS: the docs' path check fails on the planted missing file only"
