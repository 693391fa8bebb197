#!/usr/bin/env bash
# Reads recordings with @mcap/core and compares them with 'replica inspect --json': every committed
# sample (formats 1 to 3), a fresh recording with the lamp selector, and a recording killed with SIGKILL then recovered.
set -euo pipefail
replica="$1"
samples="$2"
node_dir="$3"
work="$4"
here="$(cd "$(dirname "$0")" && pwd)"
rm -rf "$work" && mkdir -p "$work"
export NODE_PATH="$node_dir/node_modules"

check() {
    local rec="$1" name
    name=$(basename "${rec%.mcap}")
    "$replica" --log-level warn inspect --json "$rec" > "$work/$name.inspect.json"
    node "$here/mcap_core_check.cjs" "$rec" "$work/$name.inspect.json"
}

for rec in "$samples"/*.mcap; do
    check "$rec"
done
"$replica" --log-level warn run --hal sim --output headless --frames 50 --size 64x40 --fast \
    --rate 20 --lamp-selector sim --record "$work/fresh.mcap" >/dev/null
check "$work/fresh.mcap"
