#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (AddressSanitizer + UndefinedBehaviorSanitizer) and runs each for
# the given number of seconds (default 60), seeded from tools/fuzz/corpus/TARGET (inputs earlier runs
# found, kept in the repository), tests/corpus and ../shared/corpus when present. The first crash, hang
# (an input taking over 60 s) or out-of-memory (4 GB) of a target stops it and fails the script (exit 1):
# the input stays in build-fuzz/crashes/TARGET/ (named after its kind and hash; the path is printed).
# Copy it into tests/corpus/bad/ with its expected message as a regression test, then fix the bug.
# CI runs 60 s a target (.ci/run); long runs are manual: tools/fuzz/run.sh 3600.
#   tools/fuzz/run.sh [SECONDS] [TARGET...]   (VRMLRAY_FUZZ_CMAKE_ARGS adds configure options)
#   tools/fuzz/run.sh --merge TARGET...   fold build-fuzz/corpus/TARGET into tools/fuzz/corpus/TARGET,
#                                         keeping the inputs that add coverage (up to 1 kB)
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
merge=0
[ "${1:-}" = --merge ] && { merge=1; shift; }
seconds=60
if [ $merge -eq 0 ] && [ $# -gt 0 ]; then seconds=$1; shift; fi
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(fuzz_classic fuzz_x3d_xml fuzz_pipeline)
# Debian 12: clang 14 and its runtime libraries (libFuzzer, the sanitizers).
"$root/tools/setup.sh" clang libclang-rt-14-dev
build=$root/build-fuzz
# shellcheck disable=SC2086  # VRMLRAY_FUZZ_CMAKE_ARGS: more configure options, split on spaces
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
      -DVRMLRAY_FUZZ=ON -DVRMLRAY_TESTS=OFF -DVRMLRAY_NATIVE=OFF ${VRMLRAY_FUZZ_CMAKE_ARGS:-} >/dev/null
cmake --build "$build" -j"$(nproc)" --target "${targets[@]}"

seeds_of() {  # the seed folders of target $1 that exist
    local t=$1 s=()
    s+=("$root/tools/fuzz/corpus/$t")
    case $t in
        fuzz_x3d_xml) s+=("$root/../shared/corpus/x3d") ;;
        *) s+=("$root/tests/corpus" "$root/../shared/corpus/vrml97" "$root/../shared/corpus/x3dv") ;;
    esac
    for d in "${s[@]}"; do [ -d "$d" ] && echo "$d"; done
}

if [ $merge -eq 1 ]; then
    for t in "${targets[@]}"; do
        keep=$root/tools/fuzz/corpus/$t
        mkdir -p "$keep"
        "$build/$t" -merge=1 -max_len=1024 "$keep" "$build/corpus/$t" 2>&1 | grep -E 'MERGE-OUTER: [0-9]+ new files' || true
        echo "== $t: $(find "$keep" -type f | wc -l) inputs kept in tools/fuzz/corpus/$t" >&2
    done
    exit 0
fi

failed=()
for t in "${targets[@]}"; do
    corpus=$build/corpus/$t
    crashes=$build/crashes/$t
    mkdir -p "$corpus" "$crashes"
    mapfile -t seeds < <(seeds_of "$t")
    echo "== $t: ${seconds}s from ${seeds[*]}" >&2
    log=$build/$t.log
    status=0
    "$build/$t" "$corpus" "${seeds[@]}" -dict="$root/tools/fuzz/vrml.dict" -max_total_time="$seconds" \
        -max_len=65536 -timeout=60 -rss_limit_mb=4096 -artifact_prefix="$crashes/" -print_final_stats=1 \
        >"$log" 2>&1 || status=$?
    grep -E '^#[0-9]+: |INFO: (fuzzed|exiting)|stat::number_of_executed_units' "$log" | tail -3 >&2 || true
    if [ $status -ne 0 ]; then
        # The sanitizer's or libFuzzer's report, and where the input was written.
        grep -E 'ERROR: |SUMMARY: |Test unit written to|==[0-9]+==' "$log" | head -20 >&2 || true
        echo "== $t: FAILED (exit $status); input kept in $crashes/, full log $log" >&2
        failed+=("$t")
    else
        echo "== $t: no crash, hang or out-of-memory in ${seconds}s" >&2
    fi
done
[ ${#failed[@]} -eq 0 ] || { echo "fuzz: failed: ${failed[*]}" >&2; exit 1; }
