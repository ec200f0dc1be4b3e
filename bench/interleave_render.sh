#!/usr/bin/env bash
# Two or more vrmlray builds on one scene, run in turn (A B C A B C ...) so that the machine's drift
# falls on all of them alike; prints each build's render phase (`--stats` seconds.render): first
# quartile, median and third quartile over RUNS runs. This is how the A/B figures of bench/README.md
# ("Issue 16 part 6") were taken; compare builds within one call only.
#
# Usage: bench/interleave_render.sh SCENE RUNS BINARY...
# Environment: ARGS (render options; default "-W 1920 -H 1080"), THREADS (default 2).
#   e.g. ARGS="-W 480 -H 270 --sky 0.7,0.7,0.7 --light-tolerance 1e-1" bench/interleave_render.sh sky.wrl 5 OLD NEW
set -euo pipefail
[ $# -ge 3 ] || { sed -n '2,9p' "$0" >&2; exit 2; }
scene=$1 runs=$2
shift 2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# shellcheck disable=SC2086  # ARGS: options split on spaces
for _ in $(seq "$runs"); do
    j=0
    for bin in "$@"; do
        j=$((j + 1))
        "$bin" render "$scene" ${ARGS:--W 1920 -H 1080} --threads "${THREADS:-2}" -o "$work/$j.ppm" -q \
            --stats "$work/$j.json"
        /usr/bin/python3 -c "import json, sys; print(sys.argv[1], json.load(open(sys.argv[2]))['seconds']['render'])" \
            "$j" "$work/$j.json"
    done
done | sort -k1,1n -k2g | awk -v names="$*" '
    BEGIN { split(names, bin, " ") }
    { v[$1, ++n[$1]] = $2 }
    END { for (k = 1; k in n; ++k) { c = n[k]
        printf "%-40s q1 %.4f  median %.4f  q3 %.4f  (%d runs)\n", bin[k], v[k, int(c / 4) + 1], v[k, int(c / 2) + 1], v[k, int(3 * c / 4) + 1], c } }'
