#!/usr/bin/env bash
# Where do POV-Ray 3.7's pixels look, against vrmlray's pixel centres (pixel (i, j) from the top left sampled
# at (i + 0.5, j + 0.5))? soft_vs_peers.sh compares the two pixel by pixel, so they must sample the same points
# (Tachyon did not: tachyon_sky_check.sh). A closed-form scene: a camera at the origin looking down -z, in
# POV-Ray through gen_scene.py's camera block as it writes it (right -x*Asp, up y, `angle` widened from VRML's
# fieldOfView, which spans the smaller side, to the horizontal), and two flat-coloured spheres (emissive /
# finish ambient 1, no lights): radius 3 at distance 10 on the axis, whose outline is a circle of radius
# 3/sqrt(91) on the image plane at distance 1, centred on the image; radius 0.4 off the axis at x = +4.2
# (right in both, if neither mirrors). For each renderer and size it prints the big disc's pixel count (about
# pi R^2 if the pixel pitch is right), the mean column and row of its pixels' centres (W/2 and H/2 if the
# lattice is centred), and the offsets a (b) for which "column j is sampled at j + a (row i at i + b)"
# predicts every pixel of the disc exactly (swept in steps of 0.005 with the other at 0.5): vrmlray's
# centres are a = b = 0.5, Tachyon's would be a = 1, b = 0; then how many pixels the two images differ in.
# 1 sample per pixel, no antialiasing, 8-bit PPM (flat 0/1 colours: 8 bits lose nothing).
#   bench/pov_pixel_check.sh [VRMLRAY_BINARY]    (default build/vrmlray; sizes 64x36 and 63x35)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=$(realpath "${1:-$root/build/vrmlray}")
work=${TMPDIR:-/tmp}/vrmlray_pov_pixel_check
mkdir -p "$work"
cd "$work"
"$root/tools/setup.sh" povray python3-numpy

fov=0.785398  # radians, VRML's: over the smaller image side
cat >check.wrl <<EOF
#VRML V2.0 utf8
NavigationInfo { headlight FALSE }
Background { skyColor [ 0 0 0 ] }
Viewpoint { position 0 0 0 fieldOfView $fov }
Transform { translation 0 0 -10 children Shape { appearance Appearance { material Material {
  diffuseColor 0 0 0 specularColor 0 0 0 ambientIntensity 0 emissiveColor 1 0 0 } } geometry Sphere { radius 3 } } }
Transform { translation 4.2 1 -10 children Shape { appearance Appearance { material Material {
  diffuseColor 0 0 0 specularColor 0 0 0 ambientIntensity 0 emissiveColor 0 1 0 } } geometry Sphere { radius 0.4 } } }
EOF
# The camera block is gen_scene.py's write_pov, with this scene's numbers.
cat >check.pov <<EOF
#version 3.7;
global_settings { assumed_gamma 1.0 ambient_light rgb 1 max_trace_level 1 }
background { rgb <0,0,0> }
#declare VRML_FOV = $fov;
#declare Asp = image_width/image_height;
#declare HAngle = (Asp >= 1 ? 2*degrees(atan(tan(VRML_FOV/2)*Asp)) : degrees(VRML_FOV));
camera {
  perspective
  location <0,0,0>
  sky <0,1,0>
  right -x*Asp  // right-handed like VRML
  up y
  angle HAngle
  look_at <0,0,-10>
}
sphere { <0,0,-10>, 3 pigment { rgb <1,0,0> } finish { ambient 1 diffuse 0 specular 0 } }
sphere { <4.2,1,-10>, 0.4 pigment { rgb <0,1,0> } finish { ambient 1 diffuse 0 specular 0 } }
EOF
for size in "64 36" "63 35"; do
    set -- $size
    "$bin" render check.wrl -W "$1" -H "$2" --threads 2 -q -o "v_$1x$2.ppm"
    povray -D -P -V +WT2 -A +W"$1" +H"$2" +FP +O"p_$1x$2.ppm" File_Gamma=1.0 check.pov 2>/dev/null
done

/usr/bin/python3 - "$fov" <<'EOF'
import math, re, sys
import numpy as np

def read_ppm(path):  # binary P6, 8 or 16 bits; POV-Ray writes comment lines in the header
    data = open(path, "rb").read()
    field = rb"\s+(?:#[^\n]*\n\s*)*(\d+)"
    w, h, maxval = (int(v) for v in re.match(rb"P6" + field * 3 + rb"\s", data).groups())
    dtype = np.uint8 if maxval < 256 else np.dtype(">u2")
    return np.frombuffer(data[-w * h * 3 * np.dtype(dtype).itemsize:], dtype=dtype).reshape(h, w, 3) / maxval

fov = float(sys.argv[1])
offsets = np.arange(0, 1.0001, 0.005)
for w, h in ((64, 36), (63, 35)):
    pitch = 2 * math.tan(fov / 2) / min(w, h)  # of the image plane at distance 1
    disc = 3 / math.sqrt(10 ** 2 - 3 ** 2)  # the big sphere's outline, a circle on that plane
    small = w / 2 + 0.42 / pitch  # the small sphere's centre's column (+x is right in both)

    def covered(a, b):  # the big disc's pixels if column j is sampled at j + a and row i at i + b
        x = (np.arange(w) + a - w / 2) * pitch
        y = (np.arange(h) + b - h / 2) * pitch
        return x[None, :] ** 2 + y[:, None] ** 2 < disc ** 2

    def fits(mask, sweep):  # the offsets (of the sweep) whose disc is the mask, pixel for pixel
        miss = np.array([(covered(*sweep(o)) != mask).sum() for o in offsets])
        ok = offsets[miss == 0]
        return "%.3f..%.3f" % (ok.min(), ok.max()) if len(ok) else "none (best %d px off)" % miss.min()

    print("%dx%d: big disc radius %.3f px, pi R^2 = %.1f; small sphere's centre at column %.2f" %
          (w, h, disc / pitch, math.pi * (disc / pitch) ** 2, small))
    print("  %-8s %6s %11s %9s %-22s %-22s %11s" % ("", "pixels", "mean column", "mean row", "a (b = 0.5) fitting",
                                                  "b (a = 0.5) fitting", "small: col"))
    images = {}
    for name, path in (("vrmlray", "v_%dx%d.ppm" % (w, h)), ("POV-Ray", "p_%dx%d.ppm" % (w, h))):
        img = images[name] = read_ppm(path)
        mask = img[..., 0] > 0.5
        rows, cols = np.nonzero(mask)
        scols = np.nonzero(img[..., 1] > 0.5)[1]
        print("  %-8s %6d %11.3f %9.3f %-22s %-22s %11.2f" % (
            name, mask.sum(), (cols + 0.5).mean(), (rows + 0.5).mean(), fits(mask, lambda o: (o, 0.5)),
            fits(mask, lambda o: (0.5, o)), (scols + 0.5).mean()))
    differ = np.any(np.abs(images["vrmlray"] - images["POV-Ray"]) > 0.5, axis=2)
    print("  pixels that differ between the two images: %d of %d" % (differ.sum(), w * h))
EOF
