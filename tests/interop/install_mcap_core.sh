#!/usr/bin/env bash
# Installs the independent MCAP reader (@mcap/core, and fzstd for zstd chunks) from the npm registry
# into DIR, once: a second run with the packages present does no network work.
set -euo pipefail
dir="${1:?usage: install_mcap_core.sh DIR}"
if [ -f "$dir/node_modules/@mcap/core/package.json" ] && [ -f "$dir/node_modules/fzstd/package.json" ]; then
    echo "install_mcap_core: @mcap/core already in $dir"
    exit 0
fi
if ! command -v npm >/dev/null 2>&1; then
    echo "FAIL: npm is not installed; run deploy/install-deps" >&2
    exit 1
fi
mkdir -p "$dir"
# Pinned major versions; retried because a CI runner's first registry request sometimes times out.
for attempt in 1 2 3; do
    if npm install --prefix "$dir" --no-audit --no-fund --no-save --loglevel error \
        "@mcap/core@^2" "fzstd@^0.1" >"$dir/npm.log" 2>&1; then
        echo "install_mcap_core: installed @mcap/core into $dir"
        exit 0
    fi
    echo "install_mcap_core: npm install failed (attempt $attempt), retrying" >&2
    sleep $((attempt * 5))
done
echo "FAIL: could not install @mcap/core from the npm registry; see $dir/npm.log" >&2
tail -5 "$dir/npm.log" >&2
exit 1
