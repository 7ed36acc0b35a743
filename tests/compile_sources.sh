#!/bin/sh
# Compiles every library source (src/*/*.c) with the project's warning flags and
# fails on any error, in one of two modes:
#   cross CC ROOT DATA_DIR DIR...  for another architecture (CC: aarch64-linux-gnu-gcc),
#                                  so that no x86 intrinsic escapes its guard; DIRs
#                                  hold the third-party headers (the same for every
#                                  architecture). Skipped (77) without CC.
#   no-simd CC ROOT DATA_DIR       for this machine with RR_NO_SIMD, which must then
#                                  leave out every x86 intrinsics header (*intrin.h).
mode=$1 cc=$2 root=$3 data=$4
shift 4
if ! command -v "$cc" >/dev/null 2>&1; then
  echo "skipped: $cc not found (scripts/deps.sh installs it)"
  exit 77
fi
flags="-std=c11 -O2 -Wall -Wextra -Werror -ffp-contract=off"
# The third-party headers come after the compiler's own, so that its C library's are found.
for dir in "$@"; do flags="$flags -idirafter $dir"; done
[ "$mode" = no-simd ] && flags="$flags -DRR_NO_SIMD -H" # -H lists every header included
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
passed=0 failed=0
for src in "$root"/src/*/*.c; do
  name=$(basename "$(dirname "$src")")_$(basename "$src" .c)
  # shellcheck disable=SC2086 # $flags is a list
  if "$cc" $flags -I"$root/include" -I"$root/src" -DRR_DATA_DIR="\"$data\"" -DRR_DATA_INSTALL_DIR="\"$data\"" \
    -c "$src" -o "$out/$name.o" 2>"$out/$name.log" &&
    ! { [ "$mode" = no-simd ] && grep -q 'intrin\.h' "$out/$name.log"; }; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAILED: ${src#"$root"/}"
    grep -E 'error|warning' "$out/$name.log" | head -n 20
    grep -E '^\.+ .*intrin\.h' "$out/$name.log" | head -n 1
  fi
done
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
