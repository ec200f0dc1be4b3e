#!/usr/bin/env bash
# tools/gen_molecule.cpp (the fast generator of bench/scale.sh) against tools/gen_molecule.py, whose
# PyMOL layout it must write: the same text once the numbers are masked, a self-avoiding walk of
# 1.5 A steps in the ball, the element mix, and vrmlray reading one sphere an atom.
# Usage: run_gen_molecule_tests.sh VRMLRAY_BINARY SOURCE_DIR WORK_DIR GEN_MOLECULE_BINARY
# shellcheck source=tests/cli/common.sh
. "$(dirname "$0")/common.sh"
gen=$(realpath "$4")

# Every number masked, the two files are the same line for line but for the header's generator name:
# the element's colour and radius lines mask alike, so a different element draw does not show.
same_layout() {  # same_layout DESCRIPTION ARGS...
    local what=$1
    shift
    "$gen" 3000 "$work/cpp.wrl" "$@" && python3 "$src/tools/gen_molecule.py" 3000 "$work/py.wrl" "$@" \
        || { fail "$what: a generator failed"; return; }
    if diff <(sed -E '2d; s/-?[0-9]+\.[0-9]+/N/g' "$work/cpp.wrl") \
            <(sed -E '2d; s/-?[0-9]+\.[0-9]+/N/g' "$work/py.wrl") >"$work/diff.txt"; then
        pass
    else
        fail "$what: the layouts differ"; head -5 "$work/diff.txt" | sed 's/^/    /'
    fi
    [ "$(sed -n 2p "$work/cpp.wrl" | sed 's/gen_molecule.cpp/gen_molecule.py/')" = "$(sed -n 2p "$work/py.wrl")" ] \
        && pass || fail "$what: header line 2 differs beyond the generator's name"
}
same_layout "atoms only" --no-bonds
same_layout "atoms and bonds"
same_layout "another seed" --no-bonds --seed 7

# The walk and the mix, on 20,000 atoms.
"$gen" 20000 "$work/walk.wrl" --no-bonds --seed 3 || fail "20,000 atoms: exit $?"
python3 - "$work/walk.wrl" 20000 <<'PY' && pass || fail "walk or element mix (above)"
import math, sys
path, n = sys.argv[1], int(sys.argv[2])
pts, radii = [], []
for line in open(path):
    if line.startswith(" translation "):
        pts.append(tuple(map(float, line.split()[1:])))
    elif "Sphere { radius" in line:
        radii.append(line.split()[4])
assert len(pts) == n and len(radii) == n, (len(pts), len(radii))
ball = 1.6 * n ** (1 / 3) + 5
# Each coordinate is rounded to 0.00005 at most, so a printed distance is off by sqrt(3) * 1e-4 at most.
steps = [math.dist(a, b) for a, b in zip([(0.0, 0.0, 0.0)] + pts, pts)]
assert all(abs(s - 1.5) < 2e-4 for s in steps), max(abs(s - 1.5) for s in steps)
assert all(math.hypot(*p) < ball + 1e-4 for p in pts), max(math.hypot(*p) for p in pts)
# The H/C/N/O/S fractions by radius; 0.015 is more than 5 standard deviations of a fraction of 20,000.
want = {"0.30": 0.20, "0.60": 0.45, "0.58": 0.14, "0.55": 0.18, "0.90": 0.03}
for r, f in want.items():
    got = radii.count(r) / n
    assert abs(got - f) < 0.015, (r, got, f)
# Not a straight line nor a cluster: the chain fills a good part of its ball.
assert max(math.hypot(*p) for p in pts) > ball / 2
PY
cmp -s <("$gen" 500 /dev/stdout --seed 3) "$work/walk.wrl" && fail "a different size gave the same file" || pass
"$gen" 500 "$work/a.wrl" --seed 3 && "$gen" 500 "$work/b.wrl" --seed 3 && cmp -s "$work/a.wrl" "$work/b.wrl" \
    && pass || fail "the same seed must give the same file"

# vrmlray reads one sphere an atom (and a cylinder a bond).
"$bin" info "$work/walk.wrl" >"$work/info.txt" 2>&1 && grep -Eq '^tracer +20000 spheres' "$work/info.txt" \
    && pass || { fail "vrmlray info: not 20000 spheres"; head -20 "$work/info.txt" | sed 's/^/    /'; }
expect 2 "no size" -- "$gen"
expect 2 "unknown option" -- "$gen" 10 "$work/x.wrl" --vmd
expect 1 "unwritable output" -- "$gen" 10 "$work/no/such/folder/x.wrl"

echo "gen_molecule tests: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
