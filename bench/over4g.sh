#!/usr/bin/env bash
# A file over 4 GiB read to its end, with messages at the right line and column (issue 45): a sparse
# file (no disk space for its first 4 GiB: they are a hole, zero bytes, which the lexer skips as white
# space) whose last 200 KB hold atoms, PyMOL-style, a field no Sphere has (a warning) and, in a second
# run, a value that is not a number (an error). Pieces of 64 KB (VRMLRAY_PIECE_BYTES) make the atoms
# past 4 GiB several pieces, read on other threads and joined as the main reader arrives. Checks the
# sphere count (info and render), both messages' file:line:col and the exit codes; prints the time
# of each run. Not in CI:
# the first 4 GiB are still read (10-60 s a run and 4 GiB of page cache), which the unit tests
# LargeFileOffsets.* avoid.
# Usage: bench/over4g.sh [VRMLRAY]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:-$root/build/vrmlray}
work=$(mktemp -d "${TMPDIR:-/tmp}/vrmlray_over4g.XXXXXX")
trap 'rm -rf "$work"' EXIT
f=$work/over4g.wrl
atoms=600
python3 - "$f" "$atoms" <<'EOF'
import sys
path, atoms = sys.argv[1], int(sys.argv[2])
with open(path, "wb") as out:
    out.write(b"#VRML V2.0 utf8\n")                     # line 1
    out.truncate((4 << 30) + 16)                        # a hole: zero bytes, white space to the lexer
    out.seek(0, 2)
    out.write(b"\n")                                    # ends line 2
    for k in range(atoms):
        out.write(b"Transform { translation %d 0 0 children Shape {\n" % k)
        out.write(b"  appearance Appearance { material Material { diffuseColor 1 0 0 } }\n")
        if k == atoms // 2:                             # the warning: column 21
            out.write(b"  geometry Sphere { spin 1 radius 0.5 } } }\n")
        else:
            out.write(b"  geometry Sphere { radius 0.5 } } }\n")
EOF
warn_line=$((3 + 3 * (atoms / 2) + 2))
size=$(stat -c %s "$f")
echo "file: $size bytes ($(du -k "$f" | cut -f1) KB on disk); atoms after byte $(((4 << 30) + 17))"
fail=0
check() { if grep -q -- "$1" "$work/out.txt"; then echo "ok: $2"; else echo "FAIL: $2 (no '$1')"; fail=1; fi; }
# run LABEL WANTED_EXIT COMMAND...: runs the command into out.txt, prints its exit and seconds.
run() {
    local label=$1 want=$2 s rc
    shift 2
    s=$(date +%s.%N)
    set +e
    VRMLRAY_PIECE_BYTES=65536 "$@" >"$work/out.txt" 2>&1
    rc=$?
    set -e
    echo "$label: exit $rc, $(echo "$(date +%s.%N) - $s" | bc) s"
    [ "$rc" -eq "$want" ] || { echo "FAIL: exit $rc, wanted $want"; fail=1; }
}

run "info (a warning)" 0 "$bin" info "$f" --limit file-bytes=5G
check "over4g.wrl:$warn_line:21: warning: unknown field .spin. in node Sphere" "the warning at line $warn_line, column 21"
check "Sphere  *$atoms\$" "$atoms Sphere nodes read"
check "tracer  *$atoms spheres" "$atoms spheres traced"

# The render path: plain pieces past 4 GiB go straight from tokens to the scene (scene/plain_piece.h).
run render 0 "$bin" render "$f" --limit file-bytes=5G -W 64 -H 48 -o "$work/out.png" \
    --stats "$work/stats.json"
check "over4g.wrl:$warn_line:21: warning: unknown field .spin. in node Sphere" "render: the warning at line $warn_line, column 21"
spheres=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["primitives"]["spheres"])' "$work/stats.json")
if [ "$spheres" = "$atoms" ]; then echo "ok: render: $atoms spheres"; else echo "FAIL: render: $spheres spheres"; fail=1; fi

# An error after the atoms: the statement on the line after the last atom, its bad value at column 34.
err_line=$((3 + 3 * atoms))
printf 'Shape { geometry Sphere { radius bad } }\n' >>"$f"
run "info (an error)" 3 "$bin" info "$f" --limit file-bytes=5G
check "over4g.wrl:$err_line:34: error: expected a number, found .bad." "the error at line $err_line, column 34"
[ "$fail" -eq 0 ] || { echo "--- output:"; cat "$work/out.txt"; exit 1; }
echo "all checks passed"
