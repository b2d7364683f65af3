#!/usr/bin/env bash
# Builds everything and runs every test: the GoogleTest suites and the Python client test
# through ctest, then the concurrency-labelled tests once more under ThreadSanitizer (a
# core-only build, so it stays quick).
#
# Usage: scripts/test.sh            (from anywhere; paths are relative to the repository)
# Environment: BUILD_DIR (default build), TSAN_BUILD_DIR (default build-tsan),
#              JOBS (default: all cores), SKIP_TSAN=1 to skip the ThreadSanitizer pass.
set -euo pipefail

cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
TSAN_BUILD_DIR=${TSAN_BUILD_DIR:-build-tsan}
JOBS=${JOBS:-$(nproc)}
generator=()
command -v ninja >/dev/null 2>&1 && generator=(-G Ninja)

configure() {  # configure DIR [CMAKE ARGS...]; keeps an existing build's generator
  local dir=$1
  shift
  if [[ -f "${dir}/CMakeCache.txt" ]]; then
    cmake -S . -B "${dir}" "$@" >/dev/null
  else
    cmake -S . -B "${dir}" "${generator[@]}" "$@" >/dev/null
  fi
}

echo "==> Building into ${BUILD_DIR}/" >&2
configure "${BUILD_DIR}"
cmake --build "${BUILD_DIR}" -j "${JOBS}"

echo "==> Running the test suites" >&2
(cd "${BUILD_DIR}" && ctest --output-on-failure -j "${JOBS}" --timeout 900)

if [[ "${SKIP_TSAN:-0}" != 1 ]]; then
  echo "==> Running the concurrency tests under ThreadSanitizer (${TSAN_BUILD_DIR}/)" >&2
  configure "${TSAN_BUILD_DIR}" -DNEURALMESH_CORE_ONLY=ON -DNEURALMESH_TSAN=ON \
    -DNEURALMESH_BUILD_BENCH=OFF
  tsan_tests=$(cd tests && find core -name '*concurrent*_test.cc' -exec basename {} .cc \;)
  # shellcheck disable=SC2086
  cmake --build "${TSAN_BUILD_DIR}" -j "${JOBS}" --target ${tsan_tests}
  (cd "${TSAN_BUILD_DIR}" && TSAN_OPTIONS=halt_on_error=1 ctest --output-on-failure -L concurrency)
fi
