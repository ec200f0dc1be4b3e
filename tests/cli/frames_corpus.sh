# Sourced by run_cli_corpus.sh: the frames of a sequence shared out among threads (issue 19, item
# 2). Frames are independent, so every frame must be the same bytes whether frames render one a
# thread, one after another with their tiles over the threads, or alone at their --time. Uses its
# $bin, $work, $corpus and pass/fail helpers.
fr=$work/frames
mkdir -p "$fr"
mol=$corpus/molecular/pymol/pept_spheres.wrl
prim=$corpus/x3dv/castle-engine-demo-models/shadow_maps/primitives.x3dv

# same_frames A B N: the frame files A_00.png ... and B_00.png ... (N of each) are the same bytes.
same_frames() {
    local k same=0
    for ((k = 0; k < $3; k++)); do
        cmp -s "$(printf '%s_%02d.png' "$1" $k)" "$(printf '%s_%02d.png' "$2" $k)" && same=$((same + 1))
    done
    [ "$same" -eq "$3" ] && pass || fail "$4 ($same of $3 frames the same bytes)"
}
# stats_are FILE PYTHON-EXPRESSION: the --stats file's JSON (j) satisfies the expression.
stats_are() {
    python3 -c 'import json,sys; j=json.load(open(sys.argv[1])); sys.exit(not eval(sys.argv[2]))' "$1" "$2" &&
        pass || fail "$3: $(head -c 300 "$1")"
}

# A 12-frame turntable of a molecule: the scene is static, so it is built once however the frames
# are shared out.
orbit=(render "$mol" -W 64 -H 48 --frames 12 --orbit 360)
expect 0 "orbit, a frame a thread" -- "$bin" "${orbit[@]}" --threads 2 -o "$fr/orbit2_%02d.png" --stats "$fr/orbit2.json"
stats_are "$fr/orbit2.json" 'j["frames_at_once"] == 2 and j["scene_builds"] == 1 and j["frame"] == 11' \
    "12 frames on 2 threads render 2 at once and build the scene once"
expect 0 "orbit, one thread" -- "$bin" "${orbit[@]}" -q --threads 1 -o "$fr/orbit1_%02d.png"
expect 0 "orbit, tiles over 2 threads" -- "$bin" "${orbit[@]}" -q --threads 2 --frames-at-once 1 -o "$fr/orbitt_%02d.png" --stats "$fr/orbitt.json"
stats_are "$fr/orbitt.json" 'j["frames_at_once"] == 1 and j["scene_builds"] == 1' "--frames-at-once 1"
same_frames "$fr/orbit2" "$fr/orbit1" 12 "orbit: frames at once against one thread"
same_frames "$fr/orbit2" "$fr/orbitt" 12 "orbit: frames at once against tiles over threads"
same=0
for k in $(seq 0 11); do
    name=$(printf 'orbit2_%02d.png' "$k")
    "$bin" "${orbit[@]}" -q --frame "$k" -o "$fr/alone_%02d.png" && cmp -s "$fr/$(printf 'alone_%02d.png' "$k")" "$fr/$name" && same=$((same + 1))
done
[ "$same" -eq 12 ] && pass || fail "orbit frames rendered at once equal 12 renders of --frame K ($same of 12)"

# An animated file: each of the 12 frames moves the sphere, so each builds its own scene, also
# when two or three render at once (each its own evaluation of the one node tree).
anim=(render "$prim" -W 48 -H 36 -q --frames 12 --fps 4)
expect 0 "primitives, a frame a thread" -- "$bin" "${anim[@]}" --threads 2 -o "$fr/prim2_%02d.png" --stats "$fr/prim2.json"
stats_are "$fr/prim2.json" 'j["frames_at_once"] == 2 and j["scene_builds"] == 12' "an animated file builds every frame"
expect 0 "primitives, one thread" -- "$bin" "${anim[@]}" --threads 1 -o "$fr/prim1_%02d.png"
expect 0 "primitives, three at once on 2 threads" -- "$bin" "${anim[@]}" --threads 2 --frames-at-once 3 -o "$fr/prim3_%02d.png"
expect 0 "primitives, tiles over 2 threads" -- "$bin" "${anim[@]}" --threads 2 --frames-at-once 1 -o "$fr/primt_%02d.png"
same_frames "$fr/prim2" "$fr/prim1" 12 "primitives: frames at once against one thread"
same_frames "$fr/prim2" "$fr/prim3" 12 "primitives: three at once against two"
same_frames "$fr/prim2" "$fr/primt" 12 "primitives: frames at once against tiles over threads"
for ((k = 0; k < 12; k++)); do
    "$bin" render "$prim" -W 48 -H 36 -q --time "$(python3 -c "print($k / 4)")" -o "$(printf '%s/prim_alone_%02d.png' "$fr" $k)"
done
same_frames "$fr/prim2" "$fr/prim_alone" 12 "primitives: frames at once against single --time renders"

# A frame that cannot be written (its name is taken by a folder): exit 4, named, with no hang.
mkdir -p "$fr/bad_05.png"
expect 4 "a frame that cannot be written" -- timeout 120 "$bin" "${orbit[@]}" -q --threads 2 -o "$fr/bad_%02d.png"
expect_stderr "bad_05\.png" "the unwritable frame is named"
