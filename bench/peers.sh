#!/usr/bin/env bash
# vrmlray beside Tachyon on the peer harness's scenes (../shared/bench), measured in the same run: the same
# scene description written as .wrl and Tachyon .dat by the harness's generator, 1 sample per pixel, hard
# shadows, 2 threads, whole process wall time (parse, build, render, write), median of RUNS runs.
# Usage: bench/peers.sh [VRMLRAY_BINARY] [RUNS] [SCENE...]   (scenes: S1_single S2_molecule_10k S3_spheres_1M)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:-$root/build/vrmlray}
runs=${2:-3}
shift 2 || true
scenes=("$@")
[ ${#scenes[@]} -eq 0 ] && scenes=(S1_single S2_molecule_10k S3_spheres_1M)
harness=$root/../shared/bench
work=${TMPDIR:-/tmp}/vrmlray_peers
mkdir -p "$work"
"$root/tools/setup.sh" tachyon python3-numpy
declare -A spec=([S1_single]=s1_single [S2_molecule_10k]=s2_molecule_10k [S3_spheres_1M]=s3_spheres_1M [S4_gas_1k]=s4_gas_1k)
median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
wall() {  # wall seconds of one command
    local t0 t1
    t0=$(date +%s.%N); "$@" >/dev/null 2>&1; t1=$(date +%s.%N)
    awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.4f\n", b - a}'
}
printf '%-18s %12s %12s %8s\n' scene "vrmlray s" "tachyon s" ratio
for s in "${scenes[@]}"; do
    [ -s "$work/$s.wrl" ] || /usr/bin/python3 "$harness/gen_scene.py" "$harness/specs/${spec[$s]}.json" --out "$work" \
        --formats wrl,dat >/dev/null
    v=$(for i in $(seq "$runs"); do wall "$bin" render "$work/$s.wrl" -W 1920 -H 1080 --threads 2 -o "$work/v.ppm" -q; done | median)
    t=$(for i in $(seq "$runs"); do wall tachyon "$work/$s.dat" -numthreads 2 -res 1920 1080 -format PPM -o "$work/t.ppm"; done | median)
    printf '%-18s %12s %12s %8s\n' "$s" "$v" "$t" "$(awk -v a="$v" -v b="$t" 'BEGIN {printf "%.2fx", a / b}')"
done
