# Sourced by run_cli_tests.sh: the command line of --time, --frames and the camera overrides, on
# repo-only inputs (SPEC section 12). Uses its $bin, $src, $work and pass/fail helpers.
seed=$src/scenes/seeds/001_sphere.wrl
expect 2 "--frames 2 without a pattern" -- "$bin" render "$seed" -W 8 -H 8 --frames 2 -o "$work/x.png"
expect_stderr "error: --frames 2 needs -o with a frame number pattern" "frames without pattern message"
expect 2 "a pattern that is not %d" -- "$bin" render "$seed" -W 8 -H 8 --frames 2 -o "$work/x_%s.png"
expect 2 "--fov out of (0, pi)" -- "$bin" render "$seed" -W 8 -H 8 --fov 3.2 -o "$work/x.png"
expect_stderr "error: --fov must lie in \(0, pi\)" "fov message"
expect 2 "--look-at the camera's own position" -- "$bin" render "$seed" -W 8 -H 8 --position 1,2,3 --look-at 1,2,3 -o "$work/x.png"
expect 2 "--position with two numbers" -- "$bin" render "$seed" -W 8 -H 8 --position 1,2 -o "$work/x.png"
# --position/--look-at: looking at the sphere from the other side gives the mirror image of a
# symmetric scene's view... here simply: a camera aimed away from the scene sees only background.
expect 0 "camera looking away" -- "$bin" render "$seed" -W 16 -H 12 --position 0,0,10 --look-at 0,0,20 -o "$work/away.png"
expect_stderr "nothing of the scene is in view" "a camera turned away sees nothing"
expect 0 "camera looking at it" -- "$bin" render "$seed" -W 16 -H 12 --position 0,0,10 --look-at 0,0,0 -o "$work/at.png"
grep -q "nothing of the scene" "$work/err.txt" && fail "a camera looking at the sphere sees it" || pass
# A ROUTE between mismatched types is an error at the ROUTE (exit 3, file:line:col).
printf '#VRML V2.0 utf8\nDEF C TimeSensor {}\nDEF T Transform {}\nROUTE C.fraction_changed TO T.set_translation\n' >"$work/bad_route.wrl"
expect 3 "ROUTE of mismatched types" -- "$bin" render "$work/bad_route.wrl" -W 8 -H 8 -o "$work/x.png"
expect_stderr "bad_route.wrl:4:1: error: ROUTE from TimeSensor 'C'.fraction_changed \(SFFloat\) to Transform 'T'.set_translation \(SFVec3f\): the types differ" "route type error names the place"
# A ROUTE no TimeSensor drives (a TouchSensor's) over several frames: the tree is released after
# the first frame's build, and later frames must not touch it (this crashed).
printf '#VRML V2.0 utf8\nDEF S TouchSensor {}\nDEF T Transform { children Shape { geometry Box {} } }\nROUTE S.hitPoint_changed TO T.set_translation\n' >"$work/touch.wrl"
expect 0 "frames of a scene whose ROUTEs no TimeSensor drives" -- "$bin" render "$work/touch.wrl" -W 16 -H 12 -q --frames 3 -o "$work/touch_%d.png"
cmp -s "$work/touch_0.png" "$work/touch_2.png" && pass || fail "a static scene renders the same frames"
# Frames at once (a frame a thread, the default with at least as many frames as threads) against
# one after another with each frame's tiles over the threads: the same bytes, for the 8-bit PNG and
# the float EXR paths of the tracer's output.
for ext in png exr; do
    expect 0 "4 frames at once ($ext)" -- "$bin" render "$seed" -W 40 -H 30 -q --frames 4 --orbit 90 --threads 2 -o "$work/at_once_%d.$ext" --stats "$work/at_once.json"
    expect 0 "4 frames one after another ($ext)" -- "$bin" render "$seed" -W 40 -H 30 -q --frames 4 --orbit 90 --threads 2 --frames-at-once 1 -o "$work/in_turn_%d.$ext"
    same=0
    for k in 0 1 2 3; do cmp -s "$work/at_once_$k.$ext" "$work/in_turn_$k.$ext" && same=$((same + 1)); done
    [ "$same" -eq 4 ] && pass || fail "frames at once wrote other $ext bytes than one after another ($same of 4 the same)"
done
python3 -c 'import json,sys; j=json.load(open(sys.argv[1])); sys.exit(not (j["frames_at_once"] == 2 and j["scene_builds"] == 1 and j["frame"] == 3))' "$work/at_once.json" &&
    pass || fail "4 frames on 2 threads: 2 at once, the static scene built once, the stats of frame 3"
cmp -s "$work/at_once_0.png" "$work/at_once_3.png" && fail "the orbit turned the camera between frames" || pass
