#!/usr/bin/env bash
# Soft light: time and achieved error against --light-tolerance (docs/rendering.md, Soft light with error bounds) on a real molecule.
# The molecule (default: Jmol's c551_spacefill.wrl from the shared corpus, 1,216 atoms as exact spheres)
# is Inlined under one sphere light; every render is compared with a reference at tolerance 1e-6.
# The colour error of a pixel is at most diffuse * (sky * dA + light * dV) <= (0.45 + 1) * E here, so
# the largest pixel error must stay below 1.45 E. Peers (Tachyon -auto_skylight, POV-Ray area_light)
# are not measured yet.
# Usage: bench/soft_light.sh BUILD/vrmlray [MOLECULE.wrl] [SIZE]
set -euo pipefail
bin=$(realpath "$1")
molecule=$(realpath "${2:-$(dirname "$0")/../../shared/corpus/molecular/jmol/c551_spacefill.wrl}")
size=${3:-160}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cat >"$work/scene.wrl" <<EOF
#VRML V2.0 utf8
NavigationInfo { headlight FALSE }
Viewpoint { fieldOfView 0.2837941 position 0 0 1449.122 }
PointLight { location -500 700 900 intensity 1 radius 1e6
  metadata MetadataSet { name "vrmlray" value [ MetadataFloat { name "sourceRadius" value 120 } ] } }
Inline { url "$molecule" }
EOF
common=(--recover-spheres -W "$size" -H "$size" --sky 0.45,0.45,0.45 --ao-distance 60 -q)
echo "load: $(cat /proc/loadavg)"
"$bin" render "$work/scene.wrl" "${common[@]}" --light-tolerance 1e-6 -o "$work/ref.exr"
printf '%-10s %8s %12s %12s\n' tolerance seconds rmse max_abs
for e in 1e-1 3e-2 1e-2 3e-3 1e-3 1e-4; do
    start=$(date +%s.%N)
    "$bin" render "$work/scene.wrl" "${common[@]}" --light-tolerance "$e" -o "$work/e.exr"
    end=$(date +%s.%N)
    "$bin" compare "$work/e.exr" "$work/ref.exr" --json >"$work/c.json" || true
    python3 - "$e" "$start" "$end" "$work/c.json" <<'PY'
import json, sys
e, start, end, path = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
c = json.load(open(path))
flag = "" if c["max_abs"] <= 1.45 * float(e) else "  ABOVE 1.45 E"
print(f"{e:<10} {end - start:8.2f} {c['rmse']:12.3g} {c['max_abs']:12.3g}{flag}")
PY
done
