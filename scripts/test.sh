#!/usr/bin/env bash
# Builds and runs the whole test suite twice: optimised, then under the address
# and undefined-behaviour sanitizers.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
(cd build && ctest --output-on-failure -j2)
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRR_SANITIZE=ON >/dev/null
cmake --build build-sanitize -j"$(nproc)"
# The same tests again under the sanitizers; property tests visit fewer views there.
(cd build-sanitize && RR_TEST_QUICK=1 ASAN_OPTIONS=detect_leaks=1 ctest --output-on-failure -j2)
