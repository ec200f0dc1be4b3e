#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (AddressSanitizer + UndefinedBehaviorSanitizer) and runs each for
# the given number of seconds (default 60) on all cores, seeded from ../shared/corpus and tests/corpus.
# Crashing inputs land in build-fuzz/crashes/TARGET/; copy each into tests/corpus/fuzz/ as a regression test.
# Usage: tools/fuzz/run.sh [SECONDS] [TARGET...]
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
seconds=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(fuzz_classic fuzz_x3d_xml fuzz_pipeline)
"$root/tools/setup.sh"
command -v clang++ >/dev/null || { sudo=""; [ "$(id -u)" -eq 0 ] || sudo=sudo; $sudo apt-get install -y -qq clang >&2; }
build=$root/build-fuzz
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
      -DVRMLRAY_FUZZ=ON -DVRMLRAY_TESTS=OFF -DVRMLRAY_NATIVE=OFF >/dev/null
cmake --build "$build" -j"$(nproc)" --target "${targets[@]}"
for t in "${targets[@]}"; do
    corpus=$build/corpus/$t
    mkdir -p "$corpus" "$build/crashes/$t"
    seeds=()
    case $t in
        fuzz_x3d_xml) seeds=("$root/../shared/corpus/x3d") ;;
        *) seeds=("$root/../shared/corpus/vrml97" "$root/../shared/corpus/x3dv" "$root/tests/corpus") ;;
    esac
    echo "== $t: ${seconds}s" >&2
    "$build/$t" "$corpus" "${seeds[@]}" -dict="$root/tools/fuzz/vrml.dict" -max_total_time="$seconds" \
        -max_len=65536 -timeout=20 -rss_limit_mb=4096 -artifact_prefix="$build/crashes/$t/" \
        -print_final_stats=1 2>&1 | tail -15
done
