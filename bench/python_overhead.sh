#!/bin/sh
# The Python package's overhead over the C API, in instructions (callgrind), which a
# busy machine does not blur: one Scene.render (3dr-bin and four AOVs at SIZE²) and
# one Scene.intersect (SIZE² rays) against the same calls from C (bench_python),
# each as the difference between runs of 2 calls and of none; rays+normals adds
# Scene.intersect's normals (rr_scene_get_normals), which the C stream call lacks.
#   bench/python_overhead.sh BUILD_DIR [SIZE]
set -eu
build=$1 size=${2:-1024}
src=$(cd "$(dirname "$0")/.." && pwd)
py=/usr/bin/python3
count() { # instructions of a command under callgrind
  valgrind --tool=callgrind --callgrind-out-file=/dev/null "$@" 2>&1 | sed -n 's/.*Collected : *\([0-9]*\).*/\1/p'
}
for mode in render rays rays+normals; do
  cmode=${mode%+normals} # the C side has no normals: the same stream call
  c0=$(count "$build/bench_python" $cmode 0 "$size"); c2=$(count "$build/bench_python" $cmode 2 "$size")
  p0=$(RASTRAY_LIBRARY="$build/librastray.so" PYTHONPATH="$src/python" count $py "$src/bench/python_overhead.py" $mode 0 "$size")
  p2=$(RASTRAY_LIBRARY="$build/librastray.so" PYTHONPATH="$src/python" count $py "$src/bench/python_overhead.py" $mode 2 "$size")
  awk -v m=$mode -v c0="$c0" -v c2="$c2" -v p0="$p0" -v p2="$p2" 'BEGIN {
    c = (c2 - c0) / 2; p = (p2 - p0) / 2
    printf "%-12s one call: C %.1f M instructions, Python %.1f M: %.3fx\n", m, c / 1e6, p / 1e6, p / c }'
done
