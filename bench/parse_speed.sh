#!/usr/bin/env bash
# Reading speed and memory on a 100 MB molecular-style scene (Transform + Shape + Sphere + full Material per
# atom, as PyMOL writes them), in the classic encoding and, converted by vrmlray, in X3D XML. For each run:
# the reader's time (load phase of `render --stats`, a 1x1 render so nothing else counts), MB/s, the
# whole process's peak memory, and the peak of reading alone (bench/parse_only.cpp, built against the
# libvrml_parser.a beside the binary when there is one: no scene build, no flattening). Medians of RUNS runs.
# Usage: bench/parse_speed.sh [VRMLRAY_BINARY] [RUNS]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:-$root/build/vrmlray}
runs=${2:-3}
work=${TMPDIR:-/tmp}/vrmlray_parse_bench
mkdir -p "$work"
wrl=$work/molecule_100mb.wrl
x3d=$work/molecule_100mb.x3d
if [ ! -s "$wrl" ]; then
    echo "generating $wrl ..." >&2
    python3 "$root/tools/gen_molecule.py" 345000 "$wrl" --no-bonds
fi
[ -s "$x3d" ] || "$bin" convert "$wrl" "$x3d" -q
# The reader alone, built as an optional target of the binary's own build folder.
build=$(dirname "$bin")
reader=""
if [ -f "$build/CMakeCache.txt" ] && cmake -S "$root" -B "$build" -DVRMLRAY_BENCH=ON >/dev/null &&
        cmake --build "$build" --target parse_only >/dev/null; then
    reader=$build/bench/parse_only
fi
for file in "$wrl" "$x3d"; do
    bytes=$(stat -c %s "$file")
    rows=()
    for i in $(seq "$runs"); do
        /usr/bin/time -f "%M" -o "$work/rss.txt" "$bin" render "$file" -W 1 -H 1 -o "$work/one.png" -q \
            --stats "$work/stats.json" >/dev/null
        parse=$(grep -o '"parse": [0-9.e+-]*' "$work/stats.json" | awk '{print $2}')
        alone=0
        if [ -n "$reader" ]; then
            /usr/bin/time -f "%M" -o "$work/rss_reader.txt" "$reader" "$file" >/dev/null || true
            alone=$(cat "$work/rss_reader.txt")
        fi
        rows+=("$parse $(cat "$work/rss.txt") $alone")
    done
    printf '%s\n' "${rows[@]}" | sort -g | awk -v b="$bytes" -v n="$runs" -v f="$(basename "$file")" '
        NR == int((n + 1) / 2) { printf "%-22s %6.1f MB  read %.2f s  %6.1f MB/s  peak %d MB (%.1fx the file)",
                                 f, b / 1e6, $1, b / 1e6 / $1, $2 / 1024, $2 * 1024 / b
                                 if ($3 > 0) printf ", reading alone %d MB (%.1fx)", $3 / 1024, $3 * 1024 / b
                                 printf "\n" }'
done
