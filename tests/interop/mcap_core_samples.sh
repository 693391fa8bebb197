#!/usr/bin/env bash
# Reads recordings with @mcap/core and compares them with 'replica inspect --json': every committed
# sample (formats 1 to 3); format 4's channels of what was shown (thumbnail against --snapshot), a fresh recording with the lamp selector, and a recording killed with SIGKILL then recovered.
set -euo pipefail
replica="$1"
samples="$2"
node_dir="$3"
work="$4"
here="$(cd "$(dirname "$0")" && pwd)"
rm -rf "$work" && mkdir -p "$work"
# shellcheck source=need_mcap_core.sh
source "$here/need_mcap_core.sh"

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
# Format 4's thumbnails: 61 frames at 60 Hz with a 1 Hz thumbnail gives thumbnails of frames 0 and
# 60, the last frame, which --snapshot writes: the reader check decodes the thumbnail and compares
# it with the snapshot downscaled independently.
"$replica" --log-level warn run --hal sim --output headless --frames 61 --size 160x100 --fast \
    --rate 60 --thumbnail-hz 1 --thumbnail-width 64 --record "$work/shown.mcap" \
    --snapshot "$work/shown.png" >/dev/null
check "$work/shown.mcap"
node "$here/thumbnail_check.cjs" "$work/shown.mcap" "$work/shown.png" 61
