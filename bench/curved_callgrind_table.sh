#!/bin/sh
# The curved cameras' instruction table of docs/cameras.md: bench/curved_callgrind.sh
# for rc-bvh and the 3D methods, parabolic, lat-long and fisheye (180°), 256²
# (lat-long 256×128), on the teapot grid 7² and the bunny from inside, one thread.
#   bench/curved_callgrind_table.sh RASTRAY [MODELS_DIR]
set -e
bin=$1 models=${2:-../shared/models}
here=$(dirname "$0")
for sc in grid bunny; do
  if [ $sc = grid ]; then s=grid:$models/teapot.obj:7 e=20.6,2.4,13.2 t=30,1.2,20
  else s=$models/stanford-bunny.obj e=0,0.12,0.09 t=-0.02,0.1,0; fi
  for cam in parabolic latlong fisheye; do
    size=256x256
    [ $cam = latlong ] && size=256x128
    for m in rc-bvh 3dr-bb 3dr-bin 3dr-full; do
      echo "$sc $("$here/curved_callgrind.sh" "$bin" "$s" $cam $m $size $e $t)"
    done
  done
done
