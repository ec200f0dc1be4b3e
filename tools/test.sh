#!/usr/bin/env bash
# Installs the packages vrmlray needs (if missing), configures, builds and runs every test with CTest.
# VRMLRAY_BUILD picks the build folder (default build/); VRMLRAY_CMAKE_ARGS adds configure options.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/tools/setup.sh"
build=${VRMLRAY_BUILD:-$root/build}
# shellcheck disable=SC2086
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release ${VRMLRAY_CMAKE_ARGS:-} >/dev/null
cmake --build "$build" -j"$(nproc)"
cd "$build"
ctest --output-on-failure -j"$(nproc)" "$@"
