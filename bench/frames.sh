#!/usr/bin/env bash
# Frames of a sequence shared out among threads (issue 19, item 2): a 36-frame turntable of a real
# protein at 320x240 on 2 threads, rendered
#   frames: two frames at once, one thread each (--frames-at-once 2)
#   tiles:  one frame after another, each frame's tiles over both threads (--frames-at-once 1)
#   one:    one thread (--threads 1), the base of the speed-up
# Whole process = wall time of the command, median of RUNS runs, the configurations alternating
# run by run; seconds per frame = that / 36. The script checks that all three wrote the same bytes.
#
# Usage: bench/frames.sh [VRMLRAY_BINARY] [RUNS] [SCENE]   (RUNS default 5; SCENE default the
# corpus's PyMOL export of interleukin-2 as spheres)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:-$root/build/vrmlray}
runs=${2:-5}
scene=${3:-$root/../shared/corpus/molecular/pymol/il2_spheres.wrl}
frames=36
work=${TMPDIR:-/tmp}/vrmlray_frames_bench
rm -rf "$work"
mkdir -p "$work"
configs=(frames tiles one)
args_of() {
    case $1 in
        frames) echo "--threads 2 --frames-at-once 2" ;;
        tiles) echo "--threads 2 --frames-at-once 1" ;;
        one) echo "--threads 1" ;;
    esac
}
median() { sort -g | awk '{a[NR]=$1} END {print (NR ? a[int((NR+1)/2)] : "-")}'; }

echo "load at start: $(cat /proc/loadavg) ($(nproc) cores; other jobs may share this machine)"
echo "scene: $scene, $frames frames, --orbit 360, 320x240"
for ((r = 1; r <= runs; r++)); do
    for c in "${configs[@]}"; do
        mkdir -p "$work/$c"
        start=$(date +%s.%N)
        # shellcheck disable=SC2046
        "$bin" render "$scene" -W 320 -H 240 -q --frames $frames --orbit 360 $(args_of "$c") \
            -o "$work/$c/f_%02d.png"
        end=$(date +%s.%N)
        echo "$end - $start" | bc -l >>"$work/$c.times"
    done
done
for c in frames tiles; do
    for f in "$work/one"/*.png; do
        cmp -s "$f" "$work/$c/$(basename "$f")" || { echo "FAIL: $c wrote other bytes than one ($f)"; exit 1; }
    done
done
echo "every configuration wrote the same bytes ($frames frames each)"
base=$(median <"$work/one.times")
printf '%-7s | %8s | %11s | %s\n' config "wall s" "s per frame" "speed-up vs one"
for c in "${configs[@]}"; do
    m=$(median <"$work/$c.times")
    printf '%-7s | %8.3f | %11.4f | %.2f\n' "$c" "$m" "$(echo "$m / $frames" | bc -l)" "$(echo "$base / $m" | bc -l)"
done
echo "load at end: $(cat /proc/loadavg)"
