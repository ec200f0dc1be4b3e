#!/usr/bin/env bash
# The man page reads in an 80-column terminal: made from docs/manual.md as the package makes it, then
# formatted by groff as man does at 80 columns (line length 78), no line may be wider than 80.
# Usage: tests/man_width.sh SOURCE_DIR
set -euo pipefail
src=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$src/tools/make_man.sh" "$src/docs/manual.md" 0 "$work/vrmlray.1"
groff -t -man -Tutf8 -rLL=78n -rcR=1 "$work/vrmlray.1" 2>/dev/null | col -bx >"$work/page.txt"
lines=$(wc -l <"$work/page.txt")
[ "$lines" -gt 100 ] || { echo "FAIL: the page has only $lines lines"; exit 1; }
wide=$(python3 -c "
import sys
rows = [l.rstrip('\n') for l in open(sys.argv[1], encoding='utf-8')]
wide = [(n + 1, l) for n, l in enumerate(rows) if len(l) > 80]
for n, l in wide[:10]: print(f'line {n} ({len(l)} columns): {l}')
print(len(wide))" "$work/page.txt")
count=$(echo "$wide" | tail -n 1)
if [ "$count" -ne 0 ]; then
    echo "$wide" | head -n -1
    echo "FAIL: $count lines of the man page are wider than 80 columns"
    exit 1
fi
echo "man page: $lines lines, none wider than 80 columns"
