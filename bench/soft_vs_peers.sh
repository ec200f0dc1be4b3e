#!/usr/bin/env bash
# Soft light beside its peers at equal error: the peer harness's S2 molecule (../shared/bench: 10,000 atoms
# + 9,999 bond cylinders, written as .wrl, .dat and .pov by its generator), in two lightings, each the same
# in every renderer (docs/rendering.md, Soft light with error bounds):
#
#   sky   sky light only: colour = Kd * 0.7 * A(p), A = (1/pi) * integral of V max(n.w, 0) over the
#         hemisphere, no distance limit. vrmlray --sky 0.7,0.7,0.7; Tachyon -auto_skylight 0.7 (its sky
#         colour; it scales the direct lights by 0.3, and there are none) -skylight_samples N, whose
#         estimate (2/N) * sum of V cos over N uniform hemisphere directions is an unbiased estimate of A.
#         Tachyon's sky term, like its lights', is scaled by the texture's DIFFUSE (1 here) and COLOR (= Kd).
#         Its camera does not sample pixel centres: in this version (0.99~b6) the ray of pixel column j goes
#         through the image plane at j + 1 pixel widths from its left edge and row i (from the top) at H - i
#         pixel heights from its bottom, half a pixel right of and above the centre. At 96x54, where an atom is
#         a pixel or two, that half pixel alone gave an RMSE of 0.10 against vrmlray however many samples.
#         So Tachyon renders (W+1) x (H+1) pixels with ZOOM scaled by H/(H+1) (the same pixel size; its
#         image plane one pixel wider and taller), and the top row and right column are cut off: what
#         is left samples vrmlray's W x H pixel centres exactly. The extra row and column cost Tachyon
#         (W+H+1)/(W*H) more rays (3% at 96x54, 0.1% at 1920x1080), which its seconds include.
#   sky4  the sky lighting with 4 samples a pixel (a publication image's antialiasing): vrmlray
#         --sampler rgss (its --light-tolerance then bounds the error of each pixel's mean over its 4
#         samples), Tachyon the same with -aasamples 4 (its jittered samples about the pixel centre),
#         the reference vrmlray rgss at REF_TOL. The two samplers' edge positions differ, so Tachyon's RMSE
#         against the reference has a floor that its sky samples do not lower; its rmse(own) column shows
#         its own convergence. Target: at least 2x sooner than Tachyon at equal RMSE.
#   area  one area light only: colour = Kd * max(n.l, 0) * V_l, V_l = the share of the light seen, l towards
#         its centre. vrmlray: a PointLight with a sourceRadius hint (a sphere of radius R at distance D);
#         POV-Ray: `area_light` N x N, `circular orient` (a disc of radius R facing every shaded point, which
#         subtends atan(R/D) against the sphere's asin(R/D): 1e-4 relative here), `adaptive 1 jitter`.
#         POV-Ray, too, takes the diffuse term from the light's centre and scales it by the share of its
#         samples that see the light (area_illumination off, its default).
#         With `adaptive 1` it starts from 3x3 samples and refines only where they disagree, so bonds
#         that none of them sees stay unseen: its RMSE against vrmlray stops near 6e-3 at 480x270 whatever
#         N (bench/README.md, "Area light against POV-Ray").
# In both: no ambient term (Material ambientIntensity 0 / AMBIENT 0 / finish ambient 0), no highlights
# (specularColor 0 / PHONG 0 / specular 0), the harness's background, camera, pixel centres, one sample per
# pixel, linear output (vrmlray .exr, Tachyon PPM48, POV-Ray +FE File_Gamma 1: half floats, whose rounding
# is at most 2.8e-4 * value RMS, far below its area-light noise), 2 threads each.
# POV-Ray 3.7 needs no such cut: bench/pov_pixel_check.sh renders a disc through gen_scene.py's camera block
# in both, and at 64x36 and 63x35 POV-Ray's pixels are vrmlray's (0 pixels differ; the disc fits column
# j + a and row i + b only for a, b within 0.5 +- 0.01 at 64x36).
#
# Every image is measured against ONE reference, vrmlray at --light-tolerance REF_TOL (default 1e-4), with
# `vrmlray compare --json`; a peer's images also against its own best setting (its own convergence). Then,
# for each peer, the time vrmlray needs to reach the peer's best RMSE (the least time of a vrmlray setting at
# or below it) against the peer's time for that RMSE; the target is a ratio of at least 5 (sky, area) or 2
# (sky4).
#
#   bench/soft_vs_peers.sh [VRMLRAY_BINARY] [WIDTH HEIGHT] [RUNS]    (default build/vrmlray 1920 1080 1)
# Environment: MODES ("sky area sky4"), TOLS ("3e-1 2.5e-1 2e-1 1e-1 3e-2 1e-2 3e-3 1e-3"), REF_TOL (1e-4; REF_TOL_SKY and
# REF_TOL_AREA for one mode), REF_SEED (7: --seed of the reference), TACHYON_N ("4 16 64 256"),
# POV_N ("3 5 9 17 33"), MAX_SECONDS (a renderer's ladder stops once a median passes it; default 600),
# EQUAL_TOL (sky4: the vrmlray tolerance Tachyon is matched to at equal RMSE, below; default 2e-2).
# Seconds are whole-process wall time, the median of RUNS runs.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=$(realpath "${1:-$root/build/vrmlray}")
width=${2:-1920}
height=${3:-1080}
runs=${4:-1}
modes=${MODES:-sky area sky4}
tols=${TOLS:-3e-1 2.5e-1 2e-1 1e-1 3e-2 1e-2 3e-3 1e-3}
ref_tol=${REF_TOL:-1e-4}
# The reference's own seed, so that its (small) error is independent of the images': with their seed (0)
# its sampling path would start on their very rays, as each point's sequence is nested.
ref_seed=${REF_SEED:-7}
tachyon_n=${TACHYON_N:-4 16 64 256}
pov_n=${POV_N:-3 5 9 17 33}
max_seconds=${MAX_SECONDS:-600}
harness=$root/../shared/bench
work=${TMPDIR:-/tmp}/vrmlray_soft_vs_peers
mkdir -p "$work"
cd "$work"
"$root/tools/setup.sh" tachyon povray python3-numpy
[ -s S2_molecule_10k.wrl ] && [ -s S2_molecule_10k.dat ] && [ -s S2_molecule_10k.pov ] ||
    /usr/bin/python3 "$harness/gen_scene.py" "$harness/specs/s2_molecule_10k.json" --out "$work" \
        --formats wrl,dat,pov >/dev/null

# The two lightings, edited from the harness's files. The area light sits 200 A from the scene's centre,
# against the harness's directional light, with radius 20 (0.1 rad: penumbrae of ~0.5 A at 5 A).
/usr/bin/python3 - <<'EOF'
import re
wrl, dat, pov = (open("S2_molecule_10k." + e).read() for e in ("wrl", "dat", "pov"))
m = re.search(r"parallel point_at <([-\d.]+),([-\d.]+),([-\d.]+)> \}  // directional, direction <([-\d.]+),"
              r"([-\d.]+),([-\d.]+)>", pov)
assert m, "no directional light in the .pov"
centre, direction = [float(v) for v in m.groups()[:3]], [float(v) for v in m.groups()[3:]]
distance, radius = 200.0, 20.0
light = [c - distance * d for c, d in zip(centre, direction)]

def matte_wrl(text):
    text, n = re.subn(r"specularColor [\d.]+ [\d.]+ [\d.]+ shininess ([\d.]+) ambientIntensity [\d.]+",
                      r"specularColor 0 0 0 shininess \1 ambientIntensity 0", text)
    assert n > 0
    return text

sky = re.sub(r"DirectionalLight \{[^}]*\}\n", "", matte_wrl(wrl))
assert "DirectionalLight" not in sky
open("sky.wrl", "w").write(sky)
area = re.sub(r"DirectionalLight \{[^}]*\}\n",
              "PointLight { location %.4f %.4f %.4f color 1 1 1 intensity 1 ambientIntensity 0 attenuation 1 0 0 "
              "radius 1e9 metadata MetadataSet { name \"vrmlray\" value [ MetadataFloat { name \"sourceRadius\" "
              "value %g } ] } }\n" % (*light, radius), matte_wrl(wrl))
open("area.wrl", "w").write(area)

sky_dat = re.sub(r"DIRECTIONAL_LIGHT [^\n]*\n", "", dat)
sky_dat, n = re.subn(r"AMBIENT [\d.]+ (.*) PHONG PLASTIC [\d.]+ ", r"AMBIENT 0 \1 PHONG PLASTIC 0 ", sky_dat)
assert n == 8 and "LIGHT" not in sky_dat
open("sky.dat", "w").write(sky_dat)

area_pov, n = re.subn(r"finish \{ ambient [\d.]+ diffuse 1 specular [\d.]+ ", "finish { ambient 0 diffuse 1 specular 0 ",
                      pov)
assert n == 8
area_pov, n = re.subn(r"light_source \{[^\n]*\n",
                      "light_source { <%.4f,%.4f,%.4f> color rgb 1 area_light <%g,0,0>, <0,%g,0>, AREA_N, AREA_N "
                      "adaptive 1 jitter circular orient }\n" % (*light, 2 * radius, 2 * radius), area_pov)
assert n == 1
open("area.pov.in", "w").write(area_pov)
EOF

# Tachyon at WIDTH+1 x HEIGHT+1 on the same pixel pitch (see the header), and the cut back to W x H.
/usr/bin/python3 - "$height" <<'EOF'
import re, sys
h = int(sys.argv[1])
dat = open("sky.dat").read()
dat, n = re.subn(r"ZOOM ([\d.]+)", lambda m: "ZOOM %.9f" % (float(m.group(1)) * h / (h + 1)), dat)
assert n == 1
open("sky_grid.dat", "w").write(dat)
EOF
tachyon_cut() {  # IN.ppm OUT.ppm: drop the top row and the right column of a PPM48
    PYTHONPATH="$root/bench" /usr/bin/python3 - "$1" "$2" <<'EOF'
import sys
from ppm48 import read_ppm48, write_ppm48
write_ppm48(sys.argv[2], read_ppm48(sys.argv[1])[1:, :-1])
EOF
}

median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
wall() {  # wall seconds of one command; its output to log
    local t0=$EPOCHREALTIME
    "$@" >log 2>&1 || { cat log >&2; return 1; }
    awk -v a="$t0" -v b="$EPOCHREALTIME" 'BEGIN {printf "%.3f\n", b - a}'
}
timed() { for r in $(seq "$runs"); do wall "$@"; done | median; }
rmse() { "$bin" compare "$1" "$2" --json 2>/dev/null | grep -o '"rmse": [-0-9.e+]*' | awk '{print $2}' || true; }
too_slow() { awk -v t="$1" -v m="$max_seconds" 'BEGIN {exit !(t > m)}'; }
vr() {  # MODE TOLERANCE OUT [SEED [OPTION ...]]
    local extra=() scene=$1
    [ "$1" = sky ] && extra=(--sky 0.7,0.7,0.7)
    [ "$1" = sky4 ] && extra=(--sky 0.7,0.7,0.7 --sampler rgss) && scene=sky
    "$bin" render "$scene.wrl" -W "$width" -H "$height" --threads 2 -q "${extra[@]}" --light-tolerance "$2" \
        --seed "${4:-0}" "${@:5}" -o "$3"
}

# sky4 at equal RMSE. Tachyon's jittered antialiasing samples other points of each pixel than rgss,
# which leaves it an RMSE against vrmlray's reference that no sky sample count lowers (its edges, not
# its sky light), so equal RMSE is taken as equal sky-light error, each against its own converged
# image: vrmlray's RMSE at EQUAL_TOL (default 2e-2, the default --light-tolerance) against the 1e-4
# reference; Tachyon's per-sample variance s2 from its ladder against its own largest N, M (the same
# jittered positions at every N: its RMSE^2 against M is s2 (1/N + 1/M), each N's s2 printed, the
# median used), so that N = s2 / RMSE^2 skylight samples give vrmlray's RMSE. Tachyon is then timed at
# that N and the two times compared (target: vrmlray at least 2x sooner).
tachyon_at_equal_rmse() {  # Tachyon's ladder images, largest N last
    local equal_tol=${EQUAL_TOL:-2e-2} ns=($tachyon_n) e_vr t_vr s2 n_eq t_t e_t
    read -r t_vr e_vr < <(awk -F'\t' -v tol="tolerance $equal_tol" '$1 == "sky4" && $2 == "vrmlray" && $3 == tol {print $4, $5}' "$rows") || true
    [ -n "$e_vr" ] || { echo "sky4 equal RMSE: no vrmlray row at tolerance $equal_tol (TOLS)" >&2; return 0; }
    local m=${ns[$((${#images[@]} - 1))]} list=()
    for ((i = 0; i < ${#images[@]} - 1; i++)); do
        local e
        e=$(rmse "${images[$i]}" "${images[-1]}")
        list+=("$(awk -v e="$e" -v n="${ns[$i]}" -v m="$m" 'BEGIN {printf "%.6e", e * e / (1 / n + 1 / m)}')")
    done
    s2=$(printf '%s\n' "${list[@]}" | median)
    n_eq=$(awk -v s="$s2" -v e="$e_vr" 'BEGIN {n = s / (e * e); printf "%d", n == int(n) ? n : int(n) + 1}')
    t_t=$(timed tachyon sky_grid.dat -numthreads 2 -res $((width + 1)) $((height + 1)) -fullshade -aasamples 4 \
        -auto_skylight 0.7 -skylight_samples "$n_eq" -format PPM48 -o t_sky4_eq_grid.ppm)
    tachyon_cut t_sky4_eq_grid.ppm t_sky4_eq.ppm
    e_t=$(rmse t_sky4_eq.ppm "${images[-1]}")
    echo "sky4 equal RMSE: Tachyon's per-sample variance s2 at N = ${ns[*]:0:${#list[@]}} against N = $m: ${list[*]}, median $s2"
    echo "sky4 equal RMSE: vrmlray tolerance $equal_tol RMSE $e_vr in $t_vr s; Tachyon -skylight_samples $n_eq" \
        "(sqrt(s2 / N) = $(awk -v s="$s2" -v n="$n_eq" 'BEGIN {printf "%.3e", sqrt(s / n)}'); against N = $m: $e_t," \
        "expected $(awk -v s="$s2" -v n="$n_eq" -v m="$m" 'BEGIN {printf "%.3e", sqrt(s * (1 / n + 1 / m))}')) in $t_t s:" \
        "$(awk -v a="$t_t" -v b="$t_vr" 'BEGIN {r = a / b; printf "vrmlray %.2fx sooner (target 2x: %s)", r, (r >= 2 ? "met" : "MISSED")}')"
}

echo "load: $(cat /proc/loadavg)  size ${width}x$height  runs $runs"
rows=$work/rows_${modes// /_}_${width}x$height.tsv  # one per run, so that runs of other modes may overlap
: >"$rows"
printf '%-5s %-8s %-18s %9s %11s %11s\n' mode renderer setting seconds rmse "rmse(own)"
for mode in $modes; do
    rt=$ref_tol
    [ "$mode" = sky ] && rt=${REF_TOL_SKY:-$ref_tol}
    [ "$mode" = area ] && rt=${REF_TOL_AREA:-$ref_tol}
    # The reference estimates every sample on its own (--sky-share 1): no interpolation error in it.
    ref=${mode}_ref_${width}x${height}_${rt}_seed${ref_seed}_share1.exr
    [ -s "$ref" ] || { t=$(wall vr "$mode" "$rt" "$ref" "$ref_seed" --sky-share 1); echo "reference $ref: $t s" >&2; }
    for tol in $tols; do
        t=$(timed vr "$mode" "$tol" "v_$mode.exr")
        e=$(rmse "v_$mode.exr" "$ref")
        printf '%-5s %-8s %-18s %9.3f %11.3e %11s\n' "$mode" vrmlray "tolerance $tol" "$t" "$e" -
        printf '%s\tvrmlray\ttolerance %s\t%s\t%s\n' "$mode" "$tol" "$t" "$e" >>"$rows"
        if too_slow "$t"; then break; fi
    done
    images=()
    if [ "$mode" = sky ] || [ "$mode" = sky4 ]; then
        peer=Tachyon
        aa=()
        [ "$mode" = sky4 ] && aa=(-aasamples 4)
        for n in $tachyon_n; do
            t=$(timed tachyon sky_grid.dat -numthreads 2 -res $((width + 1)) $((height + 1)) -fullshade \
                "${aa[@]}" -auto_skylight 0.7 -skylight_samples "$n" -format PPM48 -o "t_${mode}_${n}_grid.ppm")
            tachyon_cut "t_${mode}_${n}_grid.ppm" "t_${mode}_$n.ppm"
            images+=("t_${mode}_$n.ppm")
            printf '%s\tTachyon\tskylight_samples %s\t%s\t%s\n' "$mode" "$n" "$t" "$(rmse "t_${mode}_$n.ppm" "$ref")" >>"$rows"
            if too_slow "$t"; then break; fi
        done
    else
        peer=POV-Ray
        for n in $pov_n; do
            sed "s/AREA_N/$n/g" area.pov.in >"area_$n.pov"
            t=$(timed povray -D -P -V +WT2 -A +W"$width" +H"$height" +FE +O"p_$n.exr" File_Gamma=1.0 "area_$n.pov")
            images+=("p_$n.exr")
            printf '%s\tPOV-Ray\tarea_light %sx%s\t%s\t%s\n' "$mode" "$n" "$n" "$t" "$(rmse "p_$n.exr" "$ref")" >>"$rows"
            if too_slow "$t"; then break; fi
        done
    fi
    [ "$mode" = sky4 ] && [ "${#images[@]}" -ge 2 ] && tachyon_at_equal_rmse "${images[@]}"
    # The peer's rows, with the RMSE against its own best setting (the last) as well.
    i=0
    grep -P "^$mode\t$peer\t" "$rows" | while IFS=$'\t' read -r _ _ setting t e; do
        printf '%-5s %-8s %-18s %9.3f %11.3e %11.3e\n' "$mode" "$peer" "$setting" "$t" "$e" \
            "$(rmse "${images[$i]}" "${images[-1]}")"
        i=$((i + 1))
    done
done

echo
/usr/bin/python3 - "$rows" <<'EOF'
import sys
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1]) if l.strip()]
for mode in dict.fromkeys(r[0] for r in rows):
    mine = [(float(r[3]), float(r[4]), r[2]) for r in rows if r[0] == mode and r[1] == "vrmlray"]
    peers = [r for r in rows if r[0] == mode and r[1] != "vrmlray"]
    if not peers:
        continue
    if mode == "sky4":
        continue  # compared at equal sky-light RMSE above: its best RMSE here is its antialiasing's floor
    best = min(peers, key=lambda r: float(r[4]))
    t_peer, e_peer = float(best[3]), float(best[4])
    reach = [m for m in mine if m[1] <= e_peer]
    if not reach:
        print("%s: %s's best RMSE %.3e (%s, %.2f s): not reached by vrmlray on its ladder: MISSED" %
              (mode, best[1], e_peer, best[2], t_peer))
        continue
    t_me, e_me, setting = min(reach)
    ratio = t_peer / t_me
    target = 2 if mode == "sky4" else 5
    print("%s: %s's best RMSE %.3e (%s) in %.2f s; vrmlray %.3e (%s) in %.2f s: %.1fx sooner, target %dx %s" %
          (mode, best[1], e_peer, best[2], t_peer, e_me, setting, t_me, ratio, target,
           "met" if ratio >= target else "MISSED"))
EOF
