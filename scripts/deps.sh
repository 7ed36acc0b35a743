#!/usr/bin/env bash
# Installs the Debian 12 packages rastray builds, tests and benchmarks with.
# apt-get runs only when something is missing (as root, or through sudo).
set -eu
pkgs="cmake make gcc g++ pkg-config libassimp-dev libstb-dev libtinyexr-dev libpng-dev
      libembree-dev libosmesa6-dev hyperfine valgrind gcc-aarch64-linux-gnu
      libcjson-dev python3-numpy python3-cffi python3-opencv python3-pytest groff-base clang libclang-rt-14-dev"
missing=""
for p in $pkgs; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
[ -z "$missing" ] && exit 0
echo "installing:$missing" >&2
sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
$sudo apt-get update -q
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q $missing
