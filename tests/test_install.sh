#!/bin/sh
# Builds README.md's C example (the first ```c block of its "## Library" section,
# exactly as printed) the ways the README tells, and runs it: it must render the
# demo scene and report pixels that hit a triangle.
#   CMAKE CC SOURCE_DIR BUILD_DIR package
#       `cmake --install` of BUILD_DIR into a temporary prefix, then the example
#       through pkg-config with the shared library, through `pkg-config --static`
#       with the archive alone, and through find_package(rastray) (the README's
#       ```cmake block, plus rastray::rastray_static).
#   CMAKE CC SOURCE_DIR BUILD_DIR subdirectory
#       a parent project that add_subdirectory()s a copy of the sources and links
#       rastray::rastray: rastray's tests and flags stay out of the parent, and once
#       installed the library reads the demo's data where it was installed.
set -eu
cmake=$1 cc=$2 src=$3 build=$4 mode=$5
unset RASTRAY_DATA # the examples find the demo's data as installed or in the sources
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() {
  echo "FAILED: $*" >&2
  exit 1
}

# The README's blocks, fenced ```LANG ... ```, in the Library section.
readme_block() {
  awk -v lang="$1" '/^## / { lib = ($0 == "## Library") }
    lib && !on && $0 == "```" lang { on = 1; next }
    on && /^```$/ { exit }
    on' "$src/README.md"
}
readme_block c >"$tmp/example.c"
[ -s "$tmp/example.c" ] || fail "README.md has no \`\`\`c block in its Library section"

# Runs a built example; it must print "H of N pixels hit a triangle" with 0 < H <= N.
run() {
  out=$("$@") || fail "$* exited with status $?"
  echo "$out"
  echo "$out" | awk '$2 == "of" && $4 == "pixels" && $1 > 0 && $1 <= $3 { ok = 1 } END { exit !ok }' ||
    fail "$1 printed '$out', not hits of pixels"
}

# Tells whether a program loads librastray.so (readelf lists the libraries it needs).
needs_shared() { readelf -d "$1" | grep -q 'NEEDED.*librastray\.so'; }

if [ "$mode" = package ]; then
  prefix=$tmp/prefix
  "$cmake" --install "$build" --prefix "$prefix" >"$tmp/install.log" || {
    cat "$tmp/install.log"
    fail "cmake --install"
  }
  for f in include/rastray.h bin/rastray share/rastray/teapot.obj share/man/man1/rastray.1; do
    [ -e "$prefix/$f" ] || fail "$f is not installed"
  done
  pc=$(find "$prefix" -name rastray.pc)
  [ -n "$pc" ] || fail "rastray.pc is not installed"
  pcdir=${pc%/*}
  libdir=${pcdir%/*}

  export PKG_CONFIG_PATH="$pcdir"
  # shellcheck disable=SC2046 # pkg-config's output is a list of flags
  "$cc" "$tmp/example.c" -o "$tmp/example_pc" $(pkg-config --cflags --libs rastray) ||
    fail "the example does not compile with pkg-config"
  needs_shared "$tmp/example_pc" || fail "pkg-config did not link librastray.so"
  (export LD_LIBRARY_PATH="$libdir" && run "$tmp/example_pc")

  # The linker prefers librastray.so to librastray.a in one directory: the static
  # link is made in a copy of the prefix without it, as installed static-only.
  cp -R "$prefix" "$tmp/static"
  rm "$tmp/static/${libdir#"$prefix"/}"/librastray.so*
  export PKG_CONFIG_PATH="$tmp/static/${pcdir#"$prefix"/}"
  # shellcheck disable=SC2046
  "$cc" "$tmp/example.c" -o "$tmp/example_static" $(pkg-config --static --cflags --libs rastray) ||
    fail "the example does not link librastray.a with pkg-config --static"
  ! needs_shared "$tmp/example_static" || fail "pkg-config --static linked librastray.so"
  run "$tmp/example_static"

  mkdir "$tmp/cmake"
  cp "$tmp/example.c" "$tmp/cmake/"
  readme_block cmake >"$tmp/cmake/CMakeLists.txt"
  grep -q 'find_package(rastray' "$tmp/cmake/CMakeLists.txt" || fail "README.md has no \`\`\`cmake block using find_package"
  cat >>"$tmp/cmake/CMakeLists.txt" <<'EOF'
add_executable(example_static example.c)
target_link_libraries(example_static PRIVATE rastray::rastray_static)
EOF
  { "$cmake" -S "$tmp/cmake" -B "$tmp/cmake/build" -DCMAKE_PREFIX_PATH="$prefix" &&
    "$cmake" --build "$tmp/cmake/build"; } >"$tmp/cmake.log" 2>&1 || {
    cat "$tmp/cmake.log"
    fail "the example does not build with find_package(rastray)"
  }
  needs_shared "$tmp/cmake/build/example" || fail "rastray::rastray is not the shared library"
  ! needs_shared "$tmp/cmake/build/example_static" || fail "rastray::rastray_static linked librastray.so"
  run "$tmp/cmake/build/example"
  run "$tmp/cmake/build/example_static"
elif [ "$mode" = subdirectory ]; then
  # A copy of what a checkout holds, so that its data/ can be taken away below.
  mkdir -p "$tmp/parent/rastray"
  for f in CMakeLists.txt cmake include src tools data man; do
    [ ! -e "$src/$f" ] || cp -R "$src/$f" "$tmp/parent/rastray/"
  done
  cp "$tmp/example.c" "$tmp/parent/"
  cat >"$tmp/parent/CMakeLists.txt" <<'EOF'
cmake_minimum_required(VERSION 3.16)
project(parent C)
add_subdirectory(rastray)
add_executable(example example.c)
target_link_libraries(example PRIVATE rastray::rastray)
EOF
  # No build type: rastray's sources compile unoptimised, which is quicker.
  b=$tmp/parent/build
  { "$cmake" -S "$tmp/parent" -B "$b" -DCMAKE_INSTALL_PREFIX="$tmp/prefix" -DCMAKE_EXPORT_COMPILE_COMMANDS=ON &&
    "$cmake" --build "$b" -j2 --target example; } >"$tmp/build.log" 2>&1 || {
    cat "$tmp/build.log"
    fail "the parent project does not build"
  }
  (cd "$b" && ctest -N) | grep -q 'Total Tests: 0' || fail "rastray added its tests to the parent project"
  awk '/"command"/ { cmd = $0 } /"file".*\/parent\/example\.c"/ { print cmd }' "$b/compile_commands.json" \
    >"$tmp/example_cmd"
  [ -s "$tmp/example_cmd" ] || fail "no compile command for the parent's example.c"
  ! grep -q -e '-Werror' -e '-ffp-contract' "$tmp/example_cmd" || fail "rastray's flags reach the parent's targets"
  run "$b/example"

  # Installed, the library finds the demo's meshes under the prefix, with the
  # source tree's data/ gone (and not before the installation).
  mv "$tmp/parent/rastray/data" "$tmp/parent/rastray/data.moved"
  ! "$b/example" >/dev/null 2>&1 || fail "the demo's data was found before it was installed"
  mv "$tmp/parent/rastray/data.moved" "$tmp/parent/rastray/data"
  { "$cmake" --build "$b" -j2 && "$cmake" --install "$b"; } >"$tmp/install.log" 2>&1 || {
    cat "$tmp/install.log"
    fail "the parent project does not install"
  }
  rm -rf "$tmp/parent/rastray/data"
  run "$b/example"
  mv "$tmp/prefix/share/rastray" "$tmp/data"
  (export RASTRAY_DATA="$tmp/data" && run "$b/example")
else
  fail "unknown mode '$mode' (package or subdirectory)"
fi
echo "passed"
