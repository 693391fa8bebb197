#!/usr/bin/env bash
# Shows tests/size_check.sh failing on a planted piece over its limit and passing one at it:
#   size_check_test.sh SOURCE_ROOT KIND
# Each kind writes a minimal tree in a temporary folder and asserts the check's result and message.
set -uo pipefail
src="$1"
kind="$2"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# function_of NAME BODY_LINES: a C/GLSL function whose definition spans BODY_LINES + 4 lines.
function_of() {
    echo "int $1(int x)"
    echo "{"
    for ((i = 0; i < $2; i++)); do echo "    x += $i;"; done
    echo "    return x;"
    echo "}"
}
# file_of LINES: a file of LINES short lines.
file_of() {
    for ((i = 0; i < $1; i++)); do echo "// line $i"; done
}
write() {
    mkdir -p "$(dirname "$tmp/$1")"
    cat >"$tmp/$1"
}

expect_rc=1
expect=()
refuse=()
case "$kind" in
long_function)
    function_of plantedLong 97 | write pipeline/colour/planted.cpp
    expect=("pipeline/colour/planted.cpp:1: plantedLong is 101 lines") ;;
function_at_limit)
    function_of plantedAtLimit 96 | write pipeline/colour/planted.cpp
    expect_rc=0
    refuse=("plantedAtLimit") ;;
method)
    { echo "namespace replica {"; echo "struct Planted { int run(int x); };";
      function_of Planted::run 120; echo "}"; } | write platform/planted.cpp
    expect=("platform/planted.cpp:3: Planted::run is 124 lines") ;;
long_file)
    file_of 601 | write hal/planted.h
    expect=("hal/planted.h is 601 lines") ;;
file_at_limit)
    file_of 600 | write hal/planted.h
    expect_rc=0
    refuse=("planted.h") ;;
glsl)
    { echo "#version 310 es"; echo "void main() {"; for ((i = 0; i < 100; i++)); do echo "    gl_Position.x += 1.0;"; done; echo "}"; } |
        write pipeline/render/glsl/planted.glsl
    file_of 650 | write pipeline/render/glsl/planted_long.glsl
    expect=("pipeline/render/glsl/planted.glsl:2: main is 102 lines" "pipeline/render/glsl/planted_long.glsl is 650 lines") ;;
tests_exempt)
    function_of plantedInTests 200 | write tests/unit/planted_test.cpp
    file_of 900 | write tests/unit/planted_long_test.cpp
    function_of plantedShort 10 | write state/planted.cpp
    expect_rc=0
    refuse=("planted") ;;
*)
    echo "unknown kind '$kind'" >&2
    exit 2 ;;
esac

out=$(bash "$src/tests/size_check.sh" "$tmp" 2>&1)
rc=$?
if [ $rc -eq 77 ]; then
    echo "$out"
    exit 77
fi
if [ $rc -ne $expect_rc ]; then
    echo "FAIL: the size check exited $rc on the planted '$kind' tree, expected $expect_rc:" >&2
    echo "$out" >&2
    exit 1
fi
for message in "${expect[@]}"; do
    if ! grep -qF -- "$message" <<<"$out"; then
        echo "FAIL: the size check on the planted '$kind' tree did not say '$message':" >&2
        echo "$out" >&2
        exit 1
    fi
done
for message in "${refuse[@]}"; do
    if grep -qF -- "$message" <<<"$out"; then
        echo "FAIL: the size check on the planted '$kind' tree named '$message', which is within its limit:" >&2
        echo "$out" >&2
        exit 1
    fi
done
echo "PASS: the size check on a planted '$kind' tree exits $rc with the expected message"
