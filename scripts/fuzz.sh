#!/usr/bin/env bash
# Builds the fuzz targets of fuzz/ with clang, libFuzzer, AddressSanitizer and
# UndefinedBehaviorSanitizer, and runs each for a while, starting from its checked-in corpus.
# Inputs that fail are saved as build-fuzz/crashes/<target>-crash-<sha1> (or -leak-, -timeout-,
# -oom-); copy them into fuzz/corpus/<target>/ once fixed, so ctest replays them from then on.
#
# Usage: scripts/fuzz.sh [SECONDS_PER_TARGET (default 60)] [TARGET...]   (default: every target)
# Environment: FUZZ_BUILD_DIR (default build-fuzz), JOBS (default: all cores).
# Exit status: 0 when no target failed, 1 otherwise.
set -euo pipefail

cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
BUILD_DIR=${FUZZ_BUILD_DIR:-build-fuzz}
JOBS=${JOBS:-$(nproc)}

scripts/install-deps.sh clang libclang-rt-14-dev >&2

targets=("$@")
if [[ ${#targets[@]} -eq 0 ]]; then
  for source in fuzz/*_fuzzer.cc; do targets+=("$(basename "${source}" .cc)"); done
fi

echo "==> Building ${targets[*]} into ${BUILD_DIR}/" >&2
generator=()
[[ -f "${BUILD_DIR}/CMakeCache.txt" ]] || { command -v ninja >/dev/null && generator=(-G Ninja); }
CXX=clang++ cmake -S . -B "${BUILD_DIR}" "${generator[@]}" -DNEURALMESH_FUZZ=ON \
  -DNEURALMESH_BUILD_TESTS=OFF -DNEURALMESH_BUILD_BENCH=OFF >/dev/null
cmake --build "${BUILD_DIR}" -j "${JOBS}" --target "${targets[@]}"

mkdir -p "${BUILD_DIR}/crashes"
failed=()
for target in "${targets[@]}"; do
  # New inputs go to the first directory; the checked-in corpus is only read.
  corpus="${BUILD_DIR}/corpus/${target}"
  mkdir -p "${corpus}"
  dictionary=()
  [[ -f "fuzz/dictionaries/${target}.dict" ]] && dictionary=(-dict="fuzz/dictionaries/${target}.dict")
  echo "==> ${target}: ${seconds} s" >&2
  if ! "${BUILD_DIR}/bin/${target}" "${corpus}" "fuzz/corpus/${target}" "${dictionary[@]}" \
      -max_total_time="${seconds}" -timeout=10 -rss_limit_mb=2048 -max_len=16384 \
      -print_final_stats=1 -artifact_prefix="${BUILD_DIR}/crashes/${target}-" \
      > "${BUILD_DIR}/${target}.log" 2>&1; then
    failed+=("${target}")
    grep -E "ERROR|FUZZ_CHECK|SUMMARY|Test unit written" "${BUILD_DIR}/${target}.log" >&2 || true
  fi
  grep -E "^stat::number_of_executed_units|^#[0-9]+.*DONE" "${BUILD_DIR}/${target}.log" | tail -2 >&2 || true
done

if [[ ${#failed[@]} -gt 0 ]]; then
  echo "FAIL: ${failed[*]} (inputs in ${BUILD_DIR}/crashes/, logs in ${BUILD_DIR}/<target>.log)" >&2
  exit 1
fi
echo "PASS: ${#targets[@]} targets, ${seconds} s each, no failure" >&2
