#!/usr/bin/env bash
# Builds the Debian package from a build folder, installs it as a user would (apt resolves its dependencies),
# renders a bundled scene with the installed /usr/bin/vrmlray and compares it with the golden image; then
# removes the package again. Usage: tools/test_deb.sh [BUILD_DIR] (default build/, configured and built).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(realpath "${1:-$root/build}")
(cd "$build" && rm -f vrmlray_*.deb && cpack -G DEB >/dev/null)
deb=$(ls "$build"/vrmlray_*.deb)
export DEBIAN_FRONTEND=noninteractive
sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
$sudo apt-get install -y -qq "$deb" >/dev/null
trap '$sudo apt-get remove -y -qq vrmlray >/dev/null' EXIT
work=$(mktemp -d)
status=0
/usr/bin/vrmlray render "$root/scenes/seeds/001_sphere.wrl" -W 320 -H 240 -q -o "$work/sphere.png" || status=1
/usr/bin/vrmlray render "$root/scenes/seeds/001_sphere.wrl" -W 64 -H 48 -q -o "$work/sphere.exr" || status=1
# The same bound as the golden tests (tests/cli/run_cli_tests.sh): one 8-bit code on 0.1% of the pixels.
/usr/bin/vrmlray compare "$work/sphere.png" "$root/tests/render/golden/001_sphere.png" \
    --pixel-threshold 0 --max-fail-percent 0.1 --max-abs 0.004 >/dev/null || status=1
for f in /usr/share/man/man1/vrmlray.1 /usr/share/bash-completion/completions/vrmlray /usr/lib/vrmlray/vrmlray_oiio.so /usr/lib/vrmlray/vrmlray_exr.so; do
    [ -s "$f" ] || { echo "deb: $f missing"; status=1; }
done
# The Python module, when the build has one: Debian's python3 imports it and writes the same PNG.
if ls "$build"/python/vrmlray*.so >/dev/null 2>&1; then
    (cd "$work" && /usr/bin/python3 -c "import vrmlray, sys; s = vrmlray.load(sys.argv[1]); vrmlray.write_image('py.png', s.render(320, 240))" \
        "$root/scenes/seeds/001_sphere.wrl") || { echo "deb: the Python module does not import or render"; status=1; }
    cmp -s "$work/py.png" "$work/sphere.png" || { echo "deb: the Python module's PNG differs from the binary's"; status=1; }
fi
rm -rf "$work"
[ $status -eq 0 ] && echo "deb: 1 passed, 0 failed ($(basename "$deb") installs, renders PNG and EXR, matches the golden)" \
                  || echo "deb: 0 passed, 1 failed"
exit $status
