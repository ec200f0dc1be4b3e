# Sourced by the CLI tests: sets $corpus to the outside corpus of real files, by the same rule as
# tests/unit/corpus.h, or explains and exits 77 (CTest's skip code) / 1 (failure).
#   VRMLRAY_CORPUS=DIR (must exist), VRMLRAY_CORPUS=none (skip), unset: $src/../shared/corpus when it exists.
#   VRMLRAY_REQUIRE_CORPUS=1: a skip is a failure (CI, where the folder is laid beside the clone).
# Needs $src (the source tree).
corpus_skip() {
    if [ "${VRMLRAY_REQUIRE_CORPUS:-}" = 1 ]; then echo "FAIL: $1 (VRMLRAY_REQUIRE_CORPUS=1)"; exit 1; fi
    echo "SKIPPED: $1"
    exit 77
}
if [ "${VRMLRAY_CORPUS:-}" = none ]; then
    corpus_skip "corpus skipped: VRMLRAY_CORPUS=none"
elif [ -n "${VRMLRAY_CORPUS:-}" ]; then
    corpus=$VRMLRAY_CORPUS
    [ -d "$corpus" ] || { echo "FAIL: VRMLRAY_CORPUS=$corpus is not a folder"; exit 1; }
else
    corpus=$(cd "$src/.." && pwd)/shared/corpus
    [ -d "$corpus" ] || corpus_skip "corpus not found at $corpus; set VRMLRAY_CORPUS=DIR to run these tests"
fi
