#!/usr/bin/env bash
# Recovery as browsers do it (docs/input.md, "What is forgiven") on the conformance suites of two other
# browsers (../shared/conformance, beside the corpus; README.md there names the files broken on purpose):
# each file below renders with its warning and exits 3 under --strict, or fails with its clear error. And
# no Jmol export of the corpus fails --strict for an exporter's harmless habit.
# Usage: run_conformance_recovery.sh VRMLRAY_BINARY SOURCE_DIR WORK_DIR. Exit 77 (skipped) without them.
# shellcheck source=tests/cli/common.sh
. "$(dirname "$0")/common.sh"
# shellcheck source=tests/cli/corpus_lookup.sh
. "$src/tests/cli/corpus_lookup.sh"
conformance=$(dirname "$corpus")/conformance
[ -d "$conformance" ] || corpus_skip "conformance suites not found at $conformance"
xj3d=$conformance/xj3d-parsetest/parsetest
titania=$conformance/titania-tests/Library/Tests

# check FILE EXIT STRICT_EXIT PATTERN: render FILE (from its folder, as a user would) at 32x24; it must
# exit EXIT, and STRICT_EXIT under --strict, with PATTERN (an extended regex) in its messages.
check() {
    local file=$1 want=$2 want_strict=$3 pattern=$4 name
    name=${file#"$conformance"/}
    (cd "$(dirname "$file")" && "$bin" render "$(basename "$file")" -W 32 -H 24 -o "$work/out.png" \
        >"$work/out.txt" 2>"$work/err.txt")
    local code=$?
    [ $code -eq "$want" ] && pass || { fail "$name: exit $code, expected $want"; head -3 "$work/err.txt"; }
    expect_stderr "$pattern" "$name"
    (cd "$(dirname "$file")" && "$bin" render "$(basename "$file")" -W 32 -H 24 -o "$work/out.png" \
        --strict >/dev/null 2>&1)
    code=$?
    [ $code -eq "$want_strict" ] && pass || fail "$name --strict: exit $code, expected $want_strict"
}

# Unknown fields (misspelt, with a node value), values given to events.
check "$xj3d/error_handling/bad_field_name.wrl" 0 3 "warning: unknown field 'apperance' in node Shape; skipped with its value"
check "$xj3d/error_handling/bad_field_name2.wrl" 0 3 "warning: unknown field 'diffColor' in node Material; skipped with its value"
check "$xj3d/error_handling/eventIn_set.wrl" 0 3 "warning: .* is an event of [A-Za-z]+ and takes no value here; the value is skipped"
check "$xj3d/error_handling/inputOnly_set.x3dv" 0 3 "warning: .* is an event of [A-Za-z]+ and takes no value here; the value is skipped"
# USE of a name no DEF gave: the node left out.
check "$titania/Errors/Parser.wrl" 0 3 "warning: USE of '[A-Za-z0-9_]+', which no DEF before it names; the node is left out"
check "$xj3d/vrml97/field2.wrl" 0 3 "warning: USE of '[A-Za-z0-9_]+', which no DEF before it names; the node is left out"
# IS between mismatched types: the link dropped.
check "$xj3d/proto/is_type_mismatch.x3dv" 0 3 "warning: IS connects a [A-Za-z0-9]+ field to PROTO field '[A-Za-z]+' of type [A-Za-z0-9]+; the link is dropped"
# A stray word where a node belongs (a C comment's "*/"), an XML attribute value that does not parse.
check "$xj3d/filter/FlattenTransform/conglomeration.x3dv" 0 3 "conglomeration.x3dv:51:3: warning: '\\*/' is no node type and no '\\{' follows it; the word is skipped"
check "$xj3d/shape.xml" 0 3 "shape.xml:8:35: warning: attribute 'diffuseColor' of Material: expected a number, found '\\(0.5'; the field keeps its default"
# Legal white space in statements and headers, byte-order marks, UTF-16: read with no message at all.
for f in "$titania/Basic/Components.wrl" "$xj3d/filter/TriangulationFilter/ElevationGrid_Simple.wrl" \
    "$xj3d/geometry/text/english-nobom.wrl" "$xj3d/geometry/text/chinese1-bom.wrl" \
    "$xj3d/geometry/text/babel-ja.x3dv" "$xj3d/geometry/text/babel-ko.x3dv"; do
    check "$f" 0 0 "^$|."
    grep -Eq ': (warning|error): (the file|header|not a|COMPONENT|expected)' "$work/err.txt" &&
        fail "${f#"$conformance"/}: a message about its header, encoding or statements" || pass
done
# X3D V2.0 (no such version): read as X3D 3.
check "$titania/Geometry3D/IndexedFaceSet16.wrl" 0 3 "warning: the header names X3D V2.0, which does not exist; read as X3D 3"
# Several numbers of an MF field without brackets; X3D 3.x's CADLayer visible list; <fieldValue> in a node.
check "$xj3d/navigation/ortho_vp.x3dv" 0 3 "warning: several values of a multiple-valued field without brackets; read as one list"
check "$xj3d/cad/layer.x3dv" 0 0 "^$|."
check "$xj3d/xml/multi_field_ifs.x3d" 0 3 "warning: <fieldValue> inside <IndexedFaceSet> ignored"
# Broken on purpose: a clear error each, exit 3.
check "$xj3d/vrml97/bad_header1.wrl" 3 3 "bad_header1.wrl:1:1: error: not a VRML97 or X3D file: the first line is '# VRML V2.0 utf8'"
check "$xj3d/vrml97/bad_header2.wrl" 3 3 "bad_header2.wrl:1:1: error: not a VRML97 or X3D file: the first line is '#VRML 2.0 utf8'"
check "$xj3d/vrml97/bad_header3.wrl" 3 3 "bad_header3.wrl:1:1: error: not a VRML97 or X3D file: the first line is '#'"
check "$xj3d/vrml97/bad_header4.wrl" 3 3 "bad_header4.wrl:1:1: error: the header names no encoding: '#VRML V2.0', expected '#VRML V2.0 utf8'"
check "$xj3d/vrml97/bad_header5.wrl" 3 3 "bad_header5.wrl:1:1: error: not a VRML97 or X3D file: the first line is '#VRMLV2.0utf8'"
check "$xj3d/error_handling/bad_field_value.wrl" 3 3 "bad_field_value.wrl:[0-9]+:[0-9]+: error: expected a number, found 'children'"
check "$xj3d/vrml97/script2.wrl" 3 3 "script2.wrl:[0-9]+:[0-9]+: error: expected a field name or '\}' in Script, found '0'"
check "$xj3d/performance/elevationgrid.x3db" 3 3 "error: the file is X3D's binary encoding \(Fast Infoset, .x3db\), which is not read"

# --- Jmol's exports: their habits (unnormalised bond axes, type='EXAMINE', flat cartoon faces) pass --strict
for f in "$corpus"/molecular/jmol/*; do
    "$bin" info "$f" --strict >/dev/null 2>"$work/err.txt"
    code=$?
    [ $code -eq 0 ] && pass || { fail "jmol ${f##*/}: info --strict exits $code"; head -3 "$work/err.txt"; }
done

echo "conformance recovery ($conformance): $passed passed, $failed failed"
[ "$failed" -eq 0 ]
