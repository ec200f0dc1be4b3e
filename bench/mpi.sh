#!/usr/bin/env bash
# One image by many processes (docs/mpi.md) against one process with threads, on this machine:
# 1 rank x 2 threads, 2 ranks x 1 thread, 4 ranks x 1 thread (oversubscribed: 4 processes on the
# cores there are), plus 1 rank x 1 thread as the base of the speed-up, at 1920x1080 on
#   S2: a 10,000-atom PyMOL-style molecule with bonds (tools/gen_molecule.py 10000), opaque;
#   S3: 1,000,000 random spheres (r 0.5-2) in a 1000^3 box, --fit.
# Whole process = wall time of the command (mpirun's start-up included), median of RUNS runs, the
# configurations alternating run by run. Phases from --stats: rank 0's, and for the render the
# longest process's (seconds.render); "gather" is rank 0's wait for and copy of the others' tiles.
#
# Efficiency: e2 = T(1 rank x 2 threads) / T(2 ranks x 1 thread), the cost of processes against
# threads on the same two cores (1.0: no cost); speed-up = T(1 x 1) / T(config).
# Split reading (docs/mpi.md "Split reading"): "read max" is the slowest process's parse (each
# process builds its share of the file's pieces, then they exchange them), "pieces" and "exch" that
# process's seconds of its own pieces and of the exchange; r2 = read max(2 x 1) / parse(1 x 1), the
# per-process read time of 2 processes against one process's on one thread.
#
# Usage: bench/mpi.sh [VRMLRAY_BINARY] [RUNS]   (RUNS default 5; the binary must be built with MPI)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:-$root/build/vrmlray}
runs=${2:-5}
work=${TMPDIR:-/tmp}/vrmlray_mpi_bench
mkdir -p "$work"
"$root/tools/setup.sh" openmpi-bin time
mpi=(mpirun --oversubscribe --allow-run-as-root --bind-to none)

[ -s "$work/S2.wrl" ] || python3 "$root/tools/gen_molecule.py" 10000 "$work/S2.wrl" >/dev/null
[ -s "$work/S3.wrl" ] || python3 - "$work/S3.wrl" <<'PY'
import random, sys
rng = random.Random(3)
with open(sys.argv[1], "w") as f:
    f.write("#VRML V2.0 utf8\nDirectionalLight { direction -0.3 -0.8 -0.5 }\n")
    f.write("Background { skyColor 0.1 0.1 0.15 }\n")
    for _ in range(1000000):
        x, y, z = (rng.uniform(0, 1000) for _ in range(3))
        f.write("Transform { translation %.3f %.3f %.3f children Shape { appearance Appearance { "
                "material Material { diffuseColor 0.8 0.6 0.4 } } geometry Sphere { radius %.3f } } }\n"
                % (x, y, z, rng.uniform(0.5, 2.0)))
PY

median() { sort -g | awk '{a[NR]=$1} END {print (NR ? a[int((NR+1)/2)] : "-")}'; }
# One run of config NAME (ranks x threads) on scene S: "wall init parse scene build render gather write rss_mb
# read_max pieces exchange".
run() {
    local s=$1 ranks=$2 threads=$3 t0=$EPOCHREALTIME
    local cmd=("$bin" render "$work/$s.wrl" -W 1920 -H 1080 --threads "$threads" -q -o "$work/out_${ranks}x$threads.ppm"
        --stats "$work/stats.json")
    [ "$s" = S3 ] && cmd+=(--fit)
    [ "$ranks" -gt 1 ] && cmd=("${mpi[@]}" -np "$ranks" "${cmd[@]}")
    /usr/bin/time -f "%M" -o "$work/time.txt" "${cmd[@]}" >"$work/log" 2>&1
    local wall
    wall=$(awk -v a="$t0" -v b="$EPOCHREALTIME" 'BEGIN {printf "%.3f", b - a}')
    python3 - "$work/stats.json" "$wall" "$(cat "$work/time.txt")" <<'PY'
import json, sys
d = json.load(open(sys.argv[1])); s = d["seconds"]
procs = d.get("processes", [{"seconds": {"mpi_init": 0.0, "gather": 0.0, "parse": s["parse"]}}])
p = procs[0]["seconds"]
slow = max(procs, key=lambda q: q["seconds"]["parse"])
r = slow.get("reading", {"seconds": {"pieces": 0.0, "exchange": 0.0}})["seconds"]
print(sys.argv[2], p["mpi_init"], s["parse"], s["scene"], s["build"], s["render"], p["gather"], s["write"],
      int(sys.argv[3]) // 1024, slow["seconds"]["parse"], r["pieces"], r["exchange"])
PY
}

echo "load at start: $(cat /proc/loadavg) ($(nproc) cores; other jobs share this machine)"
configs=("1 2" "2 1" "4 1" "1 1")
for s in S2 S3; do
    declare -A rows=()
    for i in $(seq "$runs"); do
        for c in "${configs[@]}"; do
            set -- $c
            rows[$c]+="$(run "$s" "$1" "$2")"$'\n'
        done
    done
    # The images must be the same bytes whatever the configuration.
    for c in "2x1" "4x1" "1x1"; do cmp -s "$work/out_1x2.ppm" "$work/out_$c.ppm" || echo "$s: $c image differs!"; done
    echo
    echo "$s ($runs runs each, medians; load now $(cut -d' ' -f1-3 /proc/loadavg))"
    printf '%-12s | %7s | %8s | %7s | %8s | %6s | %6s | %6s | %6s | %6s | %7s | %6s | %6s | %s\n' config "wall s" \
        "mpi_init" parse "read max" pieces exch scene build render gather write "RSS MB" "speed-up vs 1x1"
    base=$(echo -n "${rows[1 1]}" | awk '{print $1}' | median)
    for c in "${configs[@]}"; do
        set -- $c
        med() { echo -n "${rows[$c]}" | awk -v k="$1" '{print $k}' | median; }
        wall=$(med 1)
        printf '%-12s | %7s | %8.3f | %7.3f | %8.3f | %6.3f | %6.3f | %6.3f | %6.3f | %6.3f | %7.3f | %6.3f | %6s | %s\n' \
            "$1 x $2" "$wall" "$(med 2)" "$(med 3)" "$(med 10)" "$(med 11)" "$(med 12)" "$(med 4)" "$(med 5)" \
            "$(med 6)" "$(med 7)" "$(med 8)" "$(med 9)" "$(awk -v a="$base" -v b="$wall" 'BEGIN {printf "%.2f", a / b}')"
        eval "wall_${1}x$2=$wall"
        eval "read_${1}x$2=$(med 10)"
    done
    awk -v a="$wall_1x2" -v b="$wall_2x1" 'BEGIN {printf "efficiency e2 = T(1x2)/T(2x1) = %.2f\n", a / b}'
    awk -v a="$read_2x1" -v b="$read_1x1" 'BEGIN {printf "read r2 = read max(2x1)/parse(1x1) = %.2f\n", a / b}'
    # e2 and r2 of each round, paired within the round (the machine is shared: a round's configs ran
    # back to back, so their ratio is less disturbed than the medians' ratio).
    paste <(echo -n "${rows[1 2]}" | awk '{print $1}') <(echo -n "${rows[2 1]}" | awk '{print $1, $10}') \
        <(echo -n "${rows[1 1]}" | awk '{print $10}') |
        awk '{e = e sprintf(" %.2f", $1 / $2); r = r sprintf(" %.2f", $3 / $4)} END {print "per round: e2" e "; r2" r}'
    unset rows
done
