#!/usr/bin/env bash
# Renders the golden images of tests/render/golden/golden.txt (a `vrmlray render --list` file) with the given
# binary, in one process. Run it only for an intended change of the images, look at every changed one (the
# report of `vrmlray compare OLD_DIR tests/render/golden --report DIR` shows them), and say in the commit why
# they changed.
# Usage: tests/render/make_goldens.sh BUILD/vrmlray [NAME...]   (NAME: only the lines with -o NAME.png)
set -euo pipefail
bin=$1
shift
golden=$(cd "$(dirname "$0")/golden" && pwd)
list=$golden/golden.txt
if [ $# -gt 0 ]; then
    # The subset beside the list, since its scene paths are relative to the list's folder.
    list=$(mktemp "$golden/.subset.XXXXXX")
    trap 'rm -f "$list"' EXIT
    for name in "$@"; do grep -E -- "-o $name\.png\$" "$golden/golden.txt" >>"$list" || { echo "no golden $name" >&2; exit 2; }; done
fi
"$bin" render --list "$list" -o "$golden/" -q
