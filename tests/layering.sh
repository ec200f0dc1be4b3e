#!/usr/bin/env bash
# Fails when a source or header includes a folder that its layer may not use. The table is the one
# the build compiles with: the vrmlray_layer(NAME FOLDER...) lines of CMakeLists.txt (a layer and the
# folders it may include). The compile catches an upward include in any file a layer compiles; this
# also catches one in a header that no source of its own layer includes, looks into subfolders, and
# fails when a folder of sources (under src/, parser/, python/) belongs to no layer.
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
    done < <(find "$dir" -type f \( -name '*.h' -o -name '*.cpp' \) -print0 |
             xargs -0 -r grep -n '^[[:space:]]*#[[:space:]]*include "' /dev/null || true)
done
# Every folder of product code is some layer's (or inside one): a new folder must get its row in
# the table before its includes are checked at all.
owned=" "
for layer in "${!folder_of[@]}"; do owned+="${folder_of[$layer]} "; done
while read -r dir; do
    rel=${dir#"$root"/} covered=0
    for f in $owned; do
        [ "$rel" = "$f" ] || [[ "$rel" == "$f"/* ]] && covered=1
    done
    if [ $covered -eq 0 ]; then
        echo "layering: $rel holds sources but no vrmlray_layer() line of CMakeLists.txt names it"
        bad=1
    fi
done < <(find "$root/src" "$root/parser" "$root/python" -type f \( -name '*.h' -o -name '*.cpp' \) \
             -printf '%h\n' | sort -u)
[ $bad -eq 0 ] && echo "layering: every include goes to the same or a lower layer"
exit $bad
