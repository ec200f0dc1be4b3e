#!/usr/bin/env bash
# Processes that split the reading (docs/mpi.md "Split reading"): under `mpirun -np N` each process
# builds only its share of a large file's pieces and the processes exchange what they built; the
# image must stay the same bytes as one process's, --stats must show that each process built its
# share and received the rest, files whose pieces are not plain must still render the same, and a
# process that cannot read the file must make all exit 3 without a hang.
# Usage: run_mpi_split_tests.sh VRMLRAY_BINARY SOURCE_DIR WORK_DIR MPI(ON|OFF). Exit 77 (skipped)
# when the binary is built without MPI or mpirun is missing.
# shellcheck source=tests/cli/common.sh
. "$(dirname "$0")/common.sh"
if [ "${4:-OFF}" != ON ]; then echo "SKIPPED: vrmlray is built without MPI (VRMLRAY_MPI=OFF)"; exit 77; fi
command -v mpirun >/dev/null || { echo "SKIPPED: no mpirun on PATH"; exit 77; }
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"  # Open MPI's start-up (run_mpi_tests.sh)
# Pieces of 64 kB: a test-sized file is cut into dozens of pieces as a large one is into 16 MB ones.
export VRMLRAY_PIECE_BYTES=65536
mpi=(timeout 300 mpirun --oversubscribe --allow-run-as-root -x VRMLRAY_PIECE_BYTES)

mol=$work/mol.wrl
python3 "$src/tools/gen_molecule.py" 4000 "$mol" >/dev/null  # atoms and bonds: spheres, cylinders
vmd=$work/vmd.wrl
python3 "$src/tools/gen_molecule.py" 1500 "$vmd" --vmd >/dev/null  # PROTOs first: nothing is plain

# split NAME N FILE ARGS...: one process on 2 threads, then N processes on one thread each; the
# same bytes.
split() {
    local name=$1 n=$2 file=$3
    shift 3
    expect 0 "$name: one process" -- "$bin" render "$file" "$@" -q --threads 2 -o "$work/$name.1.png"
    expect 0 "$name: $n processes" -- "${mpi[@]}" -np "$n" "$bin" render "$file" "$@" -q --threads 1 \
        -o "$work/$name.$n.png" --stats "$work/$name.$n.json"
    if cmp -s "$work/$name.1.png" "$work/$name.$n.png"; then pass; else
        fail "$name: $n processes wrote other bytes than one"; fi
}

# reading JSON N SHARED: --stats processes[].reading; SHARED 1: every piece was built by exactly
# one process, in the deal r, r + N, ..., and every process received all the others built.
reading() {
    python3 - "$@" <<'PY'
import json, sys
j, n, shared = json.load(open(sys.argv[1])), int(sys.argv[2]), sys.argv[3] == "1"
p = [q["reading"] for q in j["processes"]]
assert len(p) == n, p
pieces = p[0]["pieces"]
assert all(q["pieces"] == pieces for q in p), p
if shared:
    assert pieces >= 2 * n, p  # 64 kB pieces of a file of some megabytes
    for r, q in enumerate(p):
        assert q["built"] == len(range(r, pieces, n)), (r, q)  # its own share, every one plain
        assert q["received"] == pieces - q["built"], (r, q)
        assert q["bytes_sent"] > 0, (r, q)
else:
    assert all(q["built"] == 0 and q["received"] == 0 for q in p), p
PY
}

split molecule 2 "$mol" -W 160 -H 120
reading "$work/molecule.2.json" 2 1 && pass || fail "molecule, 2 processes: --stats reading is not the deal"
split molecule 3 "$mol" -W 160 -H 120
reading "$work/molecule.3.json" 3 1 && pass || fail "molecule, 3 processes: --stats reading is not the deal"
split molecule 4 "$mol" -W 160 -H 120
reading "$work/molecule.4.json" 4 1 && pass || fail "molecule, 4 processes: --stats reading is not the deal"
# Two threads a process: a piece a thread at a time between the exchanges.
expect 0 "molecule: 2 processes of 2 threads" -- "${mpi[@]}" -np 2 "$bin" render "$mol" -W 160 -H 120 -q \
    --threads 2 -o "$work/molecule.2x2.png"
if cmp -s "$work/molecule.1.png" "$work/molecule.2x2.png"; then pass; else
    fail "molecule: 2 processes of 2 threads wrote other bytes than one"; fi
# Appearances DEF'd in the head and USEd in the pieces, each stretch of the file another: each
# process interns the names its own pieces USE first, so the processes number them differently
# and every received origin is renumbered (src/app/fragment_wire.h).
uses=$work/uses.wrl
python3 - "$uses" <<'PY'
import random, sys
rng, n, kinds = random.Random(5), 6000, 24
with open(sys.argv[1], "w") as f:
    f.write("#VRML V2.0 utf8\nViewpoint { position 50 50 260 }\n")
    for k in range(kinds):
        f.write("DEF MAT_%d Appearance { material Material { diffuseColor %.2f %.2f %.2f } }\n"
                % (k, rng.random(), rng.random(), rng.random()))
    for i in range(n):
        f.write("Transform { translation %.3f %.3f %.3f children Shape { appearance USE MAT_%d "
                "geometry Sphere { radius %.2f } } }\n" % (rng.uniform(0, 100), rng.uniform(0, 100),
                rng.uniform(0, 100), (n - 1 - i) * kinds // n, rng.uniform(0.5, 2.0)))
PY
split uses 3 "$uses" -W 160 -H 120
reading "$work/uses.3.json" 3 1 && pass || fail "USE names, 3 processes: --stats reading is not the deal"
# Gas: the same fragments, another integrator.
split molecule_gas 2 "$mol" -W 120 -H 90 --spheres gas --density 0.05
# PROTOs before the pieces: the reader uses none of them, every process reads the file whole.
split vmd 2 "$vmd" -W 120 -H 90

# One process cannot read the file while the others have begun on its pieces (MPMD: rank 0 gets a
# missing file): every process exits 3, none waits for the others.
expect 3 "rank 0 cannot read, the others split the molecule" -- timeout 60 mpirun --oversubscribe \
    --allow-run-as-root -x VRMLRAY_PIECE_BYTES -np 1 "$bin" render "$work/no_such.wrl" -q -o "$work/f.png" \
    : -np 2 "$bin" render "$mol" -q -o "$work/f.png" --threads 1
expect 3 "rank 1 cannot read, the others split the molecule" -- timeout 60 mpirun --oversubscribe \
    --allow-run-as-root -x VRMLRAY_PIECE_BYTES -np 1 "$bin" render "$mol" -o "$work/g.png" --threads 1 \
    : -np 1 "$bin" render "$work/no_such.wrl" -q -o "$work/g.png" : -np 1 "$bin" render "$mol" -q \
    -o "$work/g.png" --threads 1
expect_stderr "another process failed while reading the scene" "rank 1 cannot read: rank 0 says so"
# A syntax error in the middle of the file: every process reports it, as one process does.
python3 - "$mol" "$work/broken.wrl" <<'PY'
import sys
text = open(sys.argv[1]).read()
at = text.index("\nTransform", len(text) // 2)
open(sys.argv[2], "w").write(text[:at] + "\nTransform { translation 1 2 } }" + text[at:])
PY
expect 3 "a syntax error in a shared piece" -- "${mpi[@]}" -np 2 "$bin" render "$work/broken.wrl" -q \
    -o "$work/b.png" --threads 1
expect_stderr "broken\.wrl:[0-9]+:[0-9]+: error" "a syntax error in a shared piece: its place"

echo "mpi split tests: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
