#!/usr/bin/env bash
# Checks that the docs point at files that exist: every backticked path with a folder and a file
# extension (`platform/cli/run_command.cpp`, `pipeline/render/renderer.h`, `state/lamp_arbiter.*`,
# `recordings/sample_codec.{h,cpp}`) in README.md, docs/*.md and every folder's README.md names a
# file of the tree. A path is looked for under the root, beside the document, and where the docs name
# paths from a folder of their context: pipeline/ (`render/renderer.h`), pipeline/render/
# (`glsl/dither.glsl`), platform/ (`cli/run_command.cpp`), tests/unit/ (the equation table's test
# column) and data/. Not checked: CHANGELOG.md (history), absolute paths (/etc/replica/...: the
# installed system's), paths out of the tree (../shared/...), paths under build/ (what a build or a
# test run writes: absent from a fresh clone, present in a worked-in tree, so checking them would
# make the result depend on what ran before), and templates whose folders are in
# capitals (`data/scenes/S/plan-*.json`, `DIR/patch.txt`).
#   doc_paths_check.sh ROOT
set -uo pipefail
root="${1%/}"
# Files the build writes (GLSL embedded into headers, the version stamp): named in the docs, in no tree.
generated=(render/booth_shaders.h render/display_shaders.h pipeline/render/booth_shaders.h
           pipeline/render/display_shaders.h platform/version.cpp)
exts='cpp|h|hpp|inl|glsl|cmake|sh|py|md|txt|json|toml|csv|exr|mcap|in|service|rules|yml|yaml'
docs=$(cd "$root" && { ls README.md docs/*.md 2>/dev/null
                       find . \( -path ./build -o -path ./tests/data -o -name '.?*' \) -prune -o \
                            -mindepth 2 -name README.md -print | sed 's#^\./##'; } | sort -u)
status=0
# exists DOC PATTERN: whether a file matches PATTERN (a path, a glob or one {a,b} group) where the
# docs may mean it.
exists() {
    local doc="$1" pattern="$2" base expanded=()
    if [[ $pattern =~ ^(.*)\{([^}]*)\}(.*)$ ]]; then
        local alt
        IFS=, read -ra alts <<<"${BASH_REMATCH[2]}"
        for alt in "${alts[@]}"; do expanded+=("${BASH_REMATCH[1]}$alt${BASH_REMATCH[3]}"); done
    else
        expanded=("$pattern")
    fi
    local one found
    for one in "${expanded[@]}"; do
        found=0
        for base in "$root" "$root/$(dirname "$doc")" "$root/pipeline" "$root/pipeline/render" \
                    "$root/platform" "$root/tests/unit" "$root/data"; do
            # shellcheck disable=SC2086 # the glob is meant
            if compgen -G "$base/$one" >/dev/null; then
                found=1
                break
            fi
        done
        [ $found -eq 1 ] || return 1
    done
    return 0
}
for doc in $docs; do
    while IFS=: read -r line ref; do
        [ -n "$ref" ] || continue
        [[ " ${generated[*]} " == *" $ref "* ]] && continue
        [[ $ref == ../* ]] && continue
        [[ $ref == build/* ]] && continue
        [[ $ref =~ (^|/)[A-Z][A-Z0-9_]*([.-][^/]*)?/ ]] && continue
        if ! exists "$doc" "$ref"; then
            echo "FAIL: $doc:$line: \`$ref\` names no file of the tree (fix the path or the text)" >&2
            status=1
        fi
    done < <(grep -noE '`[A-Za-z0-9_.{},*-]+(/[A-Za-z0-9_.{},*-]+)+`' "$root/$doc" |
             sed -E 's/`//g' | grep -E "\.($exts|\*|\{[a-z,]+\})$" || true)
done
[ $status -eq 0 ] && echo "PASS: every backticked path in the docs names a file of the tree"
exit $status
