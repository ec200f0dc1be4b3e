#!/usr/bin/env bash
# Many processes (docs/mpi.md): `mpirun -np 3 vrmlray render` writes the same bytes as one
# process, for opaque spheres, gas, a textured mesh and every random or neighbour-sharing sampler,
# 8-bit and float output; a process that cannot read the scene makes all exit alike, none hangs.
# Usage: run_mpi_tests.sh VRMLRAY_BINARY SOURCE_DIR WORK_DIR MPI(ON|OFF). Exit 77 (skipped) when
# the binary is built without MPI or mpirun is missing. Corpus files (../shared/corpus, or
# VRMLRAY_CORPUS) are added when present.
# shellcheck source=tests/cli/common.sh
. "$(dirname "$0")/common.sh"
if [ "${4:-OFF}" != ON ]; then echo "SKIPPED: vrmlray is built without MPI (VRMLRAY_MPI=OFF)"; exit 77; fi
command -v mpirun >/dev/null || { echo "SKIPPED: no mpirun on PATH"; exit 77; }
# Open MPI refuses root without --allow-run-as-root, and 3 processes on fewer cores without
# --oversubscribe; one thread a process keeps the machine's other work going.
mpi=(mpirun --oversubscribe --allow-run-as-root -np 3)
# Open MPI's start-up allocates memory it never frees: LeakSanitizer (CI's sanitizer run) would fail
# every process on it. Address and undefined-behaviour errors still fail.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
seeds=$src/scenes/seeds
corpus=${VRMLRAY_CORPUS:-$(cd "$src/.." && pwd)/shared/corpus}
good=$seeds/001_sphere.wrl

# same NAME ARGS...: one process and three render ARGS to NAME.EXT; the files must be equal.
same() {
    local name=$1 ext=$2
    shift 2
    expect 0 "$name: one process" -- "$bin" render "$@" -q --threads 2 -o "$work/$name.1.$ext"
    expect 0 "$name: three processes" -- "${mpi[@]}" "$bin" render "$@" -q --threads 1 \
        -o "$work/$name.3.$ext" --stats "$work/$name.json"
    if cmp -s "$work/$name.1.$ext" "$work/$name.3.$ext"; then pass; else
        fail "$name: three processes wrote other bytes than one"; fi
}

same sphere png "$seeds/001_sphere.wrl" -W 100 -H 70
same gas png "$seeds/003_particles_gas.wrl" -W 90 -H 64
same gas_alpha png "$seeds/003_particles_gas.wrl" -W 90 -H 64 --alpha
same gas_exr exr "$seeds/003_particles_gas.wrl" -W 90 -H 64 --alpha  # the float image's tiles
same checkerboard_texture png "$seeds/000_scene3_checkerboard.wrl" -W 96 -H 80
same bubbles_jitter png "$seeds/000_scene1_glass_bubbles.wrl" -W 80 -H 60 --sampler jitter --spp 4 --seed 5
same bubbles_statistical png "$seeds/000_scene1_glass_bubbles.wrl" -W 80 -H 60 --sampler statistical --spp 32
same bubbles_adaptive png "$seeds/000_scene1_glass_bubbles.wrl" -W 80 -H 60 --sampler adaptive
same one_tile png "$seeds/001_sphere.wrl" -W 16 -H 16  # one tile: two of the three processes have none
same mirrors_quincunx ppm "$seeds/000_scene4_mirror_spheres.wrl" -W 80 -H 60 --sampler quincunx
if [ -d "$corpus" ]; then
    same pymol_gas png "$corpus/molecular/pymol/pept_spheres.wrl" -W 120 -H 90 --spheres gas --density 0.03
    same castle_textures png "$corpus/vrml97/castle-engine-demo-models/castle/old/vrml_2/castle_with_lights_and_camera.wrl" -W 120 -H 90
else
    echo "note: no corpus at $corpus; its cases are left out"
fi

# --stats: each process's share; together they are every tile and every ray of the image.
python3 - "$work/bubbles_jitter.json" <<'PY' && pass || fail "--stats processes do not add up"
import json, sys
j = json.load(open(sys.argv[1]))
p = j["processes"]
tiles = -(-80 // 16) * -(-60 // 16)
assert [q["rank"] for q in p] == [0, 1, 2], p
assert sum(q["tiles"] for q in p) == tiles, p
# Interleaved tiles: no process gets more than one tile over its even share.
assert max(q["tiles"] for q in p) - min(q["tiles"] for q in p) <= 1, p
r = j["rays"]
assert sum(q["rays"] for q in p) == r["primary"] + r["shadow"] + r["secondary"], (p, r)
assert r["primary"] == 4 * 80 * 60, r  # jitter --spp 4: every pixel's four rays, counted once
assert all(q["seconds"][k] >= 0 for q in p for k in q["seconds"]), p
PY
# One process: no "processes" entry (the stats are as they always were).
expect 0 "one process: stats" -- "$bin" render "$seeds/001_sphere.wrl" -W 20 -H 20 -q -o "$work/s.png" --stats "$work/one.json"
python3 -c 'import json,sys; assert "processes" not in json.load(open(sys.argv[1]))' "$work/one.json" && pass ||
    fail "one process's --stats has a processes entry"

# Open MPI on one node: vrmlray names the ob1 point-to-point layer before MPI_Init, so that Open MPI
# opens no other (opening cm probes the network devices: 0.2 s of a 0.25 s start-up on the test
# machine), unless the user named one: --mca pml, or OMPI_MCA_pml, which then wins. Open MPI's own
# verbose log of the layer's components says which were opened.
pml_log() { grep -c "components_open: found loaded component $1" "$work/err.txt" || true; }
expect 0 "one node: ob1 only" -- "${mpi[@]}" --mca pml_base_verbose 10 "$bin" render "$good" \
    -W 20 -H 20 -q -o "$work/pml.png"
[ "$(pml_log ob1)" = 3 ] && [ "$(pml_log cm)" = 0 ] && pass ||
    fail "one node: Open MPI opened PMLs other than ob1 (ob1 $(pml_log ob1), cm $(pml_log cm) of 3 processes)"
expect 0 "one node: the user's PML list wins" -- env OMPI_MCA_pml=ob1,cm "${mpi[@]}" --mca pml_base_verbose 10 \
    "$bin" render "$good" -W 20 -H 20 -q -o "$work/pml.png"
[ "$(pml_log cm)" = 3 ] && pass || fail "one node: OMPI_MCA_pml=ob1,cm was not what Open MPI opened"

# A process that cannot read its scene (MPMD: rank 0 gets a missing file, or ranks 1-2 do): every
# process exits 3, within the time limit (no process left waiting for the others).
missing=$work/no_such_scene.wrl
expect 3 "rank 0 cannot read" -- timeout 60 mpirun --oversubscribe --allow-run-as-root \
    -np 1 "$bin" render "$missing" -q -o "$work/f1.png" : -np 2 "$bin" render "$good" -q -o "$work/f1.png"
expect_stderr "no_such_scene" "rank 0 cannot read: its message"
expect 3 "ranks 1 and 2 cannot read" -- timeout 60 mpirun --oversubscribe --allow-run-as-root \
    -np 1 "$bin" render "$good" -o "$work/f2.png" : -np 2 "$bin" render "$missing" -q -o "$work/f2.png"
expect_stderr "another process failed while reading the scene" "ranks 1-2 cannot read: rank 0 says so"
[ ! -e "$work/f2.png" ] && pass || fail "a failed many-process render wrote an image"
# An output rank 0 cannot write: exit 4 everywhere, before anything is read.
expect 4 "unwritable output" -- timeout 60 "${mpi[@]}" "$bin" render "$good" -q -o "$work/no/such/folder.png"

# --frames: whole frames go round-robin to the processes (frame k to rank k % 3), which send them
# to rank 0, which writes them all (docs/mpi.md: process 0 writes); the files are the same bytes as one
# process's, and --stats says who rendered which.
# frames NAME N ARGS...: one process on 2 threads and three on one thread each render N frames.
frames() {
    local name=$1 n=$2 k same=0
    shift 2
    expect 0 "$name: one process" -- "$bin" render "$@" -q --frames "$n" --threads 2 -o "$work/${name}1_%02d.png"
    expect 0 "$name: three processes" -- timeout 300 "${mpi[@]}" "$bin" render "$@" -q --frames "$n" \
        --threads 1 -o "$work/${name}3_%02d.png" --stats "$work/$name.json"
    for ((k = 0; k < n; k++)); do
        cmp -s "$(printf '%s/%s1_%02d.png' "$work" "$name" $k)" "$(printf '%s/%s3_%02d.png' "$work" "$name" $k)" && same=$((same + 1))
    done
    [ "$same" -eq "$n" ] && pass || fail "$name: $same of $n frames of three processes the same bytes as one's"
    python3 - "$work/$name.json" "$n" <<'PY' && pass || fail "$name: --stats processes do not name each one's frames"
import json, sys
j, n = json.load(open(sys.argv[1])), int(sys.argv[2])
p = j["processes"]
assert [q["rank"] for q in p] == [0, 1, 2], p
assert [q["frames"] for q in p] == [list(range(r, n, 3)) for r in range(3)], p
assert all(q["rays"] > 0 and q["tiles"] > 0 for q in p), p
assert j["frame"] == max(range(0, n, 3)), j["frame"]  # rank 0's last frame is the one described
PY
}
frames seed_orbit 5 "$seeds/001_sphere.wrl" -W 40 -H 30 --orbit 90  # 5 frames: two ranks get 2, one 1
# Rank 0 in one folder, ranks 1 and 2 in another, a relative -o: every frame lands in rank 0's folder
# (a cluster's nodes need not share a file system), and none in the others'.
mkdir -p "$work/wd0" "$work/wd1"
expect 0 "frames with rank 0 in its own folder" -- timeout 300 mpirun --oversubscribe --allow-run-as-root \
    -np 1 --wdir "$work/wd0" "$bin" render "$seeds/001_sphere.wrl" -W 40 -H 30 -q --threads 1 --frames 5 \
    --orbit 90 -o f_%02d.png : -np 2 --wdir "$work/wd1" "$bin" render "$seeds/001_sphere.wrl" -W 40 -H 30 -q \
    --threads 1 --frames 5 --orbit 90 -o f_%02d.png
same=0
for ((k = 0; k < 5; k++)); do
    cmp -s "$(printf '%s/wd0/f_%02d.png' "$work" $k)" "$(printf '%s/seed_orbit1_%02d.png' "$work" $k)" && same=$((same + 1))
done
[ "$same" -eq 5 ] && [ -z "$(ls -A "$work/wd1")" ] && pass ||
    fail "rank 0 writes every frame ($same of 5 in its folder, the others' folder holds: $(ls "$work/wd1" | tr '\n' ' '))"
if [ -d "$corpus" ]; then
    frames orbit 12 "$corpus/molecular/pymol/pept_spheres.wrl" -W 64 -H 48 --orbit 360
    prim=$corpus/x3dv/castle-engine-demo-models/shadow_maps/primitives.x3dv
    frames prim 12 "$prim" -W 48 -H 36 --fps 4  # animated: each rank evaluates its own frames' times
    same=0
    for ((k = 0; k < 12; k++)); do
        "$bin" render "$prim" -W 48 -H 36 -q --time "$(python3 -c "print($k / 4)")" -o "$work/prim_alone.png" &&
            cmp -s "$work/prim_alone.png" "$(printf '%s/prim3_%02d.png' "$work" $k)" && same=$((same + 1))
    done
    [ "$same" -eq 12 ] && pass || fail "primitives: $same of 12 frames of three processes equal single --time renders"
fi
# A frame that cannot be written (frame 4, rank 1's, is a folder): rank 0 fails to write it, every
# process exits 4, none hangs, and the message names the frame.
mkdir -p "$work/bad_04.png"
expect 4 "a frame another process cannot write" -- timeout 120 "${mpi[@]}" "$bin" render "$seeds/001_sphere.wrl" \
    -W 32 -H 24 -q --threads 1 --frames 6 --orbit 60 -o "$work/bad_%02d.png"
expect_stderr "bad_04\.png" "the message names the frame not written"

echo "mpi tests: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
