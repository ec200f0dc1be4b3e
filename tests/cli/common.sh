# Sourced by the CLI test scripts: their arguments, a clean work folder and the pass/fail helpers.
# Usage of a script that sources it: SCRIPT VRMLRAY_BINARY SOURCE_DIR WORK_DIR (relative paths are fine).
set -u
bin=$(realpath "$1")
src=$(realpath "$2")
work=$3
# Start clean: a rerun must never compare files an earlier run left behind.
rm -rf "$work"
mkdir -p "$work"
work=$(realpath "$work")
passed=0
failed=0
fail() { echo "FAIL: $*"; failed=$((failed + 1)); }
pass() { passed=$((passed + 1)); }

# expect CODE DESCRIPTION -- COMMAND...: the command must exit with CODE.
expect() {
    local code=$1 what=$2
    shift 3
    "$@" >"$work/out.txt" 2>"$work/err.txt"
    local got=$?
    if [ "$got" -eq "$code" ]; then pass; else fail "$what: exit $got, expected $code"; sed 's/^/    /' "$work/err.txt" | head -5; fi
}

# expect_stderr PATTERN DESCRIPTION: the last command's stderr matches the extended regex.
expect_stderr() {
    if grep -Eq -- "$1" "$work/err.txt"; then pass; else fail "$2: stderr lacks /$1/"; sed 's/^/    /' "$work/err.txt" | head -5; fi
}

# A broken corpus file lives under a folder named bad, warnings or errors.
is_broken() { case "$1" in */bad/*|*/warnings/*|*/errors/*) return 0;; *) return 1;; esac; }
