#!/usr/bin/env bash
# Speed of golden-image suites (docs/golden-tests.md):
#  1. compare REF_DIR OUT_DIR on 1,000 pairs of 320x240 PNGs (made here from the golden images: copies under
#     ten folders, 2% of the results swapped for another image so that they fail), one thread against all
#     cores, and with --report;
#  2. the corpus's good files rendered at 64x48 by one batch process against one process per file.
# Whole-process wall time, median of RUNS alternating runs (default 5; the corpus part: CORPUS_RUNS, 3).
# Usage: bench/suite_speed.sh BUILD/vrmlray [CORPUS_DIR]
set -euo pipefail
bin=$(realpath "$1")
src=$(cd "$(dirname "$0")/.." && pwd)
corpus=${2:-$src/../shared/corpus}
runs=${RUNS:-5}
corpus_runs=${CORPUS_RUNS:-3}
work=$(mktemp -d /tmp/vrmlray_suite_speed.XXXXXX)
trap 'rm -rf "$work"' EXIT

now() { date +%s.%N; }
median() { sort -g | awk '{v[NR]=$1} END {print v[int((NR+1)/2)]}'; }
# time_of COMMAND...: wall seconds of one run, its output discarded (a failing compare exits 1: expected).
time_of() { local t0; t0=$(now); "$@" >/dev/null 2>&1 || true; awk -v a="$t0" -v b="$(now)" 'BEGIN {print b - a}'; }

echo "load before: $(cat /proc/loadavg); $(nproc) cores"

# --- 1. 1,000 pairs ----------------------------------------------------------------------------------
mapfile -t goldens < <(ls "$src"/tests/render/golden/0*.png "$src"/tests/render/golden/good_*.png)
for k in $(seq 0 999); do
    d=$((k % 10))
    g=${goldens[$((k % 8))]}   # the eight 320x240 or 160x120 scene goldens
    mkdir -p "$work/ref/d$d" "$work/out/d$d"
    cp "$g" "$work/ref/d$d/img$k.png"
    if [ $((k % 50)) -eq 0 ]; then cp "${goldens[$(((k + 1) % 8))]}" "$work/out/d$d/img$k.png"; else cp "$g" "$work/out/d$d/img$k.png"; fi
done
t1=() t2=() tr=()
for r in $(seq "$runs"); do
    t1+=("$(time_of "$bin" compare "$work/ref" "$work/out" --threads 1)")
    t2+=("$(time_of "$bin" compare "$work/ref" "$work/out" --threads 2)")
    rm -rf "$work/report"
    tr+=("$(time_of "$bin" compare "$work/ref" "$work/out" --threads 2 --report "$work/report" --junit "$work/j.xml")")
done
"$bin" compare "$work/ref" "$work/out" | tail -1 || true  # exit 1: 20 pairs fail on purpose
printf '1000 pairs, median of %d: 1 thread %.2f s, 2 threads %.2f s, 2 threads with --report and --junit %.2f s\n' "$runs" \
    "$(printf '%s\n' "${t1[@]}" | median)" "$(printf '%s\n' "${t2[@]}" | median)" "$(printf '%s\n' "${tr[@]}" | median)"

# --- 2. the corpus: one batch process against one process per file ----------------------------------
if [ ! -d "$corpus" ]; then echo "no corpus at $corpus: part 2 skipped"; exit 0; fi
cd "$corpus"
mapfile -t files < <(find . -type f \( -name '*.wrl' -o -name '*.wrl.gz' -o -name '*.wrz' -o -name '*.x3dv' \
    -o -name '*.x3d' -o -name '*.x3dz' -o -name '*.x3dvz' \) | grep -Ev '/(bad|warnings|errors)/' | sed 's|^\./||' | sort)
per_file() {
    for f in "${files[@]}"; do
        local o="$work/single/${f%.*}.png"
        mkdir -p "$(dirname "$o")"
        "$bin" render "$f" -W 64 -H 48 -q -o "$o" || true
    done
}
tb=() ts=()
for r in $(seq "$corpus_runs"); do
    rm -rf "$work/batch" "$work/single"
    tb+=("$(time_of "$bin" render "${files[@]}" -W 64 -H 48 -q -o "$work/batch/")")
    ts+=("$(time_of per_file)")
done
"$bin" render "${files[@]}" -W 64 -H 48 -q -o "$work/batch/" | head -1 || true
b=$(printf '%s\n' "${tb[@]}" | median) s=$(printf '%s\n' "${ts[@]}" | median)
printf '%d corpus files at 64x48, median of %d: one batch process %.2f s, one process per file %.2f s (%.1f ms a file saved)\n' \
    "${#files[@]}" "$corpus_runs" "$b" "$s" "$(awk -v s="$s" -v b="$b" -v n="${#files[@]}" 'BEGIN {print (s - b) * 1000 / n}')"
echo "load after: $(cat /proc/loadavg)"
