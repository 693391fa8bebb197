#!/usr/bin/env bash
# Makes the independent MCAP reader (@mcap/core, and fzstd for zstd chunks) available in DIR: from
# the global install deploy/install-deps makes (no network), else from the npm registry, once.
# Neither: exits 77 (ctest: skipped) with a message saying so; the interop tests then skip too.
set -euo pipefail
dir="${1:?usage: install_mcap_core.sh DIR}"
have() { [ -f "$1/@mcap/core/package.json" ] && [ -f "$1/fzstd/package.json" ]; }
if have "$dir/node_modules"; then
    echo "install_mcap_core: @mcap/core already in $dir"
    exit 0
fi
if ! command -v npm >/dev/null 2>&1 || ! command -v node >/dev/null 2>&1; then
    echo "SKIP: Node.js/npm are not installed, so the independent MCAP reader cannot run; run deploy/install-deps" >&2
    exit 77
fi
mkdir -p "$dir"
global="$(npm root -g 2>/dev/null || true)"
if [ -n "$global" ] && have "$global"; then
    rm -rf "$dir/node_modules"
    ln -s "$global" "$dir/node_modules"
    echo "install_mcap_core: using the @mcap/core that deploy/install-deps installed in $global"
    exit 0
fi
# Not installed: try the registry (retried: a CI runner's first request sometimes times out).
for attempt in 1 2; do
    if npm install --prefix "$dir" --no-audit --no-fund --no-save --loglevel error \
        --fetch-timeout 20000 --fetch-retries 1 \
        "@mcap/core@^2" "fzstd@^0.1" >"$dir/npm.log" 2>&1; then
        echo "install_mcap_core: installed @mcap/core into $dir from the npm registry"
        exit 0
    fi
    echo "install_mcap_core: npm install failed (attempt $attempt)" >&2
    sleep $((attempt * 3))
done
echo "SKIP: @mcap/core is not installed (deploy/install-deps installs it globally) and the npm registry cannot be reached (see $dir/npm.log): the independent MCAP reader checks are skipped" >&2
tail -3 "$dir/npm.log" >&2
exit 77
