#!/usr/bin/env bash
# Parse speed and memory of `vrmlray info` on a 100 MB molecular-style .wrl (Transform + Shape + Sphere +
# full Material per atom, as PyMOL writes them). Prints MB/s and peak memory for each of RUNS runs and
# their medians. Usage: bench/parse_speed.sh [VRMLRAY_BINARY] [RUNS]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:-$root/build/vrmlray}
runs=${2:-3}
work=${TMPDIR:-/tmp}/vrmlray_parse_bench
mkdir -p "$work"
file=$work/molecule_100mb.wrl
if [ ! -s "$file" ]; then
    echo "generating $file ..." >&2
    python3 "$root/tools/gen_molecule.py" 345000 "$file" --no-bonds
fi
bytes=$(stat -c %s "$file")
echo "file: $file ($((bytes / 1000000)) MB)"
results=()
for i in $(seq "$runs"); do
    /usr/bin/time -f "%e %M" -o "$work/time.txt" "$bin" info "$file" -q >/dev/null
    read -r seconds kb <"$work/time.txt"
    mbs=$(awk -v b="$bytes" -v s="$seconds" 'BEGIN { printf "%.1f", b / 1e6 / s }')
    echo "run $i: ${seconds} s, ${mbs} MB/s, peak $((kb / 1024)) MB"
    results+=("$seconds $kb")
done
printf '%s\n' "${results[@]}" | sort -n | awk -v b="$bytes" -v n="$runs" 'NR == int((n + 1) / 2) {
    printf "median: %.2f s, %.1f MB/s (whole process: read, parse, build, flatten), peak %d MB = %.2fx the file\n",
           $1, b / 1e6 / $1, $2 / 1024, $2 * 1024 / b }'
