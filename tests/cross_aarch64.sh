#!/bin/sh
# Compiles every library source for aarch64 with the project's warning flags, so
# that no x86 intrinsic escapes its guard. Skipped (77) only without the cross
# compiler (scripts/deps.sh installs it).
# Usage: cross_aarch64.sh CC SOURCE_DIR DATA_DIR THIRD_PARTY_INCLUDE_DIR...
cc=$1 root=$2 data=$3
shift 3
if ! command -v "$cc" >/dev/null 2>&1; then
  echo "skipped: $cc not found (install gcc-aarch64-linux-gnu)"
  exit 77
fi
# Third-party headers (assimp, stb, tinyexr) after the cross compiler's own, so
# that its C library's headers are the ones found.
after=""
for dir in "$@"; do after="$after -idirafter $dir"; done
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
passed=0 failed=0
for src in "$root"/src/*/*.c; do
  name=$(basename "$(dirname "$src")")_$(basename "$src" .c)
  # shellcheck disable=SC2086 # $after is a list of flags
  if "$cc" -std=c11 -O2 -Wall -Wextra -Werror -ffp-contract=off -I"$root/include" -I"$root/src" $after \
    -DRR_DATA_DIR="\"$data\"" -c "$src" -o "$out/$name.o" 2>"$out/$name.log"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAILED: ${src#"$root"/}"
    head -n 20 "$out/$name.log"
  fi
done
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
