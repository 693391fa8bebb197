# Sourced by the interop scripts after they set node_dir: points NODE_PATH at its node_modules and
# skips the test (exit 77) when @mcap/core is not installed there.
export NODE_PATH="$node_dir/node_modules"
if [ ! -f "$NODE_PATH/@mcap/core/package.json" ]; then
    echo "SKIP: @mcap/core is not available (interop.install_mcap_core says why; deploy/install-deps installs it)" >&2
    exit 77
fi
