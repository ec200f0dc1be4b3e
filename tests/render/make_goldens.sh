#!/usr/bin/env bash
# Renders every golden image of tests/render/golden/golden.txt with the given binary. Run it only for an
# intended change of the images, look at every changed one, and say in the commit why they changed.
# Usage: tests/render/make_goldens.sh BUILD/vrmlray [NAME...]
set -euo pipefail
bin=$1
shift
src=$(cd "$(dirname "$0")/../.." && pwd)
while read -r name scene w h extra; do
    case "$name" in ''|\#*) continue;; esac
    if [ $# -gt 0 ] && [[ " $* " != *" $name "* ]]; then continue; fi
    # shellcheck disable=SC2086
    (cd "$(dirname "$src/$scene")" && "$bin" render "$(basename "$scene")" -W "$w" -H "$h" $extra -q \
        -o "$src/tests/render/golden/$name.png")
    echo "$name"
done <"$src/tests/render/golden/golden.txt"
