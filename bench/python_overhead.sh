#!/bin/sh
# The Python package's overhead over the C API, in instructions (callgrind), which a
# busy machine does not blur: Scene.render (3dr-bin and four AOVs at SIZE²) and
# Scene.intersect (SIZE² rays) against the same calls from C (bench_python, on the
# same shared library). From runs of 0, 1 and 3 calls: the first call (1 - 0: with
# Python's one-off costs, lazy imports and the interpreter's specialisation) and a
# later call ((3 - 1) / 2). rays+normals adds Scene.intersect's normals
# (rr_scene_get_normals), which the C stream call does not give.
#   bench/python_overhead.sh BUILD_DIR [SIZE]
set -eu
build=$1 size=${2:-1024}
src=$(cd "$(dirname "$0")/.." && pwd)
py=/usr/bin/python3
count() { # instructions of a command under callgrind
  valgrind --tool=callgrind --callgrind-out-file=/dev/null "$@" 2>&1 | sed -n 's/.*Collected : *\([0-9]*\).*/\1/p'
}
pycount() { RASTRAY_LIBRARY="$build/librastray.so" PYTHONPATH="$src/python" count $py "$src/bench/python_overhead.py" "$@"; }
for mode in render rays rays+normals; do
  cmode=${mode%+normals} # the C side has no normals: the same stream call
  c0=$(count "$build/bench_python" $cmode 0 "$size"); c1=$(count "$build/bench_python" $cmode 1 "$size")
  c3=$(count "$build/bench_python" $cmode 3 "$size")
  p0=$(pycount $mode 0 "$size"); p1=$(pycount $mode 1 "$size"); p3=$(pycount $mode 3 "$size")
  awk -v m=$mode -v c0="$c0" -v c1="$c1" -v c3="$c3" -v p0="$p0" -v p1="$p1" -v p3="$p3" 'BEGIN {
    cf = c1 - c0; pf = p1 - p0; cl = (c3 - c1) / 2; pl = (p3 - p1) / 2
    printf "%-12s first call: C %.1f M, Python %.1f M instructions (%.3fx); later calls: C %.1f M, Python %.1f M (%.3fx)\n",
           m, cf / 1e6, pf / 1e6, pf / cf, cl / 1e6, pl / 1e6, pl / cl }'
done
