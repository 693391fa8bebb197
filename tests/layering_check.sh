#!/usr/bin/env bash
# Checks the allowed dependency edges between layers (style guide section 1): pipeline and hal include
# nothing of the other layers (hal may use pipeline/base only); recordings only hal and pipeline/base.
set -uo pipefail
root="$1"
status=0
check() {
    local layer="$1" pattern="$2" why="$3"
    local hits
    hits=$(grep -rnE "#include <($pattern)/" "$root/$layer" --include='*.h' --include='*.cpp' || true)
    if [ -n "$hits" ]; then
        echo "FAIL: $layer/ $why:" >&2
        echo "$hits" >&2
        status=1
    fi
}
check pipeline 'hal|recordings|platform' "must not depend on device, recording or platform code"
check hal 'recordings|platform' "must not depend on recordings or platform"
check recordings 'platform' "must not depend on platform"
# hal may include only the header-only vocabulary from pipeline/base.
hits=$(grep -rnE '#include <pipeline/' "$root/hal" --include='*.h' --include='*.cpp' | grep -v '<pipeline/base/' || true)
if [ -n "$hits" ]; then
    echo "FAIL: hal/ may include only pipeline/base/ from pipeline:" >&2
    echo "$hits" >&2
    status=1
fi
hits=$(grep -rnE '#include <pipeline/' "$root/recordings" --include='*.h' --include='*.cpp' | grep -v '<pipeline/base/' || true)
if [ -n "$hits" ]; then
    echo "FAIL: recordings/ may include only pipeline/base/ from pipeline:" >&2
    echo "$hits" >&2
    status=1
fi
[ $status -eq 0 ] && echo "PASS: layer dependencies follow the allowed edges"
exit $status
