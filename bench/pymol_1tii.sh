#!/usr/bin/env bash
# The publication-figure peer: PyMOL's own ray of 1tii (5,684 atoms, the structure PyMOL's demo data ships;
# Debian's pymol-data) beside the VRML file PyMOL exports of the same view, so that vrmlray's render of the
# export can be timed and looked at against PyMOL's picture of the same structure at the same size.
#
# Usage: bench/pymol_1tii.sh [WIDTH HEIGHT]      (default 1920 1080)
# Writes to ${OUT:-/tmp/vrmlray_pymol}: 1tii.wrl (PyMOL's `save`, its default representation: cartoon, ligand
# sticks, waters), pymol_WxH.png (PyMOL `ray` with antialias 2 and shadows) and pymol_WxH.time
# (/usr/bin/time's wall and CPU seconds of the whole PyMOL process, start-up included).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
w=${1:-1920} h=${2:-1080}
out=${OUT:-/tmp/vrmlray_pymol}
"$root/tools/setup.sh" pymol >/dev/null
pdb=/usr/share/pymol/data/demo/1tii.pdb
mkdir -p "$out"
# PyMOL runs on Debian's python3, whatever python3 comes first on PATH.
export PATH=/usr/bin:$PATH
[ -s "$out/1tii.wrl" ] || pymol -cq "$pdb" -d "save $out/1tii.wrl" >/dev/null
/usr/bin/time -f "%e s wall, %U s user, %S s sys" -o "$out/pymol_${w}x${h}.time" \
    pymol -cq "$pdb" -d "set antialias, 2; set ray_shadows, 1; viewport $w,$h; ray $w,$h; png $out/pymol_${w}x${h}.png" \
    >/dev/null
echo "export: $out/1tii.wrl ($(stat -c %s "$out/1tii.wrl") bytes)"
echo "pymol ray ${w}x${h}: $(cat "$out/pymol_${w}x${h}.time")"
