#!/usr/bin/env bash
# Installs, builds, and renders the demo scene (the scene file data/demo.json: a key
# light with shadows, a sky, a reflective floor) to demo.png.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
build/rastray render data/demo.json -o demo.png
echo "rendered the demo scene to $(pwd)/demo.png"
