#!/usr/bin/env bash
# Gas volumes: vrmlray beside POV-Ray's media at equal error. Both render the peer harness's S4 scene
# (../shared/bench: 1,000 overlapping spheres of constant density, sigma 0.08, written as .wrl and .pov by
# its generator) at rising quality; every image is measured against one high-precision vrmlray reference
# with `vrmlray compare --json`, so that "time to reach error E" can be read off for each renderer.
#
#   bench/gas_vs_povray.sh [VRMLRAY_BINARY] [RUNS] [WIDTH HEIGHT]     (default build/vrmlray 3 640 480)
#
# Two models, each the same in both renderers:
#   S4     emission-absorption, exactly the harness's files: POV media `emission sigma*colour absorption
#          sigma`; vrmlray --spheres gas --density 0.08 --albedo 0,0,0 (emissiveColor = colour). vrmlray
#          integrates this in closed form, so its tolerance changes nothing.
#   S4lit  the same plus single scattering of the directional light with self-shadowing (albedo = the
#          material's colour): the harness's files are edited here, not regenerated. POV: absorption
#          sigma*(1-colour), `scattering { 1, sigma*colour }` (isotropic; POV-Ray weighs it with phase 1,
#          not 1/4pi, which is vrmlray's sigma*rho*c*i*V), `media_attenuation on` on the light so that its
#          light is dimmed by the gas on the way; vrmlray --density 0.08 with albedo = diffuseColor and the
#          light's ambientIntensity set to 0 in the .wrl (POV-Ray's media have no ambient term).
# Camera, pixel centres, colours and the linear output (POV: File_Gamma 1, +FE OpenEXR; vrmlray: .exr) are
# the harness's own conventions; no antialiasing on either side; 2 threads each; seconds are whole-process
# wall time, median of RUNS. POV-Ray's quality ladder is `intervals` (1 .. 64, the harness uses 1) with
# its default adaptive method 3 (aa_level 3, aa_threshold 0.1); vrmlray's is --tolerance. A renderer is not
# run at higher settings once its median passes MAX_SECONDS (default 150).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=$(realpath "${1:-$root/build/vrmlray}")
runs=${2:-3}
width=${3:-640}
height=${4:-480}
max_seconds=${MAX_SECONDS:-150}
harness=$root/../shared/bench
work=${TMPDIR:-/tmp}/vrmlray_gas_vs_povray
mkdir -p "$work"
cd "$work"
"$root/tools/setup.sh" povray python3-numpy
[ -s S4_gas_1k.wrl ] && [ -s S4_gas_1k.pov ] ||
    /usr/bin/python3 "$harness/gen_scene.py" "$harness/specs/s4_gas_1k.json" --out "$work" --formats wrl,pov >/dev/null

# The lit variant: per material (listed in the .wrl's header by the generator) the POV interior gets
# absorption sigma*(1-colour) and scattering sigma*colour; the light gets media_attenuation.
/usr/bin/python3 - <<'EOF'
import re
wrl = open("S4_gas_1k.wrl").read()
mats = {int(m.group(1)): ([float(v) for v in m.group(2).split()], float(m.group(3)))
        for m in re.finditer(r"#   material (\d+): diffuseColor ([-\d. ]+?) sigma ([\d.]+) emission", wrl)}
assert mats, "no material lines in the .wrl header"
lit = re.sub(r"(DirectionalLight \{[^}]*ambientIntensity) 1", r"\1 0", wrl)
assert lit != wrl, "no DirectionalLight ambientIntensity 1 to switch off"
open("S4lit.wrl", "w").write(lit)
out = []
for line in open("S4_gas_1k.pov"):
    m = re.match(r"#declare I(\d+) = interior", line)
    if m:
        rho, sigma = mats[int(m.group(1))]
        absorption = ",".join("%.6f" % (sigma * (1 - c)) for c in rho)
        scattering = ",".join("%.6f" % (sigma * c) for c in rho)
        line, n = re.subn(r"absorption <[^>]*>", "absorption <%s> scattering { 1, <%s> }" % (absorption, scattering),
                          line)
        assert n == 1
    elif line.startswith("light_source"):
        line = line.replace(" parallel ", " parallel media_attenuation on ")
    out.append(line)
open("S4lit.pov", "w").write("".join(out))
EOF

median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
wall() {  # wall seconds of one command
    local t0 t1
    t0=$(date +%s.%N); "$@" >/dev/null 2>&1; t1=$(date +%s.%N)
    awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.4f\n", b - a}'
}
field() { grep -o "\"$1\": [-0-9.e+]*" | head -1 | awk '{print $2}'; }
report() {  # SCENE RENDERER SETTING SECONDS IMAGE REFERENCE
    local json
    json=$("$bin" compare "$5" "$6" --json || true)
    printf '%-6s %-8s %-16s %9.3f %11.3e %11.3e %11.3e\n' "$1" "$2" "$3" "$4" "$(field rmse <<<"$json")" \
        "$(field mean_abs <<<"$json")" "$(field max_abs <<<"$json")"
}
too_slow() { awk -v t="$1" -v m="$max_seconds" 'BEGIN {exit !(t > m)}'; }

printf '%-6s %-8s %-16s %9s %11s %11s %11s\n' scene renderer setting seconds rmse mean_abs max_abs
for scene in S4 S4lit; do
    if [ $scene = S4 ]; then
        wrl=S4_gas_1k.wrl pov=S4_gas_1k.pov opts="--spheres gas --density 0.08 --albedo 0,0,0" tols="1e-2 1e-6"
    else
        wrl=S4lit.wrl pov=S4lit.pov opts="--spheres gas --density 0.08" tols="1e-1 1e-2 1e-3 1e-4 1e-5 1e-6"
    fi
    ref=${scene}_reference_${width}x$height.exr
    # shellcheck disable=SC2086
    [ -s "$ref" ] || "$bin" render $wrl -W "$width" -H "$height" --threads 2 $opts --tolerance 1e-9 -o "$ref" -q
    for n in 1 2 4 8 16 32 64; do
        sed "s/media { method 3 intervals [0-9]* /media { method 3 intervals $n /" "$pov" >"${scene}_i$n.pov"
        t=$(for r in $(seq "$runs"); do
            wall povray -D -P +WT2 -A +W"$width" +H"$height" +FE +O"${scene}_pov.exr" File_Gamma=1.0 "${scene}_i$n.pov"
        done | median)
        report $scene POV-Ray "intervals $n" "$t" "${scene}_pov.exr" "$ref"
        if too_slow "$t"; then break; fi
    done
    for tol in $tols; do
        # shellcheck disable=SC2086
        t=$(for r in $(seq "$runs"); do
            wall "$bin" render $wrl -W "$width" -H "$height" --threads 2 $opts --tolerance "$tol" -o "${scene}_v.exr" -q
        done | median)
        report $scene vrmlray "tolerance $tol" "$t" "${scene}_v.exr" "$ref"
        if too_slow "$t"; then break; fi
    done
done
