#!/usr/bin/env bash
# Installs the Debian 12 packages vrmlray needs, and nothing when they are all there.
#   tools/setup.sh [PACKAGE...]    also these (the benches name their peers: tachyon, povray, ...)
set -euo pipefail
pkgs=(cmake g++ make pkg-config libopenimageio-dev libglm-dev libxml2-dev libcli11-dev zlib1g-dev
      libgtest-dev libgmock-dev libpng-dev libjpeg62-turbo-dev libopenexr-dev libxml2-utils nlohmann-json3-dev
      python3 go-md2man dpkg-dev pybind11-dev python3-pybind11 python3-numpy python3-pytest python3-matplotlib
      chromium libfreetype-dev libfontconfig-dev fonts-dejavu-core groff-base bsdextrautils
      libgeographiclib-dev geographiclib-tools
      openmpi-bin libopenmpi-dev duktape-dev "$@")
missing=()
for p in "${pkgs[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "setup: installing ${missing[*]}" >&2
sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
