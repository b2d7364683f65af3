#!/usr/bin/env bash
# The main job: builds everything (CLI, server, tests, benchmarks), starts neuralmesh-server on
# a free port of 127.0.0.1, reconstructs the built-in torus through it (100000 points sampled
# from the implicit surface, streamed in batches; 5000 vertices), writes every level of detail
# to out/demo as .drc, .ply and .glb, prints the LOD table and stops the server.
#
# Usage: scripts/run-demo.sh            (from anywhere; paths are relative to the repository)
# Environment: BUILD_DIR (default build), JOBS (parallel build jobs, default: all cores),
#              OUT_DIR (default out/demo), VERTICES (default 5000).
# Exits non-zero when the build, the server or the reconstruction fails.
set -euo pipefail

cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
JOBS=${JOBS:-$(nproc)}
OUT_DIR=${OUT_DIR:-out/demo}
VERTICES=${VERTICES:-5000}

say() { printf '==> %s\n' "$*" >&2; }

# --- Build -------------------------------------------------------------------------------
say "Configuring and building into ${BUILD_DIR}/"
if [[ -f "${BUILD_DIR}/CMakeCache.txt" ]]; then
  cmake -S . -B "${BUILD_DIR}" >/dev/null
elif command -v ninja >/dev/null 2>&1; then
  cmake -S . -B "${BUILD_DIR}" -G Ninja >/dev/null
else
  cmake -S . -B "${BUILD_DIR}" >/dev/null
fi
cmake --build "${BUILD_DIR}" -j "${JOBS}"
CLI="${BUILD_DIR}/bin/neuralmesh"
SERVER="${BUILD_DIR}/bin/neuralmesh-server"

# --- Server ------------------------------------------------------------------------------
LOG_DIR=$(mktemp -d)
SERVER_PID=""
cleanup() {
  local status=$?
  if [[ -n "${SERVER_PID}" ]] && kill -0 "${SERVER_PID}" 2>/dev/null; then
    say "Stopping neuralmesh-server (pid ${SERVER_PID})"
    kill -TERM "${SERVER_PID}" 2>/dev/null || true
    wait "${SERVER_PID}" 2>/dev/null || true
  fi
  if [[ ${status} -ne 0 && -s "${LOG_DIR}/server.err" ]]; then
    say "neuralmesh-server stderr:"
    cat "${LOG_DIR}/server.err" >&2
  fi
  rm -rf "${LOG_DIR}"
  exit "${status}"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# Port 0: the server binds a free port and prints it, so no other process can take it first.
"${SERVER}" --host=127.0.0.1 --port=0 >"${LOG_DIR}/server.out" 2>"${LOG_DIR}/server.err" &
SERVER_PID=$!
PORT=""
for _ in $(seq 1 300); do
  PORT=$(sed -n 's/.*listening on [^ ]*:\([0-9][0-9]*\).*/\1/p' "${LOG_DIR}/server.out" | head -n 1)
  [[ -n "${PORT}" ]] && break
  kill -0 "${SERVER_PID}" 2>/dev/null || { say "neuralmesh-server exited at start"; exit 1; }
  sleep 0.1
done
[[ -n "${PORT}" ]] || { say "neuralmesh-server did not report its port within 30 s"; exit 1; }
ADDRESS="127.0.0.1:${PORT}"

# Healthy once it answers an rpc.
for _ in $(seq 1 50); do
  "${CLI}" sessions --server "${ADDRESS}" --connect_timeout 1s >/dev/null 2>&1 && break
  sleep 0.2
done
"${CLI}" sessions --server "${ADDRESS}" --connect_timeout 2s >/dev/null
say "neuralmesh-server is up on ${ADDRESS}"

# --- Reconstruction ----------------------------------------------------------------------
rm -rf "${OUT_DIR}"
say "Reconstructing builtin:torus to ${VERTICES} vertices through ${ADDRESS}"
"${CLI}" reconstruct builtin:torus --server "${ADDRESS}" --out-dir "${OUT_DIR}" \
  --vertices "${VERTICES}" --ply --glb | tee "${LOG_DIR}/reconstruct.out"

# The LOD table: the milestones and the final mesh (without the periodic refreshes).
echo
echo "Levels of detail written to ${OUT_DIR}:"
grep -E '^(kind|lod|final) ' "${LOG_DIR}/reconstruct.out"
echo
echo "To watch a reconstruction live in a browser: build/bin/neuralmesh view --server HOST:PORT,"
echo "then open http://127.0.0.1:8080/ (README, Watching in a browser)."
