#!/usr/bin/env bash
# Whole-program tests of golden-image suites (docs/golden-tests.md, docs/golden-tests.md): batch render, folder
# compare, --junit against tests/cli/junit.xsd, the --report page in a real browser (Debian's chromium,
# headless, which tools/setup.sh installs) and --update.
# Usage: run_suite_tests.sh VRMLRAY_BINARY SOURCE_DIR WORK_DIR
# shellcheck source=tests/cli/common.sh
. "$(dirname "$0")/common.sh"
seeds=$src/scenes/seeds

# png_size FILE: "WIDTHxHEIGHT" from the PNG header.
png_size() { python3 -c 'import struct,sys; d=open(sys.argv[1],"rb").read(24); print("%dx%d" % struct.unpack(">II", d[16:24]))' "$1"; }

# --- batch render: several scenes, one process, each with its own errors ----------------------------
expect 0 "render three scenes into a folder" -- "$bin" render "$seeds/001_sphere.wrl" "$seeds/001_flat.wrl" \
    "$src/tests/corpus/good/gzipped.wrl.gz" -W 32 -H 24 -q -o "$work/ref/"
for f in 001_sphere 001_flat gzipped; do  # outside the current folder: the file name, scene extensions off
    [ "$(png_size "$work/ref/$f.png" 2>/dev/null)" = 32x24 ] && pass || fail "batch wrote $f.png at 32x24"
done
grep -q '^batch: 3 scenes, 3 rendered, 0 failed' "$work/out.txt" && pass || fail "batch summary counts 3 rendered"
# --stats in a batch: one JSON file with a record a scene, in the batch's order (each scene's own
# record, as a single render writes it), and the failed ones named, so no scene's figures overwrite another's.
expect 3 "batch with --stats" -- "$bin" render "$seeds/001_sphere.wrl" "$src/tests/corpus/bad/binary_garbage.wrl" \
    "$seeds/001_flat.wrl" -W 16 -H 12 -q -o "$work/stats/" --stats "$work/batch_stats.json"
python3 - "$work/batch_stats.json" <<'PY' && pass || fail "batch --stats holds every scene's record in order"
import json, sys
j = json.load(open(sys.argv[1]))
scenes = j["scenes"]
assert [s["scene"].rsplit("/", 1)[-1] for s in scenes] == ["001_sphere.wrl", "binary_garbage.wrl", "001_flat.wrl"], scenes
assert scenes[0]["exit_code"] == 0 and scenes[1]["exit_code"] == 3 and scenes[2]["exit_code"] == 0
assert scenes[0]["stats"]["width"] == 16 and "stats" not in scenes[1]
assert scenes[0]["stats"]["primitives"]["spheres"] == 1
assert j["rendered"] == 2 and j["failed"] == 1 and j["seconds"] > 0
PY
# Relative paths are kept below the folder, so that two scenes of one name in two folders do not clash.
(cd "$src" && "$bin" render scenes/seeds/001_sphere.wrl tests/corpus/good/features.wrl -W 16 -H 12 -q \
    -o "$work/rel") >/dev/null 2>&1 || true
[ -f "$work/rel/scenes/seeds/001_sphere.png" ] && [ -f "$work/rel/tests/corpus/good/features.png" ] && pass ||
    fail "batch into an existing folder keeps the scenes' relative paths"
mkdir -p "$work/rel2"
expect 0 "an existing folder as -o is a batch of one" -- "$bin" render "$seeds/001_flat.wrl" -W 8 -H 6 -q -o "$work/rel2"
[ -f "$work/rel2/001_flat.png" ] && pass || fail "batch of one writes DIR/001_flat.png"
# A broken file fails alone: the others are rendered, the summary names it, the exit is 3.
expect 3 "a bad scene in a batch" -- "$bin" render "$seeds/001_flat.wrl" "$src/tests/corpus/bad/binary_garbage.wrl" \
    "$seeds/001_sphere.wrl" -W 8 -H 6 -q -o "$work/bad/"
[ -f "$work/bad/001_flat.png" ] && [ -f "$work/bad/001_sphere.png" ] && [ ! -e "$work/bad/binary_garbage.png" ] &&
    pass || fail "the good scenes of a batch with a bad one are rendered"
grep -q '^batch: 3 scenes, 2 rendered, 1 failed' "$work/out.txt" && grep -q '^FAILED .*binary_garbage.wrl (exit 3)' \
    "$work/out.txt" && pass || fail "the summary names the failed scene"
expect_stderr 'binary_garbage.wrl:1:1: error' "the bad scene's own message"
# Two scenes of one stem (the corpus has pept_spacefill.wrl and .x3d) keep their extensions apart.
mkdir -p "$work/stem"
cp "$seeds/001_sphere.wrl" "$work/stem/a.wrl" && gzip -c "$seeds/001_flat.wrl" >"$work/stem/a.wrl.gz"
(cd "$work/stem" && "$bin" render a.wrl a.wrl.gz -W 8 -H 6 -q -o out/) >/dev/null 2>&1
[ -f "$work/stem/out/a.wrl.png" ] && [ -f "$work/stem/out/a.wrl.gz.png" ] && [ ! -e "$work/stem/out/a.png" ] && pass ||
    fail "scenes of one stem keep their extensions in the batch's output names"
expect 0 "batch with --format exr" -- "$bin" render "$seeds/001_flat.wrl" -W 8 -H 6 -q --format exr -o "$work/exr/"
expect 0 "the batch's EXR reads back" -- "$bin" compare "$work/exr/001_flat.exr" "$work/exr/001_flat.exr"

# --list: one scene a line with its own options (after the command line's, so they win), paths relative to
# the list's folder, -o naming the output inside the folder; a line with a bad option fails alone.
mkdir -p "$work/list/sub"
cp "$seeds/001_sphere.wrl" "$work/list/sub/ball.wrl"
cat >"$work/list/suite.txt" <<EOF
# a comment, then a blank line

sub/ball.wrl
sub/ball.wrl --width 20 -o wide.png   # a comment after the options
"$seeds/001_flat.wrl" -H 4
sub/ball.wrl --width 0 -o bad.png
sub/ball.wrl -o wide.png
EOF
expect 3 "render --list with a bad line" -- "$bin" render --list "$work/list/suite.txt" -W 10 -H 8 -q -o "$work/listout/"
[ "$(png_size "$work/listout/sub/ball.png")" = 10x8 ] && pass || fail "a list line takes the command line's options"
[ "$(png_size "$work/listout/wide.png")" = 20x8 ] && pass || fail "a list line's own option wins, -o names the output"
[ "$(png_size "$work/listout/001_flat.png")" = 10x4 ] && pass || fail "a quoted absolute path in a list"
[ ! -e "$work/listout/bad.png" ] && pass || fail "a line with a bad option renders nothing"
grep -q '^batch: 5 scenes, 3 rendered, 2 failed' "$work/out.txt" && grep -q "^FAILED .*suite.txt:6 (exit 2)" \
    "$work/out.txt" && grep -q "^FAILED .*suite.txt:7 (exit 2)" "$work/out.txt" && pass ||
    { fail "list summary: the bad line and the clashing output fail"; cat "$work/out.txt"; }
expect_stderr 'suite.txt:7: error: its output .*wide.png is also .*suite.txt:4' "a clashing output is named"
expect_stderr 'suite.txt:6: error: --width: Value 0 not in range 1 to 65536; scene not rendered' "a bad line's message has its place"
expect 2 "scenes and --list together" -- "$bin" render "$seeds/001_flat.wrl" --list "$work/list/suite.txt" -o "$work/x/"
expect 3 "an unreadable --list" -- "$bin" render --list "$work/no_such_list.txt" -o "$work/x/"

# --- folder compare ----------------------------------------------------------------------------------
cp -r "$work/ref" "$work/same"
expect 0 "identical folders pass" -- "$bin" compare "$work/ref" "$work/same"
cp -r "$work/ref" "$work/out"
"$bin" render "$seeds/001_sphere.wrl" -W 32 -H 24 -q --background 0.3,0.3,0.3 -o "$work/out/001_sphere.png"
"$bin" render "$seeds/001_flat.wrl" -W 24 -H 24 -q -o "$work/out/001_flat.png"
rm "$work/out/gzipped.png"
cp "$work/ref/001_sphere.png" "$work/out/extra one.png"
cp "$work/ref/001_sphere.png" "$work/ref/ok.png" && cp "$work/ref/001_sphere.png" "$work/out/ok.png"
echo "notes" >"$work/ref/README.txt"  # no image: not part of the suite
expect 1 "a changed, a resized, a missing and an extra image fail" -- "$bin" compare "$work/ref" "$work/out" \
    --junit "$work/suite.xml" --report "$work/report"
cp "$work/out.txt" "$work/table.txt"
# Worst first: missing, extra, size, fail, then the pass; each with its own line.
[ "$(awk 'NR>1 && !/^[0-9]+ images/ {print $1}' "$work/table.txt" | tr '\n' ' ')" = "missing extra size fail pass " ] &&
    pass || { fail "table lists missing, extra, size, fail, pass in that order"; cat "$work/table.txt"; }
grep -q '^size .*001_flat.png  (reference 32x24, result 24x24)' "$work/table.txt" && pass || fail "size line gives both sizes"
grep -q '^5 images: 1 passed, 0 warned, 4 failed' "$work/table.txt" && pass || fail "table counts"
"$bin" compare "$work/ref" "$work/out" --threads 1 >"$work/table1.txt"
cmp -s "$work/table.txt" "$work/table1.txt" && pass || fail "one thread gives the same table as all cores"
expect 0 "thresholds apply per pair" -- "$bin" compare "$work/ref/ok.png" "$work/out/ok.png" --max-rmse 0
# --thresholds: a pair's own thresholds by glob, after the command line's; a bad line is named.
printf '# the sphere was re-lit on purpose\n001_sphere.png --max-rmse 0.3 --min-ssim 0.2\n' >"$work/th.txt"
"$bin" compare "$work/ref" "$work/out" --thresholds "$work/th.txt" >"$work/out.txt"
grep -q '^pass .*001_sphere.png$' "$work/out.txt" && grep -q '^pass .*ok.png$' "$work/out.txt" && pass ||
    fail "--thresholds loosens one pair only"
printf 'ok.png --max-rmse\n' >"$work/th_bad.txt"
expect 2 "a bad --thresholds line" -- "$bin" compare "$work/ref" "$work/out" --thresholds "$work/th_bad.txt"
expect_stderr 'th_bad.txt:1: error: --max-rmse: 1 required FLOAT missing' "a bad --thresholds line is named"
# A report written inside the result folder (out/report, a common CI layout) is not part of the suite:
# its images must not show as extra on the next compare, nor as pairs of their own.
cp -r "$work/out" "$work/out_in"
"$bin" compare "$work/ref" "$work/out_in" --report "$work/out_in/report" >/dev/null 2>&1
"$bin" compare "$work/ref" "$work/out_in" --report "$work/out_in/report" >"$work/table_in.txt" 2>&1
grep -q '^5 images: 1 passed, 0 warned, 4 failed' "$work/table_in.txt" && ! grep -q 'report/' "$work/table_in.txt" &&
    pass || { fail "a report inside the result folder is left out of the next compare"; head "$work/table_in.txt"; }
expect 2 "a folder against a file" -- "$bin" compare "$work/ref" "$work/ref/ok.png"
expect 2 "--report with two images" -- "$bin" compare "$work/ref/ok.png" "$work/out/ok.png" --report "$work/r2"

# JUnit: valid against the schema, one test case per pair, the failure carrying the figures.
xmllint --noout --schema "$src/tests/cli/junit.xsd" "$work/suite.xml" 2>"$work/err.txt" && pass ||
    { fail "--junit validates against tests/cli/junit.xsd"; head -5 "$work/err.txt"; }
[ "$(grep -c '<testcase ' "$work/suite.xml")" = 5 ] && pass || fail "--junit: a test case per pair"
grep -q '<failure type="fail" message="[^"]*">RMSE 0\.[0-9]*, PSNR' "$work/suite.xml" && pass || fail "--junit failure with figures"

# --- the report in a real browser ---------------------------------------------------------------------
browser=$(command -v chromium || true)
if [ -z "$browser" ]; then
    fail "chromium is not installed (tools/setup.sh installs it): the report cannot be tested in a browser"
else
    run_browser() { timeout 120 "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
        --user-data-dir="$work/chromium" "$@" 2>>"$work/browser.log"; }
    run_browser --dump-dom "file://$work/report/index.html" >"$work/dom.html"
    # The DOM after the page's script ran: the failing pair's section with its status and figures, all pairs.
    tr -d '\n' <"$work/dom.html" | grep -q '<section class="pair" data-status="fail" data-failed=""><h2><span class="status">fail</span>001_sphere.png</h2><div class="figs">RMSE 0\.' \
        && pass || fail "report DOM: the failing pair with its status and figures"
    [ "$(grep -o '<section class="pair"' "$work/dom.html" | wc -l)" = 5 ] && pass || fail "report DOM: five pairs"
    grep -q 'extra one.png' "$work/dom.html" && pass || fail "report DOM: the extra image's name"
    # The status filter, set from the address: only the failure is shown, the pass is hidden.
    run_browser --dump-dom "file://$work/report/index.html#status=fail" >"$work/dom_fail.html"
    grep -q 'data-status="pass" hidden=""' "$work/dom_fail.html" && ! grep -q 'data-status="fail" data-failed="" hidden' \
        "$work/dom_fail.html" && pass || fail "report filter #status=fail hides the passes only"
    # Every image the page names is there (no network: relative paths only).
    missing_img=0
    for img in $(grep -o 'src="[^"]*"' "$work/report/index.html" | sed 's/src="//; s/"$//'); do
        [ -f "$work/report/$(python3 -c 'import sys,urllib.parse; print(urllib.parse.unquote(sys.argv[1]))' "$img")" ] ||
            { missing_img=1; echo "    no $img"; }
    done
    [ $missing_img = 0 ] && pass || fail "report: every image it shows exists"
    run_browser --screenshot="$work/report.png" --window-size=1000,900 "file://$work/report/index.html" >/dev/null
    # Non-empty: a PNG of the window's size that differs clearly from a blank page of the same size
    # (text, borders and images move the RMSE against white well above 0.02; a page that failed to
    # render is white or black).
    if [ "$(png_size "$work/report.png" 2>/dev/null)" = 1000x900 ]; then
        pass
        nch=$(python3 -c 'import sys; t=open(sys.argv[1],"rb").read(26)[25]; print({2:3,6:4}.get(t,0))' "$work/report.png")
        python3 "$src/tests/cli/make_png.py" "$work/white.png" 1000 900 "$nch" 255
        "$bin" compare "$work/report.png" "$work/white.png" --json >"$work/shot.json"
        python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); sys.exit(not (d["rmse"] > 0.02 and d["rmse"] < 0.9))' \
            "$work/shot.json" && pass || fail "report screenshot shows something (RMSE against white in (0.02, 0.9))"
    else
        fail "report screenshot of 1000x900 written"
    fi
fi

# --- --update: the failing results become the references, each replacement printed -------------------
cp -r "$work/ref" "$work/upd"
expect 1 "--update leaves the missing image failing" -- "$bin" compare "$work/upd" "$work/out" --update
grep -q "^updated $work/upd/001_sphere.png <- $work/out/001_sphere.png (fail)" "$work/out.txt" &&
    grep -q "^updated $work/upd/001_flat.png <- .* (size)" "$work/out.txt" &&
    grep -q "^added $work/upd/extra one.png <- .* (extra)" "$work/out.txt" && pass ||
    { fail "--update prints each replacement"; cat "$work/out.txt"; }
cmp -s "$work/upd/001_sphere.png" "$work/out/001_sphere.png" && cmp -s "$work/ref/ok.png" "$work/upd/ok.png" && pass ||
    fail "--update copied the failing result and left the passing reference"
expect 1 "after --update only the missing image fails" -- "$bin" compare "$work/upd" "$work/out"
grep -q '^5 images: 4 passed, 0 warned, 1 failed (0 over a threshold, 1 missing' "$work/out.txt" && pass ||
    fail "after --update: 4 passed, 1 missing"

echo "suite: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
