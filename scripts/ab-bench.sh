#!/usr/bin/env bash
# Compares two builds (or two settings) of the learner on this machine, whose speed drifts by up
# to 1.7 times within minutes: runs `A` and `B` (each a learner-bench command line, with its own
# flags or environment) side by side on one core, in turns of 20,000 Basic Steps, so that both
# meet the same moments of the machine. Prints us/step per band of vertex counts for each and
# B's time over A's, and whether their final meshes are the same.
#
# Usage: scripts/ab-bench.sh 'A COMMAND' 'B COMMAND' [learner-bench flags for both...]
# Example (a baseline build against this one):
#   scripts/ab-bench.sh /tmp/base/build/bin/learner-bench build/bin/learner-bench \
#       --points=5000000 --milestones=1000,20000,50000,100000
# Environment: CPU (default 0), the core both run on.
set -euo pipefail

if [[ $# -lt 2 ]]; then
  sed -n '2,12p' "$0" >&2
  exit 2
fi
a=$1
b=$2
shift 2
dir=$(mktemp -d)
trap 'rm -rf "${dir}"' EXIT
mkfifo "${dir}/to_a" "${dir}/to_b"

# shellcheck disable=SC2086  # The commands are word-split on purpose (flags, env VAR=value).
taskset -c "${CPU:-0}" env ${a} "$@" --turns="${dir}/to_a,${dir}/to_b" >"${dir}/a.txt" &
pid_a=$!
# shellcheck disable=SC2086
taskset -c "${CPU:-0}" env ${b} "$@" --turns="${dir}/to_b,${dir}/to_a" >"${dir}/b.txt" &
pid_b=$!
printf 't' >"${dir}/to_a"  # A takes the first turn.
status=0
wait "${pid_a}" || status=1
wait "${pid_b}" || status=1
if [[ ${status} -ne 0 ]]; then
  echo "ab-bench: a run failed" >&2
  cat "${dir}/a.txt" "${dir}/b.txt" >&2
  exit 1
fi

printf '%10s %17s %11s %11s %11s %7s\n' points vertices steps "A us/step" "B us/step" "B/A"
join -j1 <(awk '$1 == "band" {print $2 "/" $3, $4, $5}' "${dir}/a.txt" | sort) \
  <(awk '$1 == "band" {print $2 "/" $3, $5}' "${dir}/b.txt" | sort) |
  sort -t/ -k1,1n -k2,2n |
  awk '{split($1, key, "/"); printf "%10s %17s %11s %11.3f %11.3f %7.3f\n", key[1], key[2], $2, $3, $4, $4 / $3}'
join -j1 <(awk '$1 == "fingerprint" {print $2, $3}' "${dir}/a.txt" | sort) \
  <(awk '$1 == "fingerprint" {print $2, $3}' "${dir}/b.txt" | sort) |
  awk '{printf "%10s points: fingerprints %s and %s%s\n", $1, $2, $3, ($2 == $3 ? "" : ": DIFFERENT MESHES")}'
