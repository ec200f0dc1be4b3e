#!/usr/bin/env bash
# Fails when a source or header includes a folder that its layer may not use. The table is the one
# the build compiles with: the vrmlray_layer(NAME FOLDER...) lines of CMakeLists.txt (a layer and the
# folders it may include). The compile catches an upward include in any file a layer compiles; this
# also catches one in a header that no source of its own layer includes.
#
#   tests/layering.sh [SOURCE_DIR]
set -euo pipefail
root=${1:-$(cd "$(dirname "$0")/.." && pwd)}
declare -A allowed folder_of
while read -r layer folders; do
    for f in $folders; do allowed[$layer]+=" ${f##*/} "; done
    folder_of[$layer]=${folders##* }  # a layer's own folder comes last
done < <(sed -n 's/^vrmlray_layer(\([a-z]*\) \(.*\))$/\1 \2/p' "$root/CMakeLists.txt")
[ ${#allowed[@]} -gt 0 ] || { echo "layering: no vrmlray_layer() lines in CMakeLists.txt" >&2; exit 1; }
bad=0
for layer in "${!allowed[@]}"; do
    dir=$root/${folder_of[$layer]}
    [ "${dir##*/}" = "$layer" ] || { echo "layering: $layer's own folder must come last" >&2; exit 1; }
    while IFS=: read -r file line text; do
        target=$(sed 's/.*#include "\([^"]*\)".*/\1/' <<<"$text")
        case $target in
            */*) top=${target%%/*} ;;
            *) continue ;;  # a file of the same folder
        esac
        if [ "$top" = ".." ] || [[ "${allowed[$layer]}" != *" $top "* ]]; then
            echo "${file#"$root"/}:$line: $layer may not include \"$target\" (it may use: $(echo ${allowed[$layer]}))"
            bad=1
        fi
    done < <(grep -n '^[[:space:]]*#[[:space:]]*include "' "$dir"/*.h "$dir"/*.cpp 2>/dev/null || true)
done
[ $bad -eq 0 ] && echo "layering: every include goes to the same or a lower layer"
exit $bad
