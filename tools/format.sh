#!/usr/bin/env bash
# Formats every C++ source of the project with clang-format (.clang-format at the top), or with --check
# only reports the files that differ and fails (CI runs that).
#   tools/format.sh          rewrite the files in place
#   tools/format.sh --check  exit 1 when any file is not formatted
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
"$root/tools/setup.sh" clang-format
mapfile -t files < <(git ls-files '*.cpp' '*.h')
if [ "${1:-}" = --check ]; then
    bad=0
    for f in "${files[@]}"; do
        clang-format --dry-run --Werror "$f" >/dev/null 2>&1 || { echo "format: $f differs from .clang-format"; bad=$((bad + 1)); }
    done
    echo "format: $((${#files[@]} - bad)) passed, $bad failed"
    [ "$bad" -eq 0 ]
else
    clang-format -i "${files[@]}"
fi
