#!/usr/bin/env bash
# Whether a speed change of the tracer kept every pixel: renders the golden list (tests/render/golden) and the
# peer scenes S2 and S3 (bench/peers.sh's, 1920x1080, 2 threads) with two binaries to 32-bit float EXR and
# compares the files byte for byte. A change that keeps the arithmetic (traversal order, prefetching, memory
# layout) must pass this, which is stronger than the 1e-4 relative bound a change of the arithmetic would be
# held to; the 8-bit goldens alone could hide a difference below 1/255.
#
# Usage: bench/same_pixels.sh OLD_VRMLRAY NEW_VRMLRAY   (scenes from bench/peers.sh's folder, made if missing)
# Environment: CORPUS=1 also renders every readable file of ../shared/corpus (not the bad, warnings and
# errors folders) at 320x240 with each binary, from the file's own folder, and compares images and exit codes.
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
corpus_differ=0
if [ "${CORPUS:-0}" = 1 ]; then
    n=0
    while IFS= read -r f; do
        n=$((n + 1))
        for v in old new; do
            bin=$(realpath "${!v}")
            code=0
            (cd "$(dirname "$f")" && "$bin" render "$(basename "$f")" -W 320 -H 240 -o "$work/c_$v.exr" -q \
                >/dev/null 2>&1) || code=$?
            echo "$code" >"$work/c_$v.code"
        done
        if ! cmp -s "$work/c_old.code" "$work/c_new.code" ||
            { [ -e "$work/c_old.exr" ] && ! cmp -s "$work/c_old.exr" "$work/c_new.exr"; }; then
            echo "differs: $f"
            corpus_differ=$((corpus_differ + 1))
        fi
        rm -f "$work"/c_*.exr
    done < <(find "$root/../shared/corpus" -type f \( -name '*.wrl' -o -name '*.x3d' -o -name '*.x3dv' \
        -o -name '*.gz' -o -name '*.wrz' \) | grep -v '/bad\|/errors\|/warnings' | sort)
    echo "corpus: $n files, $corpus_differ differ"
fi
differ=0 n=0
for f in "$work/old"/*.exr; do
    n=$((n + 1))
    cmp -s "$f" "$work/new/$(basename "$f")" || { echo "differs: $(basename "$f")"; differ=$((differ + 1)); }
done
[ "$(ls "$work/new"/*.exr | wc -l)" -eq "$n" ] || { echo "the binaries wrote different image sets"; exit 1; }
echo "$n images, $differ differ"
[ "$differ" -eq 0 ] && [ "$corpus_differ" -eq 0 ]
