#!/usr/bin/env bash
# Checks that the pieces stay short (style guide: short pieces): no function over 100 lines and no file
# over 600 lines, outside tests/ (and the build and data folders). It reads C++ sources and headers
# and the GLSL; a function's length runs from the line its definition starts on to its closing brace,
# both included, as Universal Ctags reports them (line: and end:).
#   size_check.sh ROOT
# names each function and file over its limit and exits 1 if there is one; 77 (skipped) without ctags.
set -uo pipefail
root="${1%/}"
max_function_lines=100
max_file_lines=600
if ! ctags --version 2>/dev/null | grep -q 'Universal Ctags'; then
    echo "SKIP: size_check.sh needs Universal Ctags (apt install universal-ctags)" >&2
    exit 77
fi
files=$(cd "$root" && find . \( -path ./tests -o -path ./build -o -path ./data -o -name '.?*' \) -prune -o \
            -type f \( -name '*.h' -o -name '*.hpp' -o -name '*.inl' -o -name '*.ipp' -o -name '*.hh' \
            -o -name '*.c' -o -name '*.cc' -o -name '*.cxx' -o -name '*.cpp' -o -name '*.glsl' \
            -o -name '*.vert' -o -name '*.frag' -o -name '*.comp' \) -print | sed 's#^\./##' | sort)
status=0
if [ -n "$files" ]; then
    long_files=$(cd "$root" && tr '\n' '\0' <<<"$files" | xargs -0 wc -l |
                 awk -v max="$max_file_lines" '$2 != "total" && $1 > max { print $2 " is " $1 " lines" }')
    # GLSL is C enough for ctags' C++ parser to find its functions.
    long_functions=$(cd "$root" && ctags --c++-kinds=f --fields=+ne --langmap=C++:+.glsl.vert.frag.comp \
                         --languages=C,C++ -L - -f - <<<"$files" |
                     awk -F'\t' -v max="$max_function_lines" '{
                         name = $1; file = $2; line = 0; end = 0; scope = ""
                         for (i = 4; i <= NF; i++) {
                             if ($i ~ /^line:/) line = substr($i, 6)
                             else if ($i ~ /^end:/) end = substr($i, 5)
                             else if ($i ~ /^(class|struct|union):/) { scope = $i; sub(/^.*:/, "", scope) }
                         }
                         if (end > 0 && end - line + 1 > max)
                             printf "%s:%d: %s%s is %d lines\n", file, line, (scope == "" ? "" : scope "::"), name, end - line + 1
                     }' | sort)
    if [ -n "$long_files" ]; then
        echo "FAIL: files over $max_file_lines lines (split them by what each part does):" >&2
        echo "$long_files" >&2
        status=1
    fi
    if [ -n "$long_functions" ]; then
        echo "FAIL: functions over $max_function_lines lines (split them into named steps):" >&2
        echo "$long_functions" >&2
        status=1
    fi
fi
[ $status -eq 0 ] && echo "PASS: no function over $max_function_lines lines, no file over $max_file_lines lines outside tests/"
exit $status
