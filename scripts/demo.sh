#!/usr/bin/env bash
# Installs, builds, and renders the built-in demo scene to demo.png.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
build/rastray render demo -o demo.png
echo "rendered the demo scene to $(pwd)/demo.png"
