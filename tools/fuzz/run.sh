#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (AddressSanitizer + UndefinedBehaviorSanitizer) and runs each for
# the given number of seconds (default 60) in one worker process, seeded from ../shared/corpus and
# tests/corpus. A crash, timeout (60 s) or out-of-memory (4 GB) does not end the run: each input lands in
# build-fuzz/crashes/TARGET/ and fuzzing goes on (fork mode). Copy each into tests/corpus/bad/ with its
# expected message as a regression test.
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
        -max_len=65536 -timeout=60 -rss_limit_mb=4096 -artifact_prefix="$build/crashes/$t/" \
        -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 2>&1 | grep -E '^#[0-9]+: |INFO: (fuzzed|exiting)|crash|timeout|oom' | tail -6 || true
    echo "== $t: findings: $(ls "$build/crashes/$t" | wc -l)" >&2
done
