#!/usr/bin/env bash
# Writes the man page vrmlray.1 from docs/manual.md (the same text as the manual), through go-md2man.
# Usage: tools/make_man.sh docs/manual.md VERSION OUT.1
set -euo pipefail
manual=$1 version=$2 out=$3
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
{
    printf '%% VRMLRAY 1 "%s" "vrmlray %s" "User Commands"\n\n' "$(date -u -d "@${SOURCE_DATE_EPOCH:-0}" '+%B %Y' 2>/dev/null || echo 1970)" "$version"
    printf '# NAME\nvrmlray - a fast, exact ray tracer for VRML97 and X3D scene files\n\n# SYNOPSIS\n'
    # The manual without its HTML comment and title line; its sections become the page's sections.
    # Tables become lists: a table row wider than the terminal is split beyond reading.
    grep -v '^<!--' "$manual" | tail -n +2 | python3 "$(dirname "$0")/man_tables.py"
    printf '\n# SEE ALSO\nThe project README and docs/ (input.md, rendering.md) beside the sources.\n'
} >"$tmp"
go-md2man -in "$tmp" -out "$out"
