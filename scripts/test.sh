#!/usr/bin/env bash
# Builds and runs the test suite three times: optimised; under the address and
# undefined-behaviour sanitizers with SIMD turned off (the portable code paths);
# and the tests that run threads under the thread sanitizer; then runs each
# libFuzzer target (clang) for a bounded time. Every run goes ahead whatever the
# one before found; the exit status says whether all passed.
set -euo pipefail
cd "$(dirname "$0")/.."
status=0
scripts/build.sh
(cd build && ctest --output-on-failure -j2) || status=1
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRR_SANITIZE=ON -DRR_SIMD=OFF >/dev/null
cmake --build build-sanitize -j"$(nproc)"
# The same tests again under the sanitizers; property tests visit fewer views there.
(cd build-sanitize && RR_TEST_QUICK=1 ASAN_OPTIONS=detect_leaks=1 ctest --output-on-failure -j2) || status=1
# The thread-sanitizer build has only the tests labelled `threads` (CMakeLists.txt).
cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRR_TSAN=ON >/dev/null
cmake --build build-tsan -j"$(nproc)"
(cd build-tsan && RR_TEST_QUICK=1 ctest --output-on-failure -j2 -L threads) || status=1
# The fuzz targets (tests/fuzz): clang's libFuzzer with the address and undefined sanitizers.
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRR_FUZZ=ON -DRR_SIMD=OFF >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target fuzzers
(cd build-fuzz && ctest --output-on-failure -j2 -L fuzz) || status=1
exit $status
