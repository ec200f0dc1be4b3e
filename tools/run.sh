#!/usr/bin/env bash
# Runs vrmlray with the given arguments, first installing missing packages and building it if needed.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/tools/setup.sh"
build=${VRMLRAY_BUILD:-$root/build}
if [ ! -f "$build/CMakeCache.txt" ]; then
    cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
cmake --build "$build" -j"$(nproc)" --target vrmlray >&2
exec "$build/vrmlray" "$@"
