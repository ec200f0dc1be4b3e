#!/usr/bin/env bash
# Sky light on a real molecule against PyMOL's own ray of it (issue 46's publication-figure target):
# PyMOL's export of 1tii (bench/pymol_1tii.sh: 5,684 atoms as cartoon triangles, sticks and spheres)
# rendered by vrmlray with the sky light a publication figure uses, against PyMOL `ray W,H` (antialias 2,
# shadows) of the same structure timed in the same run. Target: vrmlray at most 4x PyMOL's wall time.
#
#   bench/soft_1tii.sh [VRMLRAY_BINARY] [WIDTH HEIGHT] [RUNS]     (default build/vrmlray 1920 1080 3)
# Environment: VR_ARGS (the render's options; default the publication sky light:
#   --sampler rgss --sky 0.5,0.5,0.5 --ao-distance 10 --srgb), TOL (--light-tolerance; default: vrmlray's),
#   CONVERGENCE=1 also measures the image error at a reduced size (CW x CH, default 240 x 135): RMSE of the
#   render (linear EXR) against a --light-tolerance 1e-4 reference (--seed 7, cached in the work folder),
#   against half an 8-bit step (1.96e-3).
# Seconds are whole-process wall time, the median of RUNS runs for each renderer, taken alternately
# (PyMOL, vrmlray, PyMOL, ...) so that both see the same load.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=$(realpath "${1:-$root/build/vrmlray}")
width=${2:-1920}
height=${3:-1080}
runs=${4:-3}
read -r -a vr_args <<<"${VR_ARGS:---sampler rgss --sky 0.5,0.5,0.5 --ao-distance 10 --srgb}"
[ -n "${TOL:-}" ] && vr_args+=(--light-tolerance "$TOL")
export OUT=${OUT:-/tmp/vrmlray_pymol}
wrl=$OUT/1tii.wrl
median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
wall() {  # wall seconds of one command
    local t0=$EPOCHREALTIME
    "$@" >/dev/null 2>&1
    awk -v a="$t0" -v b="$EPOCHREALTIME" 'BEGIN {printf "%.3f\n", b - a}'
}

echo "load: $(cat /proc/loadavg)  size ${width}x$height  runs $runs  vrmlray ${vr_args[*]}"
pymol_times=() vr_times=()
for r in $(seq "$runs"); do
    "$root/bench/pymol_1tii.sh" "$width" "$height" >/dev/null
    pymol_times+=("$(awk '{print $1}' "$OUT/pymol_${width}x${height}.time")")
    vr_times+=("$(wall "$bin" render "$wrl" -W "$width" -H "$height" "${vr_args[@]}" -q \
        -o "$OUT/vrmlray_${width}x${height}.png")")
done
tp=$(printf '%s\n' "${pymol_times[@]}" | median)
tv=$(printf '%s\n' "${vr_times[@]}" | median)
echo "pymol   ray ${width}x$height: ${pymol_times[*]} s, median $tp s"
echo "vrmlray     ${width}x$height: ${vr_times[*]} s, median $tv s"
awk -v p="$tp" -v v="$tv" 'BEGIN {r = v / p; printf "vrmlray / PyMOL: %.2fx (target <= 4x: %s)\n", r, r <= 4 ? "met" : "MISSED"}'

if [ "${CONVERGENCE:-0}" = 1 ]; then
    cw=${CW:-240} ch=${CH:-135}
    lin=()
    for a in "${vr_args[@]}"; do [ "$a" != --srgb ] && lin+=("$a"); done  # EXR is linear anyway
    ref=$OUT/ref_${cw}x${ch}_1e-4.exr
    [ -s "$ref" ] || "$bin" render "$wrl" -W "$cw" -H "$ch" "${lin[@]}" --light-tolerance 1e-4 --seed 7 -q -o "$ref"
    "$bin" render "$wrl" -W "$cw" -H "$ch" "${lin[@]}" -q -o "$OUT/img_${cw}x$ch.exr"
    e=$("$bin" compare "$OUT/img_${cw}x$ch.exr" "$ref" --json 2>/dev/null | grep -o '"rmse": [-0-9.e+]*' | awk '{print $2}')
    awk -v e="$e" 'BEGIN {printf "RMSE against the 1e-4 reference: %.3e (half an 8-bit step 1.96e-3: %s)\n", e,
        e < 0.5 / 255 ? "below" : "ABOVE"}'
fi
