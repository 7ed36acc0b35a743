#!/bin/sh
# Two threads against one for the fastest method of each benchmark scene, as a
# ratio taken in one run: the two thread counts take turns, three times each, and
# the middle of the three medians counts. Writes Markdown to stdout.
#
#   bench/scaling.sh [BUILD_DIR]      (after scripts/build.sh; default build)
set -eu
build=${1:-build}
models=$(sed -n 's/^RR_MODELS_DIR:PATH=//p' "$build/CMakeCache.txt")
[ -d "$models" ] || { echo "scaling.sh: no meshes at '$models' (RR_MODELS_DIR)" >&2; exit 1; }

frame() { # SCENE METHOD THREADS [--cull-backfaces]: median frame ms of 15
  "$build/rastray" render "$1" --method "$2" --threads "$3" --size 1024x1024 --repeat 15 ${4:-} \
    -o /tmp/rastray-scaling.png --stats 2>&1 | sed -n 's/.*frame_ms=\([0-9.]*\).*/\1/p'
}
middle() { printf '%s\n' "$@" | sort -n | sed -n 2p; }

echo "| scene | method | culling | 1 thread ms | 2 threads ms | scaling |"
echo "|---|---|---|---|---|---|"
for scene in stanford-bunny.obj ogre.obj nefertiti.obj grid:teapot.obj:19 rooms:8; do
  case $scene in
    rooms*) path=$scene method=3dr-bin ;;
    grid:*) path="grid:$models/${scene#grid:}" method=3dr-bb ;;
    *) path="$models/$scene" method=3dr-bb ;;
  esac
  for cull in --cull-backfaces ""; do
    a1=$(frame "$path" $method 1 $cull) b1=$(frame "$path" $method 2 $cull)
    a2=$(frame "$path" $method 1 $cull) b2=$(frame "$path" $method 2 $cull)
    a3=$(frame "$path" $method 1 $cull) b3=$(frame "$path" $method 2 $cull)
    one=$(middle "$a1" "$a2" "$a3") two=$(middle "$b1" "$b2" "$b3")
    [ -n "$cull" ] && culled=yes || culled=no
    echo "| $scene | $method | $culled | $one | $two | $(awk "BEGIN { printf \"%.2f\", $one / $two }")× |"
  done
done
rm -f /tmp/rastray-scaling.png
