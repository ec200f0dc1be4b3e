#!/usr/bin/env bash
# Does Tachyon's sky light compute docs/rendering.md, Soft light with error bounds's A(p), and where do its pixels look? The simplest scene with a
# closed form: a plane y = 0 (Tachyon PLANE, green) under one sphere of radius r = 1 at height h = 2 (red),
# seen straight down by a pinhole camera 20 above the plane whose image spans 10 x 10 of it. On the plane,
# at a distance s from the sphere's foot, d^2 = s^2 + h^2 and cos(theta) = h/d, so
#     green = 0.7 * A = 0.7 * (1 - (r/d)^2 h/d)       (Tachyon -auto_skylight 0.7, COLOR 0 1 0, DIFFUSE 1)
# The sphere alone (no plane) has A = 1 everywhere: red = 0.7.
# Tachyon renders twice: at W x H as is, and on vrmlray's pixel centres the way soft_vs_peers.sh does it
# ((W+1) x (H+1), ZOOM * H/(H+1), top row and right column cut). Printed: pixels against the closed form,
# the sphere's rows and columns (a centred sphere covers the same number of pixels on each side of the
# image's centre), and the sphere-alone mean. vrmlray's side of the same closed form is a unit test
# (SoftLight.SkyLightOfAPlanePointUnderOneSphereIsTheClosedForm).
#   bench/tachyon_sky_check.sh [SIZE] [SAMPLES]    (default 50 16384)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
size=${1:-50}
samples=${2:-16384}
work=${TMPDIR:-/tmp}/vrmlray_tachyon_sky_check
mkdir -p "$work"
cd "$work"
"$root/tools/setup.sh" tachyon python3-numpy

scene() {  # ZOOM PLANE(0/1)
    cat <<EOF
BEGIN_SCENE
  RESOLUTION $size $size
CAMERA
  PROJECTION PERSPECTIVE
  ZOOM $1
  ASPECTRATIO 1.0
  ANTIALIASING 0
  RAYDEPTH 1
  CENTER 0 20 0
  VIEWDIR 0 -1 0
  UPDIR 0 0 1
END_CAMERA
BACKGROUND 0 0 0
TEXDEF TP AMBIENT 0 DIFFUSE 1.0 SPECULAR 0.0 OPACITY 1.0 PHONG PLASTIC 0 PHONG_SIZE 25.6 COLOR 0 1 0 TEXFUNC 0
TEXDEF TS AMBIENT 0 DIFFUSE 1.0 SPECULAR 0.0 OPACITY 1.0 PHONG PLASTIC 0 PHONG_SIZE 25.6 COLOR 1 0 0 TEXFUNC 0
$([ "$2" = 1 ] && echo "PLANE CENTER 0 0 0 NORMAL 0 1 0 TP")
SPHERE CENTER 0 2 0 RAD 1 TS
END_SCENE
EOF
}
# ZOOM = 0.5 / tan(half the vertical field): the image's half height, 5, seen from 20.
zoom=2.0
zoom_grid=$(awk -v z=$zoom -v h="$size" 'BEGIN {printf "%.9f", z * h / (h + 1)}')
scene $zoom 1 >plane.dat
scene "$zoom_grid" 1 >plane_grid.dat
scene $zoom 0 >sphere.dat
sky=(-fullshade -auto_skylight 0.7 -skylight_samples "$samples" -numthreads 2 -format PPM48)
tachyon plane.dat -res "$size" "$size" "${sky[@]}" -o plane.ppm >/dev/null
tachyon plane_grid.dat -res $((size + 1)) $((size + 1)) "${sky[@]}" -o plane_grid.ppm >/dev/null
tachyon sphere.dat -res "$size" "$size" "${sky[@]}" -o sphere.ppm >/dev/null

PYTHONPATH="$root/bench" /usr/bin/python3 - "$size" <<'EOF'
import math, sys
import ppm48
import numpy as np

def read_ppm48(path):
    return ppm48.read_ppm48(path) / 65535.0


n = int(sys.argv[1])
as_is = read_ppm48("plane.ppm")
centred = read_ppm48("plane_grid.ppm")[1:, :-1]
pitch = 10.0 / n
r, h = 1.0, 2.0
print("Tachyon sky light, plane under a sphere, %dx%d (a pixel is %.2f of the plane)" % (n, n, pitch))
print("%-10s %6s %10s %12s %12s" % ("pixel", "s", "0.7*A", "Tachyon", "on centres"))
q = n // 2
for row, col in [(q, q + 6), (q - 7, q), (q, q - 7), (q + 6, q), (q, q + 9), (q - 10, q), (q + 8, q + 8),
                 (q - 9, q - 9), (q, n - 1), (0, q)]:
    x, z = (col + 0.5 - n / 2) * pitch, (row + 0.5 - n / 2) * pitch
    d = math.hypot(math.hypot(x, z), h)
    closed = 0.7 * (1 - (r / d) ** 2 * h / d)
    print("(%3d,%3d) %6.3f %10.4f %12.4f %12.4f" % (row, col, math.hypot(x, z), closed, as_is[row, col, 1],
                                                     centred[row, col, 1]))
for name, img in (("as is", as_is), ("on centres", centred)):
    mask = img[..., 0] > 0
    rows, cols = np.where(mask.any(1))[0], np.where(mask.any(0))[0]
    print("sphere %-10s rows %d..%d, columns %d..%d; mirrored about the image centre: rows %d..%d, columns %d..%d"
          % (name, rows.min(), rows.max(), cols.min(), cols.max(), n - 1 - rows.max(), n - 1 - rows.min(),
             n - 1 - cols.max(), n - 1 - cols.min()))
alone = read_ppm48("sphere.ppm")[..., 0]
print("sphere alone: mean red %.4f over %d pixels (0.7 * A = 0.7)" % (alone[alone > 0].mean(), (alone > 0).sum()))
EOF
