#!/usr/bin/env bash
# Whole-program tests of the vrmlray command line: exit codes, messages, every corpus file, golden images.
# Usage: run_cli_tests.sh VRMLRAY_BINARY SOURCE_DIR WORK_DIR
set -u
bin=$1
src=$2
work=$3
corpus=${VRMLRAY_CORPUS_DIR:-$src/../shared/corpus}
mkdir -p "$work"
passed=0
failed=0
fail() { echo "FAIL: $*"; failed=$((failed + 1)); }
pass() { passed=$((passed + 1)); }

# expect CODE DESCRIPTION -- COMMAND...: the command must exit with CODE.
expect() {
    local code=$1 what=$2
    shift 3
    "$@" >"$work/out.txt" 2>"$work/err.txt"
    local got=$?
    if [ "$got" -eq "$code" ]; then pass; else fail "$what: exit $got, expected $code"; sed 's/^/    /' "$work/err.txt" | head -5; fi
}

# expect_stderr PATTERN DESCRIPTION: the last command's stderr matches the extended regex.
expect_stderr() {
    if grep -Eq -- "$1" "$work/err.txt"; then pass; else fail "$2: stderr lacks /$1/"; sed 's/^/    /' "$work/err.txt" | head -5; fi
}

# A broken corpus file lives under a folder named bad, warnings or errors.
is_broken() { case "$1" in */bad/*|*/warnings/*|*/errors/*) return 0;; *) return 1;; esac; }

# --- exit codes and messages (SPEC section 1) ---------------------------------------------------------
expect 2 "no subcommand" -- "$bin"
expect 2 "unknown option" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" --no-such-option
expect 2 "bad --background" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" --background 1,2 -o "$work/x.png"
expect 3 "missing scene file" -- "$bin" render "$work/does_not_exist.wrl" -o "$work/x.png"
expect_stderr "does_not_exist.wrl: error: cannot open file" "missing file message"
printf '#VRML V2.0 utf8\nTransform {\n  children Shape { geometry Sphere { radius 1 colour 2 } }\n}\n' >"$work/bad_field.wrl"
expect 3 "unknown field" -- "$bin" render "$work/bad_field.wrl" -o "$work/x.png"
expect_stderr "bad_field.wrl:3:47: error: unknown field 'colour' in node Sphere" "error names file:line:col"
expect_stderr "^    +\^$" "caret under the column"
expect 4 "unwritable output" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 8 -H 8 -o "$work/no/such/dir/x.png"
expect 0 "info on the seed scene" -- "$bin" info "$src/scenes/seeds/001_sphere.wrl"
expect 2 "unknown sampler" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" --sampler bogus -W 8 -H 8 -o "$work/x.png"
expect 2 "grid needs a square spp" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" --sampler grid --spp 5 -W 8 -H 8 -o "$work/x.png"
expect_stderr "sampler 'grid' needs a square number" "sampler message"
for s in center grid rgss rooks8 quincunx jitter adaptive statistical; do
    expect 0 "sampler $s renders" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" --sampler $s -W 24 -H 16 -o "$work/s_$s.png" -q
done
expect 3 "a render that cannot fit in memory is refused before allocating" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 65536 -H 65536 -o "$work/x.png"
expect_stderr "001_sphere.wrl: error: rendering 65536x65536 .* needs about 103 GB, more than" "memory estimate message"
expect 3 "--max-memory lowers the limit" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 640 -H 480 --max-memory 0.001 -o "$work/x.png"
expect 0 "--max-memory raises nothing that fits" -- "$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 64 -H 48 --max-memory 0.01 -o "$work/x.png"
# --limit: a limit lowered below what a scene needs stops it with exit 3; an unknown name is a usage error.
printf '#VRML V2.0 utf8\nGroup { children Group { children Group { children Shape { geometry Sphere {} } } } }\n' >"$work/nested.wrl"
expect 0 "three levels pass the default nesting limit" -- "$bin" info "$work/nested.wrl"
expect 3 "--limit nesting-depth=2 refuses three levels" -- "$bin" info "$work/nested.wrl" --limit nesting-depth=2
expect_stderr "nested.wrl:2:.*: error: nodes nested deeper than 2" "lowered nesting limit message"
expect 3 "--limit primitives=1 refuses a scene of 17 quadrics" -- "$bin" render "$src/scenes/seeds/000_scene5_table_chairs.wrl" --limit primitives=1 -W 8 -H 8 -o "$work/x.png"
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
# Determinism: the same floats for 1 and 2 threads and on a second run (opaque with a random sampler, and gas).
for scene in 000_scene2_metal_glass 003_particles_gas; do
    "$bin" render "$src/scenes/seeds/$scene.wrl" -W 48 -H 36 --sampler jitter --spp 4 --seed 3 --threads 1 -q -o "$work/det1.exr"
    "$bin" render "$src/scenes/seeds/$scene.wrl" -W 48 -H 36 --sampler jitter --spp 4 --seed 3 --threads 2 -q -o "$work/det2.exr"
    "$bin" render "$src/scenes/seeds/$scene.wrl" -W 48 -H 36 --sampler jitter --spp 4 --seed 3 --threads 2 -q -o "$work/det3.exr"
    expect 0 "$scene: 1 and 2 threads give the same image" -- "$bin" compare "$work/det1.exr" "$work/det2.exr" --max-abs 0
    expect 0 "$scene: a second run gives the same image" -- "$bin" compare "$work/det2.exr" "$work/det3.exr" --max-abs 0
done
# Deterministic bytes (SPEC section 9): the same render writes the same file for any thread count, with
# no timestamp (the second run starts a second later, so a clock in the file would show).
for ext in exr png tif; do
    for alpha in "" --alpha; do
        "$bin" render "$src/scenes/seeds/003_particles_gas.wrl" -W 40 -H 30 $alpha --threads 1 -q -o "$work/bytes1.$ext"
        sleep 1
        "$bin" render "$src/scenes/seeds/003_particles_gas.wrl" -W 40 -H 30 $alpha --threads 2 -q -o "$work/bytes2.$ext"
        cmp -s "$work/bytes1.$ext" "$work/bytes2.$ext" && pass || fail "$ext $alpha: two renders wrote different bytes"
    done
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

# --- compare (SPEC section 10) -----------------------------------------------------------------------
"$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 32 -H 24 -o "$work/a.png" -q
"$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 32 -H 24 --background 1,1,1 -o "$work/b.png" -q
"$bin" render "$src/scenes/seeds/001_sphere.wrl" -W 16 -H 16 -o "$work/c.png" -q
expect 0 "identical images pass" -- "$bin" compare "$work/a.png" "$work/a.png" --max-rmse 0 --min-ssim 1
expect 1 "different images fail a threshold" -- "$bin" compare "$work/a.png" "$work/b.png" --max-rmse 0.01
expect 3 "size mismatch is an error" -- "$bin" compare "$work/a.png" "$work/c.png"
expect 0 "compare --json and --diff" -- "$bin" compare "$work/a.png" "$work/b.png" --json --diff "$work/diff.png"
grep -q '"rmse"' "$work/out.txt" && pass || fail "compare --json prints rmse"
[ -s "$work/diff.png" ] && pass || fail "compare --diff writes the heat-map"

# --- bench (SPEC section 11) ------------------------------------------------------------------------
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

# --- convert round trip ------------------------------------------------------------------------------
expect 0 "convert to X3D classic" -- "$bin" convert "$src/scenes/seeds/001_sphere.wrl" "$work/s.x3dv"
expect 0 "convert back to VRML97 gzip" -- "$bin" convert "$work/s.x3dv" "$work/s.wrl.gz"
expect 0 "render the converted file" -- "$bin" render "$work/s.wrl.gz" -W 32 -H 24 -o "$work/s.png" -q
expect 0 "converted file renders the same image" -- "$bin" compare "$work/a.png" "$work/s.png" --max-abs 0

# --- tests/corpus/good: valid files load (exit 0) with exactly their expected warnings ----------------------
for f in "$src"/tests/corpus/good/*.wrl; do
    name=$(basename "$f")
    (cd "$(dirname "$f")" && "$bin" info "$name" >/dev/null 2>"$work/err.txt")
    code=$?
    if [ $code -eq 0 ] && cmp -s "$work/err.txt" "${f%.wrl}.expected"; then pass; else
        fail "good/$name: exit $code, or warnings differ from ${name%.wrl}.expected:"; diff "$work/err.txt" "${f%.wrl}.expected" | head -5
    fi
done

# --- tests/corpus/bad: every broken file fails with exit 3 and exactly its expected first message ---------
for f in "$src"/tests/corpus/bad/*.wrl; do
    name=$(basename "$f")
    (cd "$(dirname "$f")" && "$bin" info "$name" -q >/dev/null 2>"$work/err.txt")
    code=$?
    expected=$(cat "${f%.wrl}.expected")
    got=$(head -1 "$work/err.txt")
    if [ $code -eq 3 ] && [ "$got" = "$expected" ]; then pass; else fail "bad/$name: exit $code, message '$got', expected '$expected'"; fi
done

# --- every corpus file: info never crashes; valid files load and render without NaN --------------------
if [ -d "$corpus" ]; then
    while IFS= read -r -d '' f; do
        "$bin" info "$f" -q >"$work/out.txt" 2>"$work/err.txt"
        code=$?
        if is_broken "$f"; then
            { [ $code -eq 0 ] || [ $code -eq 3 ]; } && pass || fail "info $f: exit $code (broken file must exit 0 or 3)"
        else
            [ $code -eq 0 ] && pass || { fail "info $f: exit $code"; head -3 "$work/err.txt"; }
        fi
    done < <(find "$corpus" -type f \( -name '*.wrl' -o -name '*.wrl.gz' -o -name '*.wrz' -o -name '*.x3dv' -o -name '*.x3d' -o -name '*.x3dz' -o -name '*.x3dvz' \) -print0 | sort -z)

    while IFS= read -r -d '' f; do
        is_broken "$f" && continue
        "$bin" render "$f" -W 48 -H 36 -o "$work/corpus.exr" -q >"$work/out.txt" 2>"$work/err.txt"
        code=$?
        if [ $code -ne 0 ]; then fail "render $f: exit $code"; head -3 "$work/err.txt"; continue; fi
        # compare counts a NaN or infinity as an infinite difference, so an image with one fails against itself.
        "$bin" compare "$work/corpus.exr" "$work/corpus.exr" --max-abs 0 >/dev/null 2>&1 && pass || fail "render $f: NaN or inf in the image"
    done < <(find "$corpus/vrml97" "$corpus/x3dv" -type f \( -name '*.wrl' -o -name '*.wrl.gz' -o -name '*.x3dv' \) -print0 | sort -z)
else
    echo "note: corpus not found at $corpus; corpus tests skipped"
fi

# --- golden images of the bundled scenes --------------------------------------------------------------
# Each tests/render/golden/NAME.png was rendered by vrmlray at the size in tests/render/golden/sizes.txt
# and inspected by eye. A render may differ from it by rounding only: one 8-bit step at a few pixels
# (platform libm differences at silhouettes), so thresholds allow max 1/255 on 0.5% of pixels and SSIM >= 0.995.
if [ -f "$src/tests/render/golden/sizes.txt" ]; then
    while read -r name w h extra; do
        [ -z "$name" ] && continue
        case "$name" in \#*) continue;; esac
        scene=$(find "$src/scenes" -name "$name.wrl" | head -1)
        # shellcheck disable=SC2086
        "$bin" render "$scene" -W "$w" -H "$h" $extra -o "$work/golden_$name.png" -q 2>"$work/err.txt" || { fail "golden $name: render failed"; continue; }
        expect 0 "golden $name" -- "$bin" compare "$work/golden_$name.png" "$src/tests/render/golden/$name.png" \
            --pixel-threshold 0.0040 --max-fail-percent 0.5 --min-ssim 0.995
    done <"$src/tests/render/golden/sizes.txt"
fi

echo "cli: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
