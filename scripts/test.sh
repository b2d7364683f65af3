#!/usr/bin/env bash
# Builds everything and runs every test: the GoogleTest suites and the Python client test
# through ctest, then the concurrency-labelled tests once more under ThreadSanitizer, and the
# core tests (all but the minutes-long acceptance runs) under AddressSanitizer and
# UndefinedBehaviorSanitizer (core-only builds, so they stay quick).
#
# Usage: scripts/test.sh            (from anywhere; paths are relative to the repository)
# Environment: BUILD_DIR (default build), TSAN_BUILD_DIR (default build-tsan),
#              ASAN_BUILD_DIR (default build-asan), JOBS (default: all cores),
#              SKIP_TSAN=1 / SKIP_ASAN=1 to skip the ThreadSanitizer / AddressSanitizer pass.
set -euo pipefail

cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
TSAN_BUILD_DIR=${TSAN_BUILD_DIR:-build-tsan}
ASAN_BUILD_DIR=${ASAN_BUILD_DIR:-build-asan}
JOBS=${JOBS:-$(nproc)}
generator=()
command -v ninja >/dev/null 2>&1 && generator=(-G Ninja)

phase() {  # phase MESSAGE: what starts now, and the seconds since the script began
  echo "==> $1 (at ${SECONDS} s)" >&2
}

configure() {  # configure DIR [CMAKE ARGS...]; keeps an existing build's generator
  local dir=$1
  shift
  if [[ -f "${dir}/CMakeCache.txt" ]]; then
    cmake -S . -B "${dir}" "$@" >/dev/null
  else
    cmake -S . -B "${dir}" "${generator[@]}" "$@" >/dev/null
  fi
}

phase "Building into ${BUILD_DIR}/"
configure "${BUILD_DIR}"
cmake --build "${BUILD_DIR}" -j "${JOBS}"

phase "Running the test suites"
(cd "${BUILD_DIR}" && ctest --output-on-failure -j "${JOBS}" --timeout 900)

if [[ "${SKIP_TSAN:-0}" != 1 ]]; then
  phase "Running the concurrency tests under ThreadSanitizer (${TSAN_BUILD_DIR}/)"
  configure "${TSAN_BUILD_DIR}" -DNEURALMESH_CORE_ONLY=ON -DNEURALMESH_TSAN=ON \
    -DNEURALMESH_BUILD_BENCH=OFF
  tsan_tests=$(cd tests && find core -name '*concurrent*_test.cc' -exec basename {} .cc \;)
  # shellcheck disable=SC2086
  cmake --build "${TSAN_BUILD_DIR}" -j "${JOBS}" --target ${tsan_tests}
  (cd "${TSAN_BUILD_DIR}" && TSAN_OPTIONS=halt_on_error=1 ctest --output-on-failure -L concurrency)
fi

if [[ "${SKIP_ASAN:-0}" != 1 ]]; then
  phase "Running the core tests under AddressSanitizer and UBSan (${ASAN_BUILD_DIR}/)"
  configure "${ASAN_BUILD_DIR}" -DNEURALMESH_CORE_ONLY=ON -DNEURALMESH_SANITIZE=ON \
    -DNEURALMESH_BUILD_BENCH=OFF
  cmake --build "${ASAN_BUILD_DIR}" -j "${JOBS}"
  (cd "${ASAN_BUILD_DIR}" && ctest --output-on-failure -j "${JOBS}" -LE acceptance --timeout 900)
fi
phase "All passed"
