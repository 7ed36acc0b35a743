#!/bin/sh
# Instruction counts of the visibility pass (rr_render, one thread) of a method on
# a camera: bench/curved_callgrind.sh RASTRAY SCENE CAMERA METHOD SIZE [EYE TARGET]
# prints "camera method Ir setups bins bins_empty". Instruction counts repeat
# from run to run where times on a shared machine do not.
set -e
bin=$1 scene=$2 cam=$3 method=$4 size=$5
view=""
[ -n "$6" ] && view="--eye $6 --target $7"
fov=70
[ "$cam" = fisheye ] && fov=180
out=$(mktemp -d)
valgrind --tool=callgrind --callgrind-out-file="$out/cg" --collect-atstart=no --toggle-collect=rr_render \
  "$bin" render "$scene" --camera "$cam" --size "$size" $view --fov $fov --method "$method" --threads 1 \
  --shade id -o /dev/null --stats -q 2>"$out/err" >/dev/null
ir=$(grep -E '^(summary|totals):' "$out/cg" | head -1 | awk '{print $2}')
st=$(grep -o 'setups=[0-9]* \|bins=[0-9]* \|bins_empty=[0-9]*' "$out/err" | tr -d ' ' | tr '\n' ' ')
echo "$cam $method $ir $st"
rm -rf "$out"
