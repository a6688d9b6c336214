#!/usr/bin/env bash
# Sets up (Debian packages), builds and runs the default test suite: unit + verification
# tests (about a quarter of an hour on 2 cores). Long validation runs are labelled
# `validation`; run them with:  ctest --test-dir build -L validation
#
#   scripts/run-tests.sh              Release build in build/, ctest -LE validation
#   scripts/run-tests.sh --sanitize   also builds the unit tests with ASan+UBSan in build-asan/
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
jobs=$(nproc 2>/dev/null || echo 2)

bash scripts/setup-debian.sh
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs"
ctest --test-dir build -LE validation --output-on-failure -j"$jobs"

if [ "${1:-}" = "--sanitize" ]; then
  # The unit tests only (fast); benchmarks are not built in this tree.
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVALVEFSI_SANITIZE=ON -DVALVEFSI_BUILD_BENCH=OFF
  cmake --build build-asan -j"$jobs"
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-asan -L unit --output-on-failure -j"$jobs"
fi
