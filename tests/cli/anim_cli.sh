# Sourced by run_cli_tests.sh: the command line of --time, --frames and the camera overrides, on
# repo-only inputs (docs/animation.md). Uses its $bin, $src, $work and pass/fail helpers.
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
# IS events in an X3D XML <ProtoBody> (<connect> of inputOnly, outputOnly and inputOutput fields)
# animate as the classic encoding's IS: the same scene in both encodings gives the same bytes at
# two times, and the two times differ (the box, its colour and the sphere that follows it move).
anim=$src/tests/cli/anim
for t in 0.5 1.5; do
    for ext in x3dv x3d; do
        expect 0 "proto_is.$ext at --time $t" -- "$bin" render "$anim/proto_is.$ext" -W 48 -H 32 -q --time "$t" -o "$work/proto_is_${ext}_$t.png"
    done
    cmp -s "$work/proto_is_x3dv_$t.png" "$work/proto_is_x3d_$t.png" && pass || fail "XML and classic PROTO IS events animate the same at $t"
done
cmp -s "$work/proto_is_x3d_0.5.png" "$work/proto_is_x3d_1.5.png" && fail "the XML PROTO's IS events move it between 0.5 and 1.5 s" || pass
# IMPORT/EXPORT: a ROUTE of the main file moves a node of its Inline, in both encodings alike.
for t in 0.5 1.5; do
    for ext in x3dv x3d; do
        expect 0 "import_main.$ext at --time $t" -- "$bin" render "$anim/import_main.$ext" -W 48 -H 32 -q --time "$t" -o "$work/import_${ext}_$t.png"
    done
    cmp -s "$work/import_x3dv_$t.png" "$work/import_x3d_$t.png" && pass || fail "XML and classic IMPORT animate the same at $t"
done
cmp -s "$work/import_x3dv_0.5.png" "$work/import_x3dv_1.5.png" && fail "a ROUTE to an IMPORTed node moves it" || pass
cp "$anim/import_inner.x3dv" "$work/import_inner.x3dv"
printf '#X3D V3.3 utf8\nPROFILE Immersive\nDEF I Inline { url "import_inner.x3dv" }\n  IMPORT I.Nothing AS N\n' >"$work/bad_export.x3dv"
expect 3 "IMPORT of a name the Inline does not export" -- "$bin" render "$work/bad_export.x3dv" -W 8 -H 8 -o "$work/x.png"
expect_stderr "bad_export.x3dv:4:3: error: IMPORT: the file of Inline 'I' \(.*import_inner.x3dv\) exports no 'Nothing'" "unknown export names the IMPORT"
printf '#X3D V3.3 utf8\nPROFILE Immersive\nDEF I Transform {}\nIMPORT I.Box AS N\n' >"$work/bad_import.x3dv"
expect 3 "IMPORT of a node that is no Inline" -- "$bin" render "$work/bad_import.x3dv" -W 8 -H 8 -o "$work/x.png"
expect_stderr "bad_import.x3dv:4:8: error: IMPORT names 'I', a Transform, not an Inline" "IMPORT of a Transform names the place"
printf '<X3D><Scene><Transform DEF="I"/>\n<IMPORT inlineDEF="I" importedDEF="Box" AS="N"/></Scene></X3D>\n' >"$work/bad_import.x3d"
expect 3 "XML IMPORT of a node that is no Inline" -- "$bin" render "$work/bad_import.x3d" -W 8 -H 8 -o "$work/x.png"
expect_stderr "bad_import.x3d:2:20: error: IMPORT names 'I', a Transform, not an Inline" "XML IMPORT error names the attribute"
