#!/usr/bin/env bash
# After a failed CTest run in BUILD under LeakSanitizer: reruns alone, at most twice, each failed test whose
# only fault was LeakSanitizer's own tracer crashing at exit ("Tracer caught signal 11" ... "LeakSanitizer
# has encountered a fatal error", after the test had printed PASSED). That is a known flake of the runtime's
# stop-the-world step (google/sanitizers#1353), seen in CI at the exit of a test that loads the OpenImageIO
# module, whose libraries leave thread pools alive. It is not a leak: a leak prints "ERROR: LeakSanitizer:
# detected memory leaks" and is never retried, nor is any other failure.
# Usage: tools/retry_lsan_tracer.sh BUILD [LOG]  (LOG: the run's output, default BUILD/ctest-last.log).
# Exit 0 when every failed test was a tracer crash that passed on a rerun.
set -euo pipefail
build=$1
log=${2:-$build/ctest-last.log}
failed=$build/Testing/Temporary/LastTestsFailed.log
[ -s "$failed" ] || { echo "retry_lsan_tracer: no failed tests recorded in $failed" >&2; exit 1; }
cp "$failed" "$failed.first"  # the reruns below rewrite it

# The output CTest printed for test NUM: from its result line to the next Start or result line.
block_of() {
    awk -v n="$1" '
        $0 ~ "Test +#" n ":" { on = 1; print; next }
        on && ($0 ~ /^ *Start +[0-9]+:/ || $0 ~ /^ *[0-9]+\/[0-9]+ Test +#/ || $0 ~ /tests passed, /) { exit }
        on { print }' "$log"
}

status=0
while IFS=: read -r num name; do
    block=$(block_of "$num")
    if ! grep -q 'LeakSanitizer has encountered a fatal error' <<<"$block" ||
        ! grep -q '^\[  PASSED  \]' <<<"$block" ||
        grep -q 'detected memory leaks' <<<"$block"; then
        echo "retry_lsan_tracer: $name failed for a reason other than the tracer crash: not retried"
        status=1
        continue
    fi
    passed=0
    for attempt in 1 2; do
        if (cd "$build" && ctest --output-on-failure -R "^${name}\$") >"$build/retry-$num.log" 2>&1; then
            passed=1
            echo "retry_lsan_tracer: $name: LeakSanitizer's tracer crashed at exit; rerun $attempt passed"
            break
        fi
    done
    if [ "$passed" = 0 ]; then
        echo "retry_lsan_tracer: $name failed twice more; its last output:"
        cat "$build/retry-$num.log"
        status=1
    fi
done <"$failed.first"
exit "$status"
