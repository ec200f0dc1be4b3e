#!/usr/bin/env bash
# Whether a speed change of the tracer kept every pixel: renders the golden list (tests/render/golden) and the
# peer scenes S2 and S3 (bench/peers.sh's, 1920x1080, 2 threads) with two binaries to 32-bit float EXR and
# compares the files byte for byte. A change that keeps the arithmetic (traversal order, prefetching, memory
# layout) must pass this, which is stronger than the 1e-4 relative bound a change of the arithmetic would be
# held to; the 8-bit goldens alone could hide a difference below 1/255.
#
# Usage: bench/same_pixels.sh OLD_VRMLRAY NEW_VRMLRAY   (scenes from bench/peers.sh's folder, made if missing)
# Exit: 0 every image identical, 1 some differ (listed).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
old=$1 new=$2
work=${TMPDIR:-/tmp}/vrmlray_same_pixels
peers=${TMPDIR:-/tmp}/vrmlray_peers
rm -rf "$work" && mkdir -p "$work/old" "$work/new"
declare -A spec=([S2_molecule_10k]=s2_molecule_10k [S3_spheres_1M]=s3_spheres_1M)
for s in "${!spec[@]}"; do
    [ -s "$peers/$s.wrl" ] || { mkdir -p "$peers" && /usr/bin/python3 "$root/../shared/bench/gen_scene.py" \
        "$root/../shared/bench/specs/${spec[$s]}.json" --out "$peers" --formats wrl >/dev/null; }
done
# The golden list with absolute scene paths and .exr outputs (its -o names win over --format).
golden=$root/tests/render/golden
awk -v dir="$golden" '/^#/ || NF == 0 {next} {$1 = dir "/" $1; sub(/\.png$/, ".exr"); print}' \
    "$golden/golden.txt" >"$work/list.txt"
for v in old new; do
    bin=${!v}
    "$bin" render --list "$work/list.txt" -o "$work/$v/" -q
    for s in "${!spec[@]}"; do
        "$bin" render "$peers/$s.wrl" -W 1920 -H 1080 --threads 2 -o "$work/$v/$s.exr" -q
    done
done
differ=0 n=0
for f in "$work/old"/*.exr; do
    n=$((n + 1))
    cmp -s "$f" "$work/new/$(basename "$f")" || { echo "differs: $(basename "$f")"; differ=$((differ + 1)); }
done
[ "$(ls "$work/new"/*.exr | wc -l)" -eq "$n" ] || { echo "the binaries wrote different image sets"; exit 1; }
echo "$n images, $differ differ"
[ "$differ" -eq 0 ]
