#!/usr/bin/env bash
# How reading and rendering grow with the size of a molecular export (issue 16): for each size, a
# PyMOL-style file (Transform + Shape + Appearance + Material + Sphere per atom, no bonds) rendered
# at 1920x1080 with --stats. Prints per size the whole process's time and peak memory (/usr/bin/time
# -v), the seconds of each phase, the peak memory per atom after reading, after the scene build and
# at the end, and the ratio of the whole process to ../shared/bench/wrl_scan.cpp (tokenizing and
# converting every number, the floor of any reader) measured in the same run, alternating with
# vrmlray. Medians of RUNS runs. Files live in a temporary folder that is deleted at the end. They
# come from tools/gen_molecule.cpp (compiled here with g++ -O2; tools/gen_molecule.py's layout, and
# that script is used when g++ fails), which writes at the disk's pace where the Python script
# spends ~35 us an atom (an hour for 100M atoms).
# Usage: bench/scale.sh [--big] [--huge] [--runs N] [--sizes "100000 300000"] [--bin VRMLRAY]... [--csv FILE]
#   --big adds 10M atoms (a 3 GB file; ~5 GB of free disk space needed).
#   --huge adds 100M atoms (a 29 GB file, ~6-8 min to write; ~32 GB of free disk space and some 14 GB
#   of memory needed). A file over 4 GiB is read with --limit file-bytes, nodes, primitives and
#   group-visits raised to fit it; wrl_scan reads the whole file into memory, so where that fails
#   (29 GB on a 24 GB machine) its time is left out (nan).
#   --bin given twice or more: each binary runs on the same files, alternating, one table each
#   (e.g. a build of the previous commit against this one); --csv holds the last binary's table.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bins=()
runs=3
sizes="100000 300000 1000000 3000000"
csv=""
while [ $# -gt 0 ]; do
    case $1 in
        --big) sizes="$sizes 10000000" ;;
        --huge) sizes="$sizes 100000000" ;;
        --runs) runs=$2; shift ;;
        --sizes) sizes=$2; shift ;;
        --bin) bins+=("$2"); shift ;;
        --csv) csv=$2; shift ;;
        *) echo "usage: bench/scale.sh [--big] [--huge] [--runs N] [--sizes LIST] [--bin VRMLRAY] [--csv FILE]" >&2
           exit 2 ;;
    esac
    shift
done
[ ${#bins[@]} -gt 0 ] || bins=("$root/build/vrmlray")
work=$(mktemp -d "${TMPDIR:-/tmp}/vrmlray_scale.XXXXXX")
trap 'rm -rf "$work"' EXIT

scan=""
scan_src=$root/../shared/bench/wrl_scan.cpp
if [ -f "$scan_src" ] && g++ -O2 -std=c++17 "$scan_src" -o "$work/wrl_scan"; then scan=$work/wrl_scan; fi

# The molecules' writer: the C++ one when it compiles, else the Python script (the same layout).
gen=(python3 "$root/tools/gen_molecule.py")
if g++ -O2 -std=c++20 "$root/tools/gen_molecule.cpp" -o "$work/gen_molecule"; then gen=("$work/gen_molecule"); fi

echo "load at start: $(cat /proc/loadavg); $(nproc) cores; $runs runs per size; $(date -u '+%F %H:%M UTC')"
rows=$work/rows.txt
: >"$rows"
for n in $sizes; do
    wrl=$work/molecule_$n.wrl
    "${gen[@]}" "$n" "$wrl" --no-bonds
    bytes=$(stat -c %s "$wrl")
    # The default limits refuse a file over 4 GiB (docs/input.md, Limits): raised to fit this one.
    limits=()
    if [ "$bytes" -gt $((4 << 30)) ]; then
        limits=(--limit "file-bytes=$bytes" --limit "nodes=$((6 * n))" --limit "primitives=$((2 * n))"
                --limit "group-visits=$((4 * n))")
    fi
    for i in $(seq "$runs"); do for b in "${!bins[@]}"; do
        bin=${bins[$b]}
        /usr/bin/time -v -o "$work/time.txt" "$bin" render "$wrl" -W 1920 -H 1080 -q \
            -o "$work/out.png" --stats "$work/stats.json" "${limits[@]}" >/dev/null
        wall=$(awk -F': ' '/Elapsed \(wall clock\)/ {n = split($2, a, ":"); s = 0
                                                      for (i = 1; i <= n; ++i) s = s * 60 + a[i]
                                                      print s}' "$work/time.txt")
        rss=$(awk -F': ' '/Maximum resident set size/ {print $2}' "$work/time.txt")
        scan_s=0
        if [ -n "$scan" ]; then
            scan_s=$("$scan" "$wrl" | grep -o 'total_s=[0-9.]*' | cut -d= -f2) || scan_s=nan
        fi
        python3 - "$work/stats.json" "$b" "$n" "$bytes" "$wall" "$rss" "$scan_s" >>"$rows" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))
t = s["seconds"]
print(*sys.argv[2:8], t["parse"], t["scene"], t["build"], t["render"], t["write"],
      s.get("peak_memory_mb_after_parse", "nan"), s.get("peak_memory_mb_after_scene", "nan"),
      s["peak_memory_mb"])
EOF
    done; done
    rm -f "$wrl"
done

for b in "${!bins[@]}"; do
[ ${#bins[@]} -eq 1 ] || echo "${bins[$b]}:"
python3 - "$rows" "$([ "$b" -eq $((${#bins[@]} - 1)) ] && echo "$csv")" "$b" <<'EOF'
import statistics, sys
cols = ["bin", "atoms", "bytes", "wall", "rss_kb", "scan", "parse", "scene", "build", "render", "write",
        "mb_parse", "mb_scene", "mb_end"]
by = {}
for line in open(sys.argv[1]):
    v = dict(zip(cols, map(float, line.split())))
    if int(v["bin"]) != int(sys.argv[3]):
        continue
    by.setdefault(int(v["atoms"]), []).append(v)
med = {n: {c: statistics.median(r[c] for r in rs) for c in cols} for n, rs in by.items()}
print(f"{'atoms':>9} {'MB':>7} {'total s':>8} {'peak MB':>8} {'B/atom':>7} {'parse':>6} {'scene':>6}"
      f" {'bvh':>6} {'render':>6} {'write':>6} {'B/atom parse':>12} {'scene':>6} {'MB/s read':>9}"
      f" {'wrl_scan s':>10} {'ratio':>6}")
out = []
for n in sorted(med):
    m = med[n]
    per = lambda mb: mb * 1048576 / n
    ratio = m["wall"] / m["scan"] if m["scan"] > 0 else float("nan")
    row = [n, m["bytes"] / 1e6, m["wall"], m["rss_kb"] / 1024, m["rss_kb"] * 1024 / n, m["parse"],
           m["scene"], m["build"], m["render"], m["write"], per(m["mb_parse"]), per(m["mb_scene"]),
           m["bytes"] / 1e6 / m["parse"], m["scan"], ratio]
    out.append(row)
    print(f"{n:>9} {row[1]:>7.1f} {row[2]:>8.2f} {row[3]:>8.0f} {row[4]:>7.0f} {row[5]:>6.2f}"
          f" {row[6]:>6.2f} {row[7]:>6.2f} {row[8]:>6.2f} {row[9]:>6.2f} {row[10]:>12.0f}"
          f" {row[11]:>6.0f} {row[12]:>9.0f} {row[13]:>10.2f} {row[14]:>6.2f}")
if sys.argv[2]:
    with open(sys.argv[2], "w") as f:
        f.write("atoms,file_mb,total_s,peak_mb,bytes_per_atom,parse_s,scene_s,bvh_s,render_s,write_s,"
                "bytes_per_atom_parse,bytes_per_atom_scene,read_mb_s,wrl_scan_s,ratio\n")
        for r in out:
            f.write(",".join(f"{x:.6g}" for x in r) + "\n")
EOF
done
