#!/usr/bin/env bash
# Many processes (SPEC section 14): `mpirun -np 3 vrmlray render` writes the same bytes as one
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

# A process that cannot read its scene (MPMD: rank 0 gets a missing file, or ranks 1-2 do): every
# process exits 3, within the time limit (no process left waiting for the others).
good=$seeds/001_sphere.wrl
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

echo "mpi tests: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
