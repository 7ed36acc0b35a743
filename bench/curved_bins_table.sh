#!/bin/sh
# The curved cameras' empty-bin table of docs/cameras.md: the share of refined bins
# that held none of their triangle (rastray render --stats), 3dr-bin and 3dr-full,
# parabolic, lat-long and fisheye (180°), 512² (lat-long 512×256), 2 threads, on
# the teapot grid 7² and the bunny from inside.
#   bench/curved_bins_table.sh RASTRAY [MODELS_DIR]
set -e
bin=$1 models=${2:-../shared/models}
for sc in grid bunny; do
  if [ $sc = grid ]; then s=grid:$models/teapot.obj:7 e=20.6,2.4,13.2 t=30,1.2,20
  else s=$models/stanford-bunny.obj e=0,0.12,0.09 t=-0.02,0.1,0; fi
  for cam in parabolic latlong fisheye; do
    size=512x512 fov=70
    [ $cam = latlong ] && size=512x256
    [ $cam = fisheye ] && fov=180
    for m in 3dr-bin 3dr-full; do
      st=$("$bin" render "$s" --camera $cam --size $size --eye $e --target $t --fov $fov --method $m --threads 2 \
        --shade id -o /dev/null --stats -q 2>&1 | grep -o 'bins=[0-9]* bins_empty=[0-9]*')
      b=${st#bins=}; b=${b%% *}; z=${st#*bins_empty=}
      echo "$sc $cam $m $z of $b $(awk "BEGIN{if ($b) printf \"%.1f%%\", 100*$z/$b; else print \"-\"}")"
    done
  done
done
