#!/usr/bin/env bash
# Uploading a large point file to neuralmesh-server, read whole against read where it lies
# (`neuralmesh reconstruct --server --off_core`). off-core-bench writes a LAS file of POINTS
# points of a torus in UTM coordinates; a server on a free port of 127.0.0.1 takes it, once
# each way, learning to VERTICES vertices. Prints for each way, from the command's start: when
# the session is created (the input is loaded or mapped), when the first mesh arrives, when the
# final mesh arrives (every point uploaded, then the finish), and the client's peak memory:
# anonymous (its own allocations, sampled every 20 ms) and resident (with the file's pages).
# With COLD=1 the file is dropped from the page cache before each way, as a file on the disk;
# with LAZ=1 the file is compressed to LAZ first (`neuralmesh convert`), which off-core is
# decoded a chunk at a time. A LAS file is also piped into `neuralmesh reconstruct -` (stdin),
# its records streamed as they arrive.
#
# Usage: scripts/upload-bench.sh   (after the build; from anywhere)
# Environment: BUILD_DIR (default build), POINTS (default 20000000), VERTICES (default 2000),
#              COLD (default 0), LAZ (default 0), FILE (default /tmp/upload-bench.las, removed
#              afterwards with its .laz).
set -euo pipefail

cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
POINTS=${POINTS:-20000000}
VERTICES=${VERTICES:-2000}
COLD=${COLD:-0}
LAZ=${LAZ:-0}
FILE=${FILE:-/tmp/upload-bench.las}
CLI="${BUILD_DIR}/bin/neuralmesh"
SERVER="${BUILD_DIR}/bin/neuralmesh-server"

WORK=$(mktemp -d)
SERVER_PID=""
cleanup() {
  if [[ -n "${SERVER_PID}" ]]; then kill -TERM "${SERVER_PID}" 2>/dev/null || true; fi
  wait 2>/dev/null || true
  rm -rf "${WORK}" "${FILE}"
  if [[ "${LAZ}" == 1 ]]; then rm -f "${FILE%.*}.laz"; fi
}
trap cleanup EXIT

"${BUILD_DIR}/bin/off-core-bench" --points="${POINTS}" --file="${FILE}" --write_only
INPUT="${FILE}"
if [[ "${LAZ}" == 1 ]]; then
  INPUT="${FILE%.*}.laz"
  "${CLI}" convert "${FILE}" -o "${INPUT}" >/dev/null
  echo "compressed to ${INPUT} ($(( $(stat -c %s "${INPUT}") / 1000000 )) MB)"
fi

"${SERVER}" --host=127.0.0.1 --port=0 --log_sessions=false >"${WORK}/server.out" \
  2>"${WORK}/server.err" &
SERVER_PID=$!
PORT=""
for _ in $(seq 1 300); do
  PORT=$(sed -n 's/.*listening on [^ ]*:\([0-9][0-9]*\).*/\1/p' "${WORK}/server.out" | head -n 1)
  [[ -n "${PORT}" ]] && break
  sleep 0.1
done
[[ -n "${PORT}" ]] || { echo "neuralmesh-server did not start" >&2; exit 1; }
ADDRESS="127.0.0.1:${PORT}"

# Prints "seconds line" for each line of standard input, seconds counted from $1.
stamp() {
  local start=$1 line
  while IFS= read -r line; do
    printf '%s %s\n' "$(awk -v now="$(date +%s.%N)" -v start="${start}" \
      'BEGIN { printf "%.3f", now - start }')" "${line}"
  done
}

# The first stamp of a line that matches $2 in the stamped output $1, or "-".
when() { awk -v pattern="$2" '$0 ~ pattern { printf "%.2f", $1; found = 1; exit }
                              END { if (!found) printf "-" }' "$1"; }

printf '%-12s %10s %12s %12s %14s %13s\n' "way" "session s" "first mesh s" "final s" \
  "anonymous MB" "resident MB"
ways=("read whole" "off-core")
[[ "${LAZ}" == 1 ]] || ways+=("stdin")  # LAS piped in; LAZ cannot be decoded as it arrives.
for way in "${ways[@]}"; do
  source_file="${INPUT}"
  flags=()
  [[ "${way}" == "off-core" ]] && flags=(--off_core)
  if [[ "${way}" == "stdin" ]]; then source_file="-"; fi
  if [[ "${COLD}" == 1 ]]; then dd if="${INPUT}" iflag=nocache count=0 status=none; fi
  rm -rf "${WORK}/out"
  start=$(date +%s.%N)
  "${CLI}" reconstruct "${source_file}" --server "${ADDRESS}" --out-dir "${WORK}/out" \
    --vertices "${VERTICES}" "${flags[@]}" <"${INPUT}" \
    > >(stamp "${start}" >"${WORK}/run.out") &
  pid=$!
  peak_anon=0
  peak_rss=0
  while kill -0 "${pid}" 2>/dev/null; do
    if status=$(cat "/proc/${pid}/status" 2>/dev/null); then
      anon=$(awk '/^RssAnon:/ { print $2 }' <<<"${status}")
      rss=$(awk '/^VmHWM:/ { print $2 }' <<<"${status}")
      [[ -n "${anon}" && "${anon}" -gt "${peak_anon}" ]] && peak_anon=${anon}
      [[ -n "${rss}" && "${rss}" -gt "${peak_rss}" ]] && peak_rss=${rss}
    fi
    sleep 0.02
  done
  wait "${pid}"
  sleep 0.2  # The stamping of the last lines.
  printf '%-12s %10s %12s %12s %14d %13d\n' "${way}" \
    "$(when "${WORK}/run.out" ' session s-')" "$(when "${WORK}/run.out" ' lod ')" \
    "$(when "${WORK}/run.out" ' final mesh:')" $((peak_anon / 1024)) $((peak_rss / 1024))
done
