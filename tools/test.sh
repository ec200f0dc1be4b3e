#!/usr/bin/env bash
# Installs the packages vrmlray needs (if missing), configures, builds and runs every test with CTest, then
# says in one line what ran and what was skipped, and why.
# VRMLRAY_BUILD picks the build folder (default build/); VRMLRAY_CMAKE_ARGS adds configure options;
# VRMLRAY_CORPUS=DIR points the corpus tests at a folder of real files (default ../shared/corpus, when it exists);
# VRMLRAY_CONFORMANCE=DIR the conformance test at the Xj3D and Titania suites (default ../shared/conformance).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/tools/setup.sh"
build=${VRMLRAY_BUILD:-$root/build}
case "$build" in /*) ;; *) build=$root/$build ;; esac  # the summary reads $build/ctest-last.log after cd
# shellcheck disable=SC2086
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release ${VRMLRAY_CMAKE_ARGS:-} >/dev/null
cmake --build "$build" -j"$(nproc)"
cd "$build"
log=$build/ctest-last.log
status=0
ctest --output-on-failure -j"$(nproc)" "$@" 2>&1 | tee "$log" || status=$?

# The summary: counts from CTest's own lines, and the reason for the skips.
total=$(grep -Eo 'tests failed out of [0-9]+' "$log" | grep -Eo '[0-9]+$' || echo 0)
failed=$(grep -Eo '[0-9]+ tests failed out of' "$log" | grep -Eo '^[0-9]+' || echo 0)
skipped=$(grep -Ec '^[[:space:]]*[0-9]+ - .*\(Skipped\)$' "$log" || true)
passed=$((total - failed - skipped))
corpus=${VRMLRAY_CORPUS:-$(cd "$root/.." && pwd)/shared/corpus}
why=""
if [ "$skipped" -gt 0 ]; then
    if [ "$corpus" = none ]; then why=" (VRMLRAY_CORPUS=none: the corpus tests were skipped)"
    elif [ ! -d "$corpus" ]; then why=" (no corpus of real files at $corpus: its tests were skipped; set VRMLRAY_CORPUS=DIR)"
    else why=" (see 'The following tests did not run' above)"; fi
    # The conformance suites are looked for on their own (tools/conformance.py): say so when they were not found.
    conformance=${VRMLRAY_CONFORMANCE:-$(cd "$root/.." && pwd)/shared/conformance}
    if [ "$conformance" = none ] || [ ! -d "$conformance" ]; then
        why="$why (no conformance suites at $conformance: the 'conformance' test was skipped; set VRMLRAY_CONFORMANCE=DIR)"
    fi
fi
echo "tests: $passed passed, $failed failed, $skipped skipped$why"
exit "$status"
