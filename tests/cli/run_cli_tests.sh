#!/usr/bin/env bash
# Whole-program tests of the vrmlray command line: exit codes, messages, tests/corpus, golden images.
# The outside corpus of real files is tested by run_cli_corpus.sh.
# Usage: run_cli_tests.sh VRMLRAY_BINARY SOURCE_DIR WORK_DIR
# shellcheck source=tests/cli/common.sh
. "$(dirname "$0")/common.sh"

# --- exit codes and messages (docs/manual.md) ---------------------------------------------------------
expect 2 "no subcommand" -- "$bin"
# Command-line errors in the house style, with where to read more; usage lines name vrmlray, not a path.
# expect_usage_error DESCRIPTION MESSAGE HELP -- COMMAND...: exit 2 and exactly these two stderr lines.
expect_usage_error() {
    local what=$1 want
    want=$(printf 'vrmlray: error: %s\nvrmlray: see '"'"'%s'"'"'' "$2" "$3")
    shift 3
    expect 2 "$what" "$@"
    [ "$(cat "$work/err.txt")" = "$want" ] && pass || { fail "$what: stderr is not '$want'"; sed 's/^/    /' "$work/err.txt" | head -3; }
}
expect_usage_error "unknown option" "the following argument was not expected: --nosuch" "vrmlray render --help" \
    -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" --nosuch
expect_usage_error "out-of-range value" "--width: Value 0 not in range 1 to 65536" "vrmlray render --help" \
    -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" --width 0
expect_usage_error "missing value" "--width: 1 required INT:INT in [1 - 65536] missing" "vrmlray render --help" \
    -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" --width
expect_usage_error "missing image" "result is required" "vrmlray compare --help" -- "$bin" compare "$work/a.png"
expect_usage_error "no subcommand" "a subcommand is required" "vrmlray --help" -- "$bin"
"$bin" --help >"$work/out.txt" && [ "$(head -1 "$work/out.txt")" = "Usage: vrmlray [OPTIONS] SUBCOMMAND" ] && pass || fail "--help starts with the usage naming vrmlray"
# bash completion: an option's value completes from the option's own --help line: a set of words, paths
# for FILE and DIR values, nothing for a number or R,G,B (never unrelated file names).
complete_words() {  # complete_words WORD... : what <Tab> offers after these words
    # As bash-completion runs it: extglob on (the scene filter is an extended pattern).
    bash -c 'shopt -s extglob; . "$1/tools/completion/vrmlray.bash"; shift; COMP_WORDS=("$@");
             COMP_CWORD=$(($# - 1)); cd "$0" && { _vrmlray; printf "%s\n" "${COMPREPLY[@]}"; }' \
        "$work" "$src" "$bin" "$@" | sed '/^$/d' | sort | tr '\n' ' '
}
touch "$work/zz_scene.wrl"
[ "$(complete_words render x.wrl --sampler r)" = "rgss rooks8 " ] && pass || fail "--sampler r<Tab> offers rgss rooks8 ($(complete_words render x.wrl --sampler r))"
[ "$(complete_words render x.wrl --spheres "")" = "gas hints opaque " ] && pass || fail "--spheres <Tab> offers its three words"
[ "$(complete_words render x.wrl --camera "")" = "ortho perspective viewpoint " ] && pass || fail "--camera <Tab> offers its three words"
[ -z "$(complete_words render x.wrl -W zz)" ] && pass || fail "-W <Tab> offers no file names"
[ -z "$(complete_words render x.wrl --background zz)" ] && pass || fail "--background <Tab> offers no file names"
[ "$(complete_words render x.wrl -o zz_)" = "zz_scene.wrl " ] && pass || fail "-o <Tab> offers files"
[ "$(complete_words render zz_)" = "zz_scene.wrl " ] && pass || fail "a scene argument offers scene files"
touch "$work/yy_scene.x3dvz" "$work/yy_notes.txt"
[ "$(complete_words render yy_)" = "yy_scene.x3dvz " ] && pass || fail "a scene argument offers every scene extension render's help lists, and no other file ($(complete_words render yy_))"
"$bin" render --help >"$work/out.txt" && [ "$(head -1 "$work/out.txt")" = "Usage: vrmlray render [OPTIONS] [scene...]" ] && pass || fail "render --help starts with its usage"
# --stats is valid JSON whatever the scene's name, with figures at full precision: per_pixel must be
# exactly primary / pixels as Python's double division gives it (the statistical sampler's ray count
# is not a multiple of the 35 pixels, so six digits would not do).
weird="$work/we\"ird\\name.wrl"
cp "$src/scenes/seeds/001_sphere.wrl" "$weird"
expect 0 "render a scene named we\"ird\\name.wrl with --stats" -- "$bin" render "$weird" -W 7 -H 5 --sampler statistical -q -o "$work/weird.png" --stats "$work/weird.json"
python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))
r = d["rays"]
ok = d["scene"] == sys.argv[2] and r["primary"] % 35 != 0 and r["per_pixel"] == r["primary"] / 35
sys.exit(not ok)' "$work/weird.json" "$weird" && pass || fail "--stats JSON parses, names the scene, and holds full-precision figures"
expect 2 "bad --background" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" --background 1,2 -o "$work/x.png"
expect 3 "missing scene file" -- "$bin" render "$work/does_not_exist.wrl" -o "$work/x.png"
expect_stderr "does_not_exist.wrl: error: cannot open file" "missing file message"
printf '#VRML V2.0 utf8\nTransform {\n  children Shape { geometry Sphere { radius 1 colour 2 } }\n}\n' >"$work/bad_field.wrl"
# As browsers do (docs/input.md, "What is forgiven"): a warning at its place, and the scene renders;
# --strict makes it exit 3 after the image is written.
expect 0 "unknown field: a warning, the scene renders" -- "$bin" render "$work/bad_field.wrl" -W 8 -H 8 -o "$work/x.png"
expect_stderr "bad_field.wrl:3:47: warning: unknown field 'colour' in node Sphere; skipped with its value" "warning names file:line:col"
expect_stderr "^    +\^$" "caret under the column"
rm -f "$work/strict.png"
expect 3 "unknown field under --strict" -- "$bin" render "$work/bad_field.wrl" -W 8 -H 8 -o "$work/strict.png" --strict
expect_stderr "vrmlray: error: --strict: 1 warning, exit 3" "--strict says why it exits 3"
[ -s "$work/strict.png" ] && pass || fail "--strict writes the image before exiting 3"
expect 4 "unwritable output" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 8 -H 8 -o "$work/no/such/dir/x.png"
expect 0 "info on the seed scene" -- "$bin" info "$src/scenes/seeds/001_sphere.wrl"
# Files are written over in place and then cut to length (docs/manual.md): a named pipe or a device has
# no length to cut, and must take the image all the same.
expect 0 "render to a file" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 16 -H 12 -q -o "$work/plain.ppm"
mkfifo "$work/pipe.ppm"
timeout 60 cat "$work/pipe.ppm" >"$work/from_pipe.ppm" &
reader=$!
expect 0 "render into a named pipe" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 16 -H 12 -q -o "$work/pipe.ppm"
wait "$reader"
if cmp -s "$work/plain.ppm" "$work/from_pipe.ppm"; then pass; else fail "the pipe got other bytes than the file"; fi
ln -s /dev/null "$work/null.png"
expect 0 "render to a link to /dev/null" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 16 -H 12 -q -o "$work/null.png"
expect 2 "unknown sampler" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" --sampler bogus -W 8 -H 8 -o "$work/x.png"
expect_stderr "bogus not in \{center,grid,rgss,rooks8,quincunx,jitter,adaptive,statistical\}" "unknown sampler names the choices"
expect 2 "grid needs a square spp" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" --sampler grid --spp 5 -W 8 -H 8 -o "$work/x.png"
expect_stderr "sampler 'grid' needs a square number" "sampler message"
for s in center grid rgss rooks8 quincunx jitter adaptive statistical; do
    expect 0 "sampler $s renders" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" --sampler $s -W 24 -H 16 -o "$work/s_$s.png" -q
done
# Soft light (docs/rendering.md, Soft light with error bounds): options, the centre sampler refused with a lens, the hints read from light metadata.
soft="$src/scenes/demos/soft_light.wrl"
expect 2 "--aperture with the centre sampler" -- "$bin" render "$soft" --aperture 0.1 -W 8 -H 8 -o "$work/x.png"
expect_stderr "aperture needs several samples per pixel spread over the lens: pick a sampler" "lens message says to pick a sampler"
expect 2 "bad --sky" -- "$bin" render "$soft" --sky 1,2 -W 8 -H 8 -o "$work/x.png"
expect 0 "sky light, area lights and a lens render" -- "$bin" render "$soft" --sky 0.3,0.3,0.3 --ao-distance 2 --light-tolerance 1e-2 --aperture 0.05 --sampler jitter --spp 4 -W 24 -H 16 -q -o "$work/soft.png"
# --sky FILE: a constant EXR (an empty scene's background, written by vrmlray) lights as --sky R,G,B does;
# with a Background node in the scene, the map does not show behind it either.
printf '#VRML V2.0 utf8\nWorldInfo {}\n' >"$work/empty.wrl"
"$bin" render "$work/empty.wrl" --background 0.25,0.5,0.75 -W 16 -H 8 -q -o "$work/sky_const.exr"
{ cat "$soft"; echo 'Background { skyColor 0.1 0.1 0.1 }'; } >"$work/soft_bg.wrl"
"$bin" render "$work/soft_bg.wrl" --sky 0.25,0.5,0.75 --ao-distance 2 --light-tolerance 1e-2 -W 24 -H 16 -q -o "$work/sky_rgb.exr"
expect 0 "--sky with an EXR image" -- "$bin" render "$work/soft_bg.wrl" --sky "$work/sky_const.exr" --ao-distance 2 --light-tolerance 1e-2 -W 24 -H 16 -q -o "$work/sky_map.exr"
# E = 1e-2 times the largest texel (0.75) bounds each pixel's sky term (diffuse <= 1).
expect 0 "a constant sky image equals --sky R,G,B within the tolerance" -- "$bin" compare "$work/sky_map.exr" "$work/sky_rgb.exr" --max-abs 0.0075
expect 3 "a missing sky image" -- "$bin" render "$soft" --sky "$work/no_sky.hdr" -W 8 -H 8 -o "$work/x.png"
expect_stderr "error: --sky wants R,G,B or an image file: .*no_sky.hdr" "missing sky image message"
"$bin" render "$soft" -W 32 -H 24 -q -o "$work/soft_area.png"
sed 's/value 0.6/value 0/; s/value 0.08/value 0/' "$soft" >"$work/soft_point.wrl"
"$bin" render "$work/soft_point.wrl" -W 32 -H 24 -q -o "$work/soft_point.png"
expect 0 "info on the soft light demo" -- "$bin" info "$soft"
grep -q "PointLight .* sourceRadius 0.6$" "$work/out.txt" && grep -q "DirectionalLight .* angularRadius 0.08$" "$work/out.txt" && pass || fail "info shows the area light hints"
expect 1 "sourceRadius/angularRadius change the shadows" -- "$bin" compare "$work/soft_area.png" "$work/soft_point.png"
# Penumbra points that the sampling path cannot bring within the tolerance in its 8 x 128^2 rays are
# said, with how many, rather than counted in --stats alone: a box's shadow edge across a sphere light
# at 1e-4. At 1e-2 every point converges and nothing is said.
cat >"$work/penumbra.wrl" <<'EOF'
#VRML V2.0 utf8
NavigationInfo { headlight FALSE }
Viewpoint { position 0 6 0 orientation 1 0 0 -1.5708 fieldOfView 0.8 }
PointLight { location 0.3 4 0 radius 100
  metadata MetadataSet { name "vrmlray" value [ MetadataFloat { name "sourceRadius" value 0.8 } ] } }
Shape { appearance Appearance { material Material {} } geometry Box { size 8 0.1 8 } }
Transform { translation 0 1 0 children Shape { appearance Appearance { material Material {} } geometry Box { size 1 0.2 1 } } }
EOF
expect 0 "a penumbra at --light-tolerance 1e-4" -- "$bin" render "$work/penumbra.wrl" -W 12 -H 9 --light-tolerance 1e-4 -o "$work/penumbra.png" --stats "$work/penumbra.json"
n=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["soft_light"]["unconverged_points"])' "$work/penumbra.json")
[ "$n" -gt 0 ] && pass || fail "the penumbra case has unconverged points (got $n)"
expect_stderr "penumbra.wrl: warning: soft light: $n of [0-9]+ sampled shading points did not reach --light-tolerance 0.0001 within 131072 shadow rays" "unconverged points are said, with their count"
expect 0 "the same penumbra at 1e-2" -- "$bin" render "$work/penumbra.wrl" -W 12 -H 9 --light-tolerance 1e-2 -o "$work/penumbra.png"
grep -q "did not reach" "$work/err.txt" && fail "no unconverged warning at 1e-2" || pass
printf '#VRML V2.0 utf8\nDirectionalLight { metadata MetadataSet { name "vrmlray" value [ MetadataFloat { name "sourceRadius" value 1 } ] } }\nShape { geometry Sphere {} }\n' >"$work/wrong_hint.wrl"
expect 0 "a sourceRadius on a DirectionalLight" -- "$bin" info "$work/wrong_hint.wrl"
expect_stderr "sourceRadius is for PointLight and SpotLight; ignored" "misplaced area hint warns"
expect 3 "a render that cannot fit in memory is refused before allocating" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 65536 -H 65536 -o "$work/x.png"
expect_stderr "001_sphere.wrl: error: rendering 65536x65536 .* needs about 103 GB, more than" "memory estimate message"
expect 3 "--max-memory lowers the limit" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 640 -H 480 --max-memory 0.001 -o "$work/x.png"
expect_stderr "001_sphere.wrl: error: rendering 640x480 .* needs about 0.007.* GB, more than 0.001 GB \(--max-memory\)" "lowered memory limit message"
expect 0 "--max-memory raises nothing that fits" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 64 -H 48 --max-memory 0.01 -o "$work/x.png"
# --limit: a limit lowered below what a scene needs stops it with exit 3; an unknown name is a usage error.
printf '#VRML V2.0 utf8\nGroup { children Group { children Group { children Shape { geometry Sphere {} } } } }\n' >"$work/nested.wrl"
expect 0 "three levels pass the default nesting limit" -- "$bin" info "$work/nested.wrl"
expect 3 "--limit nesting-depth=2 refuses three levels" -- "$bin" info "$work/nested.wrl" --limit nesting-depth=2
expect_stderr "nested.wrl:2:.*: error: nodes nested deeper than 2" "lowered nesting limit message"
expect 3 "--limit primitives=1 refuses a scene of 17 quadrics" -- "$bin" render "$src/scenes/seeds/000_scene5_table_chairs.wrl" --limit primitives=1 -W 8 -H 8 -o "$work/x.png"
expect_stderr "error: the scene expands to more primitives than the limit allows" "primitive limit message"
# Offsets are 64-bit and a place in a file (kept with every node) holds 38 bits of one: a file-bytes limit
# above 4 GiB is taken (a 29 GB 10^8-atom export is read, bench/README.md "Issue 45: files over 4 GiB"),
# one above 256 GiB is refused as a usage error rather than let a larger file be misread.
expect 0 "--limit file-bytes above 4 GiB is taken" -- "$bin" info "$src/scenes/seeds/001_sphere.wrl" --limit file-bytes=30G
expect 2 "--limit file-bytes above 256 GiB is refused" -- "$bin" info "$src/scenes/seeds/001_sphere.wrl" --limit file-bytes=275G
expect_stderr "file-bytes is at most 274877906944" "file-bytes ceiling message"
# An X3D XML file over 4 GiB is refused, not misread (the XML reader's offsets stay 32-bit): a sparse file,
# which takes no disk space and of which nothing past the first line is read.
printf '<?xml version="1.0" encoding="UTF-8"?>\n<X3D><Scene><Shape><Sphere/></Shape></Scene></X3D>\n' >"$work/big.x3d"
truncate -s 4294967297 "$work/big.x3d"
expect 3 "an X3D XML file over 4 GiB is refused" -- "$bin" info "$work/big.x3d" --limit file-bytes=5G
expect_stderr "big.x3d:1:1: error: an X3D XML file is read up to 4 GiB" "XML size ceiling message"
rm -f "$work/big.x3d"
mkdir -p "$work/tex"
"$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 4 -H 4 -q -o "$work/tex/t.png"
printf '#VRML V2.0 utf8\nShape { appearance Appearance { texture ImageTexture { url "t.png" } } geometry Box {} }\n' >"$work/tex/textured.wrl"
expect 0 "a 4x4 texture within the default limit" -- "$bin" render "$work/tex/textured.wrl" -W 8 -H 8 -o "$work/x.png"
grep -q "too large" "$work/err.txt" && fail "a small texture is not too large" || pass
expect 0 "--limit texture-pixels=15 ignores a 16-pixel texture with a warning" -- "$bin" render "$work/tex/textured.wrl" -W 8 -H 8 --limit texture-pixels=15 -o "$work/x.png"
expect_stderr "warning: .*t.png: the image is too large \(4 x 4 = 16 pixels; the limit is 15\)" "texture limit warning"
expect 2 "unknown --limit name" -- "$bin" info "$work/nested.wrl" --limit bogus=1
expect_stderr "--limit wants NAME=VALUE with NAME one of nesting-depth" "unknown limit message"
expect 2 "--limit needs a positive number" -- "$bin" info "$work/nested.wrl" --limit nodes=0
expect_stderr "error: --limit nodes wants a positive whole number, optionally with k, M or G \(got '0'\)" "limit value message"
# Determinism: the same floats for 1 and 2 threads and on a second run (opaque with a random sampler, and gas).
for scene in 000_scene2_metal_glass 003_particles_gas; do
    "$bin" render "$src/scenes/seeds/$scene.wrl" -W 48 -H 36 --sampler jitter --spp 4 --seed 3 --threads 1 -q -o "$work/det1.exr"
    "$bin" render "$src/scenes/seeds/$scene.wrl" -W 48 -H 36 --sampler jitter --spp 4 --seed 3 --threads 2 -q -o "$work/det2.exr"
    "$bin" render "$src/scenes/seeds/$scene.wrl" -W 48 -H 36 --sampler jitter --spp 4 --seed 3 --threads 2 -q -o "$work/det3.exr"
    expect 0 "$scene: 1 and 2 threads give the same image" -- "$bin" compare "$work/det1.exr" "$work/det2.exr" --max-abs 0
    expect 0 "$scene: a second run gives the same image" -- "$bin" compare "$work/det2.exr" "$work/det3.exr" --max-abs 0
done
# Deterministic bytes (docs/manual.md, render): the same render writes the same file for any thread count, with
# no timestamp (the second run starts a second later, so a clock in the file would show).
for ext in exr png tif; do
    for alpha in "" --alpha; do
        "$bin" render "$src/scenes/seeds/003_particles_gas.wrl" -W 40 -H 30 $alpha --threads 1 -q -o "$work/bytes1.$ext"
        sleep 1
        "$bin" render "$src/scenes/seeds/003_particles_gas.wrl" -W 40 -H 30 $alpha --threads 2 -q -o "$work/bytes2.$ext"
        cmp -s "$work/bytes1.$ext" "$work/bytes2.$ext" && pass || fail "$ext $alpha: two renders wrote different bytes"
    done
done
# PNG and EXR (the ground truth) never load the OpenImageIO module (0.2-0.4 s and ~130 MB): libpng and
# the OpenEXR module serve them. LD_DEBUG=files lists every object the dynamic loader opens.
for ext in exr png; do
    LD_DEBUG=files "$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 32 -H 24 --alpha -q -o "$work/nooiio.$ext" 2>"$work/ld.txt"
    LD_DEBUG=files "$bin" compare "$work/nooiio.$ext" "$work/nooiio.$ext" >/dev/null 2>>"$work/ld.txt"
    grep -q "file=.*vrmlray_oiio" "$work/ld.txt" && fail "$ext render or compare loaded the OpenImageIO module" || pass
done
# The output is checked before the scene is read or a ray traced (a 4000x4000 render at 64 spp would take
# minutes): a missing folder or an unknown format is exit 4 within a second, and nothing is written.
for out in /no/such/dir/x.png "$work/x.bogus"; do
    rm -f "$work/x.bogus"
    start=$(date +%s%N)
    expect 4 "unwritable $out is refused at once" -- "$bin" render "$src/scenes/seeds/000_scene1_glass_bubbles.wrl" -W 4000 -H 4000 --spp 64 -o "$out"
    ms=$(( ($(date +%s%N) - start) / 1000000 ))
    [ "$ms" -lt 1000 ] && pass || fail "unwritable $out: exit after $ms ms, not at once"
    [ -e "$out" ] && fail "unwritable $out: a file was written" || pass
done
expect_stderr "^vrmlray: error: cannot write '.*x.bogus': unknown image format '.bogus'$" "unknown format message"
expect 4 "missing folder" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" -o /no/such/dir/x.png
expect_stderr "^vrmlray: error: cannot write '/no/such/dir/x.png': the folder '/no/such/dir' does not exist$" "missing folder message"
# --alpha with a format that has no alpha channel: a one-line usage error, before rendering.
for ext in jpg ppm hdr; do
    rm -f "$work/alpha.$ext"
    expect 2 "--alpha with .$ext" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" --alpha -W 8 -H 8 -o "$work/alpha.$ext"
    expect_stderr "^vrmlray: error: --alpha: cannot write '.*alpha.$ext' with an alpha channel: ${ext^^} files have none" "--alpha .$ext message"
    [ "$(wc -l <"$work/err.txt")" -eq 1 ] && pass || fail "--alpha .$ext: the error is not one line"
    [ -e "$work/alpha.$ext" ] && fail "--alpha .$ext: a file was written" || pass
done
rm -f "$work/timeout.png"
expect 3 "--timeout stops a long render" -- "$bin" render "$src/scenes/seeds/000_scene1_glass_bubbles.wrl" -W 2000 -H 2000 --spp 256 --timeout 0.5 -o "$work/timeout.png"
expect_stderr "error: the render passed --timeout 0.5 s" "timeout message"
[ ! -e "$work/timeout.png" ] && pass || fail "no image is written after a timeout"
expect 2 "unknown viewpoint" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" --viewpoint Nowhere -W 8 -H 8 -o "$work/x.png"
expect_stderr "error: no viewpoint named 'Nowhere' \\(the scene has: 'Camera'\\)" "unknown viewpoint lists the scene's viewpoints"

# --- info: the figures a user reads (docs/manual.md) ---------------------------------------------------
expect 0 "info on the table-and-chairs seed" -- "$bin" info "$src/scenes/seeds/000_scene5_table_chairs.wrl"
for line in '^encoding +VRML97 \(classic\)$' '^nodes +100 read \(PROTO bodies expanded\), 13 top-level$' '^  Box +17$' \
    '^tracer +0 spheres, 17 quadrics .*, 1 meshes with 2 triangles$' '^ +3 materials, 1 textures, 0 shapes skipped$' \
    '^bounds +\(-15 0 -15\) \.\. \(15 1.325 15\)$' '^lights +2, headlight off$' \
    '^  PointLight +colour \(1 1 1\) intensity 0.9 ambient 0.3 at \(2 6 3\) radius 100$' \
    '^   "corner" position \(4.5 4 6.5\) fieldOfView 0.75$'; do
    grep -Eq -- "$line" "$work/out.txt" && pass || fail "info output lacks /$line/"
done

# --- URLs, --sandbox, --strict, empty images, the camera without a Viewpoint (docs/manual.md, 2, 4) ---
mkdir -p "$work/urls/scene" "$work/urls/textures"
"$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 4 -H 4 -q -o "$work/urls/textures/t.png"
printf '#VRML V2.0 utf8\nViewpoint { position 0 0 4 }\nShape { appearance Appearance { texture ImageTexture { url "../textures/t.png" } } geometry Box {} }\n' >"$work/urls/scene/up.wrl"
expect 0 "a ../ texture URL loads without --sandbox" -- "$bin" render "$work/urls/scene/up.wrl" -W 8 -H 8 --strict -o "$work/x.png"
expect 0 "--sandbox refuses it with a warning" -- "$bin" render "$work/urls/scene/up.wrl" -W 8 -H 8 --sandbox -o "$work/x.png"
expect_stderr "warning: .*'../textures/t.png' lies outside the --sandbox folder .*/urls/scene \(--allow-path DIR" "sandbox message"
expect 0 "--sandbox DIR with the parent folder allows it" -- "$bin" render "$work/urls/scene/up.wrl" -W 8 -H 8 --sandbox "$work/urls" --strict -o "$work/x.png"
expect 2 "--sandbox before the scene would take it as DIR: a usage error" -- "$bin" render --sandbox "$work/urls/scene/up.wrl" -W 8 -H 8 -o "$work/x.png"
expect_stderr "--sandbox: Directory is actually a file" "--sandbox DIR must be a folder"
expect 0 "--allow-path adds a folder to the sandbox" -- "$bin" render "$work/urls/scene/up.wrl" -W 8 -H 8 --sandbox --allow-path "$work/urls/textures" --strict -o "$work/x.png"
printf '#VRML V2.0 utf8\nInline { url "missing.wrl" }\n' >"$work/urls/only_missing.wrl"
expect 0 "a scene whose only Inline is missing renders" -- "$bin" render "$work/urls/only_missing.wrl" -W 8 -H 8 -o "$work/x.png"
expect_stderr "only_missing.wrl: warning: nothing to render, the image shows only the background: 1 Inline was not loaded" "empty-image warning names the Inline"
expect 3 "--strict turns the warnings into exit 3" -- "$bin" render "$work/urls/only_missing.wrl" -W 8 -H 8 --strict -o "$work/x.png"
expect_stderr "error: --strict: 2 warnings" "--strict message"
expect 3 "--strict on info" -- "$bin" info "$work/urls/only_missing.wrl" --strict
expect 3 "--strict on convert" -- "$bin" convert "$work/urls/only_missing.wrl" "$work/urls/x.x3dv" --strict
expect 0 "a clean scene passes --strict" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 8 -H 8 --strict -o "$work/x.png"
printf '#VRML V2.0 utf8\nViewpoint { position 0 0 10 }\nTransform { translation 100 0 0 children Shape { geometry Sphere {} } }\n' >"$work/urls/away.wrl"
expect 3 "geometry outside the view is a warning (--strict: exit 3)" -- "$bin" render "$work/urls/away.wrl" -W 8 -H 8 --strict -o "$work/x.png"
expect_stderr "warning: nothing of the scene is in view, .*every primary ray missed \(camera at \(0 0 10\) looking along \(0 0 -1\)" "out-of-view warning"
printf '#VRML V2.0 utf8\nTransform { translation 100 0 0 children Shape { geometry Sphere {} } }\n' >"$work/urls/no_viewpoint.wrl"
expect 0 "a scene without Viewpoint is framed, so nothing is out of view" -- "$bin" render "$work/urls/no_viewpoint.wrl" -W 8 -H 8 --strict -o "$work/x.png"
expect_stderr "no_viewpoint.wrl: note: no Viewpoint: framed from \+Z at \(100 0 " "framing note"
expect 0 "info names the bound Viewpoint" -- "$bin" info "$src/scenes/seeds/001_sphere.wrl"
grep -q '^camera      Viewpoint DEF Camera "seed camera" at (-1 0 1)$' "$work/out.txt" && pass || fail "info camera line for a Viewpoint"

# --- compare (docs/golden-tests.md) -----------------------------------------------------------------------
"$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 32 -H 24 -o "$work/a.png" -q
"$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 32 -H 24 --background 1,1,1 -o "$work/b.png" -q
"$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 16 -H 16 -o "$work/c.png" -q
expect 0 "identical images pass" -- "$bin" compare "$work/a.png" "$work/a.png" --max-rmse 0 --min-ssim 1
expect 1 "different images fail a threshold" -- "$bin" compare "$work/a.png" "$work/b.png" --max-rmse 0.01
expect 3 "size mismatch is an error" -- "$bin" compare "$work/a.png" "$work/c.png"
# With no threshold the images must agree to 1e-6 (idiff's default): a and b differ in the background.
expect 1 "unrelated images fail with no threshold" -- "$bin" compare "$work/a.png" "$work/b.png"
grep -q "FAIL: .*no threshold given: idiff's default --fail 1e-06 --failpercent 0" "$work/out.txt" && pass || fail "the default test names itself"
expect 0 "identical images pass with no threshold" -- "$bin" compare "$work/a.png" "$work/a.png"
expect 1 "compare --json and --diff (different images fail)" -- "$bin" compare "$work/a.png" "$work/b.png" --json --diff "$work/diff.png"
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); sys.exit(not (d["pass"] is False and d["rmse"] > 0))' "$work/out.txt" \
    && pass || fail "compare --json prints valid JSON with rmse and pass"
[ -s "$work/diff.png" ] && pass || fail "compare --diff writes the heat-map"
# Images no render gives: 10x10 grey 128/255, one with alpha 0 at one pixel, one without alpha, and one
# whose first row (10% of the pixels) is 51/255 = 0.2 brighter in red.
mkpng() { python3 "$src/tests/cli/make_png.py" "$@"; }
mkpng "$work/grey.png" 10 10 4 128
mkpng "$work/grey_alpha.png" 10 10 4 128 3,4,3=0
mkpng "$work/grey_rgb.png" 10 10 3 128
mkpng "$work/grey_row.png" 10 10 4 128 0,0,0=179 1,0,0=179 2,0,0=179 3,0,0=179 4,0,0=179 5,0,0=179 6,0,0=179 7,0,0=179 8,0,0=179 9,0,0=179
expect 1 "an alpha-only change fails --max-abs 0" -- "$bin" compare "$work/grey.png" "$work/grey_alpha.png" --max-abs 0
grep -Eq '^max abs diff +0.501961$' "$work/out.txt" && pass || fail "alpha enters max abs diff (128/255)"
expect 1 "RGB against RGBA fails" -- "$bin" compare "$work/grey_rgb.png" "$work/grey.png" --max-rmse 1
grep -q "FAIL: channel counts differ: the reference has 3 channels (no alpha), the result 4 channels (with alpha)" "$work/out.txt" \
    && pass || fail "channel mismatch message"
# idiff's flags, each on both sides of its threshold (the row differs by 0.2; 10% of the pixels).
cmp_row() { "$bin" compare "$work/grey.png" "$work/grey_row.png" "$@"; }
expect 0 "--fail 0.25 passes a 0.2 difference" -- cmp_row --fail 0.25
expect 1 "--fail 0.15 fails it" -- cmp_row --fail 0.15
expect 0 "--failpercent 10 passes 10% failed pixels" -- cmp_row --failpercent 10
expect 1 "--failpercent 9 fails them" -- cmp_row --failpercent 9
expect 0 "--hardfail 0.25 passes" -- cmp_row --failpercent 100 --hardfail 0.25
expect 1 "--hardfail 0.15 fails" -- cmp_row --failpercent 100 --hardfail 0.15
for w in "--warn 0.15" "--warnpercent 9" "--hardwarn 0.15 --warnpercent 100"; do
    # shellcheck disable=SC2086
    expect 0 "$w warns and passes" -- cmp_row --failpercent 100 $w
    grep -q "^WARNING: " "$work/out.txt" && pass || fail "$w prints a warning"
done
for w in "--warn 0.25" "--warnpercent 10" "--hardwarn 0.25 --warnpercent 100"; do
    # shellcheck disable=SC2086
    expect 0 "$w passes" -- cmp_row --failpercent 100 $w
    grep -q "WARNING" "$work/out.txt" && fail "$w prints no warning" || pass
done

# --- bench (docs/manual.md, bench) ------------------------------------------------------------------------
(cd "$work" && "$bin" bench "$src/scenes/seeds/001_sphere.wrl" -W 32 -H 24 --runs 1 -q >"$work/out.txt" 2>"$work/err.txt")
[ $? -eq 0 ] && pass || fail "bench runs"
[ "$(wc -l <"$work/001_sphere-bench.csv")" -eq 25 ] && pass || fail "bench CSV has a header and 24 settings"
# Along each fixed-pattern series the error must fall as the samples rise (the CSV's rmse column): the
# last setting at least halves the first one's error. Neighbouring settings are not compared, because on
# a 32x24 image a 3x3 grid can alias worse than a 2x2 one.
for series in grid rgss rooks8 jitter; do
    awk -F, -v s="$series" 'NR > 1 && $1 == s { if (!n++) first = $10; last = $10 } END { exit !(n >= 3 && last < first / 2) }' \
        "$work/001_sphere-bench.csv" && pass || fail "bench: RMSE falls along the $series series"
done
grep -q 'fastest sampler to reach an RMSE' "$work/out.txt" && grep -Eq '^  RMSE <= 1e-02 +[a-z]' "$work/out.txt" && pass || fail "bench names the fastest sampler per error"
"$bin" compare "$work/001_sphere-bench.png" "$work/001_sphere-bench.png" >/dev/null && pass || fail "bench plot is a readable image"
# The second run reads the reference the first rendered and cached: the errors must be the same (the
# first run measured against the reference in memory, with its alpha channel, 13% lower RMSE on RGB).
cut -d, -f10-13 "$work/001_sphere-bench.csv" >"$work/bench_first.txt"
(cd "$work" && "$bin" bench "$src/scenes/seeds/001_sphere.wrl" -W 32 -H 24 --runs 1 -q >/dev/null 2>&1)
cut -d, -f10-13 "$work/001_sphere-bench.csv" | cmp -s - "$work/bench_first.txt" && pass ||
    fail "bench: errors against a cached reference equal those against the reference just rendered"

# --- convert round trip ------------------------------------------------------------------------------
expect 0 "convert to X3D classic" -- "$bin" convert "$src/scenes/seeds/001_sphere.wrl" "$work/s.x3dv"
expect 0 "convert back to VRML97 gzip" -- "$bin" convert "$work/s.x3dv" "$work/s.wrl.gz"
expect 0 "render the converted file" -- "$bin" render "$work/s.wrl.gz" -W 32 -H 24 -o "$work/s.png" -q
expect 0 "converted file renders the same image" -- "$bin" compare "$work/a.png" "$work/s.png" --max-abs 0

# --- tests/corpus/good: valid files load (exit 0) with exactly their expected warnings, and render -------
# Together they use every reader once (VRML97, X3D classic, X3D XML, VRML 1.0, gzip), PROTO, EXTERNPROTO,
# Inline, a texture and gas, so that a clone without the outside corpus still tests each.
good_files() { find "$src/tests/corpus/good" -maxdepth 1 -type f ! -name '*.expected' -print0 | sort -z; }
while IFS= read -r -d '' f; do
    name=$(basename "$f")
    stem=${name%%.*}
    (cd "$(dirname "$f")" && "$bin" info "$name" >/dev/null 2>"$work/err.txt")
    code=$?
    if [ $code -eq 0 ] && cmp -s "$work/err.txt" "$src/tests/corpus/good/$stem.expected"; then pass; else
        fail "good/$name: exit $code, or warnings differ from $stem.expected:"; diff "$work/err.txt" "$src/tests/corpus/good/$stem.expected" | head -5
    fi
    # Every warning is an error under --strict (exit 3); a file without one passes it.
    want=0
    grep -q ': warning: ' "$src/tests/corpus/good/$stem.expected" && want=3
    (cd "$(dirname "$f")" && "$bin" info "$name" --strict >/dev/null 2>&1)
    code=$?
    [ $code -eq $want ] && pass || fail "good/$name: info --strict exits $code, expected $want"
done < <(good_files)

# --- tests/corpus/bad: every broken file fails with exit 3 and exactly its expected first message ---------
for f in "$src"/tests/corpus/bad/*.wrl; do
    name=$(basename "$f")
    (cd "$(dirname "$f")" && "$bin" info "$name" -q >/dev/null 2>"$work/err.txt")
    code=$?
    expected=$(cat "${f%.wrl}.expected")
    got=$(head -1 "$work/err.txt")
    if [ $code -eq 3 ] && [ "$got" = "$expected" ]; then pass; else fail "bad/$name: exit $code, message '$got', expected '$expected'"; fi
done

# --- reading in pieces on several threads (parser/classic_pieces.h) -------------------------------------------
# A molecule export read in 64 KB pieces renders the same bytes as one read by one thread (the default piece is
# 16 MB, so this 6 MB file is read whole unless the test-only VRMLRAY_PIECE_BYTES says otherwise).
python3 "$src/tools/gen_molecule.py" 20000 "$work/pieces.wrl" --no-bonds
VRMLRAY_PIECE_BYTES=0 "$bin" render "$work/pieces.wrl" -W 320 -H 180 -q -o "$work/pieces_one.png" &&
    VRMLRAY_PIECE_BYTES=65536 "$bin" render "$work/pieces.wrl" -W 320 -H 180 -q -o "$work/pieces_many.png" &&
    cmp -s "$work/pieces_one.png" "$work/pieces_many.png" && pass ||
    fail "a molecule read in 64 KB pieces renders the bytes a single-thread read gives"
rm -f "$work/pieces.wrl"

# --- golden images: the bundled scenes, tests/corpus/good and every sampler ------------------------
# Each tests/render/golden/NAME.png was rendered by tests/render/make_goldens.sh from the list golden.txt and
# inspected by eye. Renders are deterministic, so on the machine that made a golden it matches to the bit.
# Allowed: at most one 8-bit code (1/255 = 0.0039) on at most 0.1% of the pixels, alpha included: the last bit
# of a libm function or of the gas quadrature (to --tolerance 1e-4) can carry a value across an 8-bit rounding
# boundary; a real change of the picture moves more values, or by more. The suite runs as a user's would: one
# batch render of the list, one folder compare (a golden without its line in the list fails as missing).
expect 0 "golden list renders in one process" -- "$bin" render --list "$src/tests/render/golden/golden.txt" \
    -o "$work/golden/" -q
expect 0 "golden images match" -- "$bin" compare "$src/tests/render/golden" "$work/golden" \
    --pixel-threshold 0 --max-fail-percent 0.1 --max-abs 0.004 --report "$work/golden_report"
grep -Ev '^(pass|status) ' "$work/out.txt" | grep -v ' 0 failed (' | sed 's/^/    /' | head -30

# shellcheck source=tests/cli/anim_cli.sh
. "$src/tests/cli/anim_cli.sh"

echo "cli: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
