#!/usr/bin/env bash
# Lit gas: render time against error for one or more vrmlray binaries, measured in the same run.
#
#   bench/gas_speed.sh [RUNS] BINARY...        e.g. bench/gas_speed.sh 3 /tmp/vrmlray-old build/vrmlray
#
# Scenes: the 60,000-atom molecule of tools/gen_molecule.py (no bonds, density 1, one shadowing
# directional light) at 480x270, and the harness's S4 (../shared/bench, 1,000 overlapping spheres,
# sigma 0.08) lit by its directional light at 640x480. Every binary renders each scene at tolerances
# 1e-2 .. 1e-6 (2 threads, RUNS times, interleaved so that the machine's load hits them alike); the error
# is measured against a reference rendered by the LAST binary at --tolerance 1e-9, with `vrmlray compare
# --json` (RMSE and largest pixel difference on the linear EXR). Printed per setting: the median render
# seconds (the "render" phase of --stats, so start-up and parsing are left out) and the errors. A binary
# whose median passes MAX_SECONDS (default 60) is not run at the tighter tolerances of that scene.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
runs=${1:-3}
shift || true
bins=("$@")
[ ${#bins[@]} -eq 0 ] && bins=("$root/build/vrmlray")
ref_bin=${bins[${#bins[@]} - 1]}
harness=$root/../shared/bench
work=${TMPDIR:-/tmp}/vrmlray_gas_speed
mkdir -p "$work"
"$root/tools/setup.sh" python3-numpy
[ -s "$work/mol60k.wrl" ] || python3 "$root/tools/gen_molecule.py" 60000 "$work/mol60k.wrl" --no-bonds
[ -s "$work/S4_gas_1k.wrl" ] || /usr/bin/python3 "$harness/gen_scene.py" "$harness/specs/s4_gas_1k.json" \
    --out "$work" --formats wrl >/dev/null
# name | file | size | options
scenes=("mol60k|mol60k.wrl|480 270|--spheres gas"
        "S4|S4_gas_1k.wrl|640 480|--spheres gas --density 0.08")
tolerances=(1e-2 1e-3 1e-4 1e-5 1e-6)
max_seconds=${MAX_SECONDS:-60}
median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
field() { grep -o "\"$1\": [-0-9.e+]*" | head -1 | awk '{print $2}'; }
render() {  # BINARY SCENE W H TOL OPTIONS OUT -> render seconds
    local bin=$1 scene=$2 w=$3 h=$4 tol=$5 opts=$6 out=$7
    # shellcheck disable=SC2086
    "$bin" render "$work/$scene" -W "$w" -H "$h" --threads 2 --tolerance "$tol" $opts -o "$out" \
        --stats "$work/stats.json" -q
    field render <"$work/stats.json"
}
printf '%-7s %-40s %8s %10s %11s %11s\n' scene binary tol seconds rmse max_abs
for entry in "${scenes[@]}"; do
    IFS='|' read -r name scene size opts <<<"$entry"
    read -r w h <<<"$size"
    ref=$work/${name}_ref_${w}x$h.exr
    [ -s "$ref" ] || render "$ref_bin" "$scene" "$w" "$h" 1e-9 "$opts" "$ref" >/dev/null
    declare -A slow=()
    for tol in "${tolerances[@]}"; do
        declare -A times=()
        for r in $(seq "$runs"); do
            for i in "${!bins[@]}"; do
                [ -n "${slow[$i]:-}" ] && continue
                times[$i]+="$(render "${bins[$i]}" "$scene" "$w" "$h" "$tol" "$opts" "$work/${name}_$i.exr") "
            done
        done
        for i in "${!bins[@]}"; do
            [ -n "${slow[$i]:-}" ] && continue
            # shellcheck disable=SC2086
            t=$(printf '%s\n' ${times[$i]} | median)
            awk -v t="$t" -v m="$max_seconds" 'BEGIN {exit !(t > m)}' && slow[$i]=1
            json=$("${bins[$i]}" compare "$work/${name}_$i.exr" "$ref" --json || true)
            printf '%-7s %-40s %8s %10.3f %11.3e %11.3e\n' "$name" "${bins[$i]}" "$tol" "$t" \
                "$(field rmse <<<"$json")" "$(field max_abs <<<"$json")"
        done
        unset times
    done
    unset slow
done
