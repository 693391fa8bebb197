#!/usr/bin/env bash
# Fails when any C++ source differs from clang-format's output (config: .clang-format).
set -uo pipefail
root="$1"
if ! command -v clang-format >/dev/null 2>&1; then
    echo "clang-format not installed; skipping" >&2
    exit 77
fi
bad=$(cd "$root" && git ls-files '*.h' '*.cpp' 2>/dev/null | while read -r f; do
    clang-format --dry-run --Werror "$f" >/dev/null 2>&1 || echo "$f"
done)
if [ -n "$bad" ]; then
    echo "FAIL: not clang-formatted (run clang-format -i on them):" >&2
    echo "$bad" >&2
    exit 1
fi
echo "PASS: all sources clang-formatted"
