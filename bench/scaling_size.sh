#!/bin/sh
# Frame time against scene size, the one command that remakes all of it:
# bench_scaling measures (teapot grids 1², 3², 7², 13², 19²; every method and
# Embree; 1 and 2 threads) into docs/scaling-size.csv and .md, plot_scaling.py
# draws docs/scaling-size.svg (and a PNG when rsvg-convert is installed), and the
# tables replace the part of docs/scaling.md between its two scaling_size.sh marks.
# 6 minutes at 1024x1024 on the 2-core machine at load average 9-15; less when quiet.
#
#   bench/scaling_size.sh [BUILD_DIR] [bench_scaling options, e.g. --size 512]
#                                     (after scripts/build.sh; default build)
set -eu
build=build
case ${1:-} in -*|"") ;; *) build=$1; shift ;; esac
out=docs/scaling-size doc=docs/scaling.md
[ -x "$build/bench_scaling" ] || { echo "scaling_size.sh: no $build/bench_scaling (build first)" >&2; exit 1; }
if ! grep -q '^<!-- scaling_size.sh: from here -->$' "$doc" || ! grep -q '^<!-- scaling_size.sh: to here -->$' "$doc"
then echo "scaling_size.sh: $doc lacks the two scaling_size.sh marks" >&2; exit 1; fi

"$build/bench_scaling" --out "$out" "$@"
python3 "$(dirname "$0")/plot_scaling.py" "$out.csv" -o "$out.svg"
if command -v rsvg-convert >/dev/null; then rsvg-convert "$out.svg" -o "$out.png"; fi

# The tables go between the marks; the rest of the document stays as written.
awk -v tables="$out.md" '
  $0 == "<!-- scaling_size.sh: to here -->" { inside = 0 }
  !inside { print }
  $0 == "<!-- scaling_size.sh: from here -->" { inside = 1; while ((getline line < tables) > 0) print line }
' "$doc" > "$doc.tmp" && mv "$doc.tmp" "$doc"
echo "updated $doc" >&2
