# Sourced by run_cli_corpus.sh: animation at --time, frame sequences and the turntable on real files
# (docs/animation.md). Uses its $bin, $work, $corpus and pass/fail helpers.
anim=$work/anim
mkdir -p "$anim"
prim=$corpus/x3dv/castle-engine-demo-models/shadow_maps/primitives.x3dv
# Its PositionInterpolator moves the sphere (loop, 5 s cycle): a quarter cycle later it stands
# 0.4 to the side, so the images differ.
expect 0 "primitives.x3dv at t=0" -- "$bin" render "$prim" -W 96 -H 72 -q --time 0 -o "$anim/prim_0.png"
expect 0 "primitives.x3dv at t=1.25" -- "$bin" render "$prim" -W 96 -H 72 -q --time 1.25 -o "$anim/prim_1.25.png"
expect 1 "primitives.x3dv: the sphere moved between t=0 and t=1.25" -- "$bin" compare "$anim/prim_0.png" "$anim/prim_1.25.png"
# At t = 0 the running TimeSensor already applies the first key value. The file's first key equals
# the field's own value, so a copy gets another first key (0.2 0.3 0), and a static copy holds that
# value with no ROUTE: the two must render the same bytes.
sed 's/keyValue \[ 0 0 0 /keyValue [ 0.2 0.3 0 /' "$prim" >"$anim/first_key.x3dv"
sed 's/^DEF SphereTransform Transform {/DEF SphereTransform Transform { translation 0.2 0.3 0/; /^ROUTE/d' "$prim" >"$anim/static.x3dv"
grep -q "keyValue \[ 0.2 0.3 0 " "$anim/first_key.x3dv" && pass || fail "the first-key copy was made"
expect 0 "first-key copy at t=0" -- "$bin" render "$anim/first_key.x3dv" -W 96 -H 72 -q -o "$anim/first_key.png"
expect 0 "static copy" -- "$bin" render "$anim/static.x3dv" -W 96 -H 72 -q -o "$anim/static.png"
cmp -s "$anim/first_key.png" "$anim/static.png" && pass || fail "t=0 shows the interpolator's first key value"
expect 1 "... which is not the file's value" -- "$bin" compare "$anim/first_key.png" "$anim/prim_0.png"
# freewrl 41.wrl: a CoordinateInterpolator wiggles an Extrusion's spine through VRML97's set_spine
# eventIn (a plain field): a quarter cycle (1 s of 4) bends the snake the other way.
f41=$corpus/vrml97/freewrl/freewrl/tests/41.wrl
expect 0 "41.wrl at t=0" -- "$bin" render "$f41" -W 96 -H 72 -q --time 0 -o "$anim/f41_a.png"
expect 0 "41.wrl at t=1" -- "$bin" render "$f41" -W 96 -H 72 -q --time 1 -o "$anim/f41_b.png"
expect 1 "41.wrl: the snake moved" -- "$bin" compare "$anim/f41_a.png" "$anim/f41_b.png"
# The same animation in X3D XML and X3D classic (material_parameters: a light on a rotating
# Transform) renders the same bytes at t=0.5, and other ones than at t=0.
mp=$corpus/x3d/castle-engine-demo-models/x3d/material_parameters_x3dom_xite_tests/material_parameters
for ext in x3d x3dv; do
    for t in 0 0.5; do
        expect 0 "material_parameters.$ext at t=$t" -- "$bin" render "$mp.$ext" -W 96 -H 72 -q --time $t -o "$anim/mp_${ext}_$t.png"
    done
done
cmp -s "$anim/mp_x3d_0.5.png" "$anim/mp_x3dv_0.5.png" && pass || fail "XML and classic ROUTEs give the same image at t=0.5"
expect 1 "material_parameters: the light moved" -- "$bin" compare "$anim/mp_x3d_0.png" "$anim/mp_x3d_0.5.png"

# --frames: N files named by the pattern, frame k the render at --time T0 + k / fps.
expect 0 "three frames" -- "$bin" render "$prim" -W 48 -H 36 -q --time 0.5 --frames 3 --fps 4 -o "$anim/seq_%04d.png"
[ "$(cd "$anim" && ls seq_* | tr '\n' ' ')" = "seq_0000.png seq_0001.png seq_0002.png " ] && pass || fail "frames are named seq_0000.png to seq_0002.png"
expect 0 "the third frame alone" -- "$bin" render "$prim" -W 48 -H 36 -q --time 1 -o "$anim/seq_alone.png"
cmp -s "$anim/seq_0002.png" "$anim/seq_alone.png" && pass || fail "frame 2 at 0.5 + 2/4 s is the render at --time 1"

# A 36-frame turntable of a molecule: frame k turned k * 10 degrees about the centre. The sequence says
# so in one note (not one a frame); each frame is the same bytes as that frame rendered alone with
# --frame K, which prints the frame's camera at full precision.
mol=$corpus/molecular/pymol/pept_spheres.wrl
expect 0 "36-frame orbit" -- "$bin" render "$mol" -W 64 -H 48 --frames 36 --orbit 360 -o "$anim/orbit_%02d.png"
[ "$(grep -c 'note:' "$work/err.txt")" -le 2 ] && pass || fail "the orbit's notes are not one a frame ($(grep -c 'note:' "$work/err.txt"))"
same=0
: >"$anim/alone_err.txt"
for k in $(seq 0 35); do
    name=$(printf 'orbit_%02d.png' "$k")
    "$bin" render "$mol" -W 64 -H 48 --frames 36 --orbit 360 --frame "$k" -o "$anim/alone_%02d.png" 2>>"$anim/alone_err.txt" &&
        cmp -s "$anim/$(printf 'alone_%02d.png' "$k")" "$anim/$name" && same=$((same + 1))
done
[ "$same" -eq 36 ] && pass || fail "orbit frames equal 36 renders of --frame K ($same of 36)"
grep -o 'alone_[0-9]*\.png: --position .*' "$anim/alone_err.txt" | sort >"$anim/orbit_cameras.txt"
[ "$(wc -l <"$anim/orbit_cameras.txt")" -eq 36 ] && pass || fail "--frame K prints frame K's camera"
# The printed cameras turn by 10 degrees a frame about the up axis through the centre (to 1e-9 rad:
# the positions print at 17 digits, far finer).
python3 - "$anim/orbit_cameras.txt" <<'PY' && pass || fail "orbit positions turn 10 degrees a frame"
import math, sys
rows = [l.split() for l in open(sys.argv[1])]
ok = len(rows) == 36
for k, r in enumerate(rows):
    p = [float(v) for v in r[2].split(",")]
    c = [float(v) for v in r[4].split(",")]
    up = [float(v) for v in r[6].split(",")]
    if k == 0:
        p0 = p
    # up is +Y for this file: the angle in the x-z plane, from frame 0's offset.
    a0 = math.atan2(p0[0] - c[0], p0[2] - c[2])
    a = math.atan2(p[0] - c[0], p[2] - c[2])
    turn = (a - a0) % (2 * math.pi)
    want = math.radians(10 * k)
    ok &= up == [0.0, 1.0, 0.0] and abs((turn - want + math.pi) % (2 * math.pi) - math.pi) < 1e-9
    ok &= abs(p[1] - p0[1]) < 1e-12
sys.exit(not ok)
PY
