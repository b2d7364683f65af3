#!/usr/bin/env bash
# Builds the container image from docker/Dockerfile with podman and tests it end to end, on a
# Debian 12 machine without a Docker engine, where podman works with a few adjustments:
#   1. installs podman, runc and debootstrap (and the project's build dependencies) when missing;
#   2. creates the base image docker.io/library/debian:bookworm-slim from Debian's own packages
#      (debootstrap + podman import) when it is not there, since no registry can be reached;
#   3. builds the image (podman build --isolation=chroot; cached layers make re-runs cheap);
#   4. runs it with its port published on 127.0.0.1 only, at a free host port, and waits for the
#      standard gRPC health service (grpc.health.v1) to report SERVING;
#   5. reconstructs builtin:torus through the container with the host's client
#      (build/bin/neuralmesh, built when missing) and decodes the final .drc with Debian's
#      draco_decoder and `neuralmesh stats`; reads the metrics page (--metrics_port, published
#      on 127.0.0.1 too): the session finished, its points accepted, the calls counted;
#   6. stops the container with SIGTERM (podman stop) and checks that the server shut down
#      gracefully (exit status 0, shutdown messages in its log); starts it again and checks
#      that the finished session came back from the state volume (--state_dir), its final
#      mesh served byte for byte as before;
#   7. runs it again secured, with TLS and an access token from a read-only mount (throw-away
#      certificates made with openssl): plaintext and token-less calls are refused, a client
#      with the CA and the token reconstructs a torus, the metrics page answers over HTTPS
#      with its own token (--metrics_tls, --metrics_token_file) and 401 without it, and after
#      `podman kill -s HUP` with a new tokens file and a certificate from another CA copied
#      over the old ones, only the new token and the new certificate are accepted (the metrics
#      page presents the new certificate too).
# The containers are always removed at the end. The Dockerfile itself stays standard: every
# podman adjustment (containers.conf, chroot isolation, the imported base image) lives here.
#
# Usage: scripts/container-test.sh      (as root; from anywhere, paths are relative to the repo)
# Environment: IMAGE (default localhost/neuralmesh:latest), BUILD_DIR (host build, default
#              build), JOBS (host build jobs, default: all cores), VERTICES (default 2000),
#              OUT_DIR (logs and meshes, default out/container-test).
# Prints a PASS/FAIL summary; exits non-zero, naming the failed step, on any failure.
set -euo pipefail

cd "$(dirname "$0")/.."
IMAGE=${IMAGE:-localhost/neuralmesh:latest}
BUILD_DIR=${BUILD_DIR:-build}
JOBS=${JOBS:-$(nproc)}
VERTICES=${VERTICES:-2000}
OUT_DIR=${OUT_DIR:-out/container-test}
BASE_IMAGE=docker.io/library/debian:bookworm-slim
CONTAINER_PORT=50051  # the port the image's ENTRYPOINT listens on
CONTAINER_METRICS_PORT=9464  # and its metrics page
# Debian's interpreter, where python3-grpcio lives; an earlier python3 on PATH may lack it.
PYTHON=/usr/bin/python3
CLI="${BUILD_DIR}/bin/neuralmesh"

STARTED_AT=$(date +%s)
STEP="start"
CONTAINER=""
ROOTFS=""
WORK_DIR=""
IMAGE_BUILD_SECONDS="-"
IMAGE_SIZE="-"

say() { printf '==> %s\n' "$*" >&2; }
step() {  # step NAME: what is being done now, named by the FAIL summary if it goes wrong
  STEP=$1
  say "$1"
}
fail() {
  printf 'container-test: %s failed: %s\n' "${STEP}" "$*" >&2
  exit 1
}

cleanup() {
  local status=$?
  trap - EXIT INT TERM
  if [[ -n "${CONTAINER}" ]]; then
    if [[ ${status} -ne 0 ]]; then
      say "Last lines of the container's log:"
      podman logs "${CONTAINER}" 2>&1 | tail -n 20 >&2 || true
    fi
    podman rm -f -v "${CONTAINER}" >/dev/null 2>&1 || true
  fi
  [[ -n "${ROOTFS}" ]] && rm -rf "${ROOTFS}"
  [[ -n "${WORK_DIR}" ]] && rm -rf "${WORK_DIR}"
  local total=$(($(date +%s) - STARTED_AT))
  echo
  if [[ ${status} -eq 0 ]]; then
    echo "container-test: PASS (image build ${IMAGE_BUILD_SECONDS} s, whole script ${total} s," \
      "image ${IMAGE} ${IMAGE_SIZE})"
  else
    echo "container-test: FAIL at step: ${STEP} (exit ${status}, after ${total} s;" \
      "logs in ${OUT_DIR}/)"
  fi
  exit "${status}"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

[[ "$(id -u)" -eq 0 ]] || fail "run as root (podman runs rootful here, debootstrap needs root)"
rm -rf "${OUT_DIR}"
mkdir -p "${OUT_DIR}"
WORK_DIR=$(mktemp -d -t neuralmesh-container.XXXXXX)

# --- 1. Packages ---------------------------------------------------------------------------
step "Checking packages (podman, runc, debootstrap and the build dependencies)"
scripts/install-deps.sh podman runc debootstrap >&2 || fail "installing packages"

# The sandboxes of these machines refuse podman's default resource limits, their cgroup
# layout is hybrid, and podman is to use runc (installed above): a containers.conf of our own.
cat >"${WORK_DIR}/containers.conf" <<'EOF'
[containers]
default_ulimits = []

[engine]
cgroup_manager = "cgroupfs"
runtime = "runc"
EOF
export CONTAINERS_CONF="${WORK_DIR}/containers.conf"

# --- 2. Base image -------------------------------------------------------------------------
if podman image exists "${BASE_IMAGE}"; then
  say "Base image ${BASE_IMAGE} present"
else
  step "Creating the base image ${BASE_IMAGE} with debootstrap (no registry here)"
  ROOTFS=$(mktemp -d /var/tmp/neuralmesh-rootfs.XXXXXX)
  debootstrap --variant=minbase bookworm "${ROOTFS}" http://deb.debian.org/debian \
    >"${OUT_DIR}/debootstrap.log" 2>&1 || fail "debootstrap (see ${OUT_DIR}/debootstrap.log)"
  # Make it behave like the official slim image, so that a standard Dockerfile gives the same
  # result here: its apt sources (with updates and security), its apt settings that keep no
  # package cache in a layer, and the slim variant's dpkg excludes (no docs, man pages,
  # translations).
  rm -f "${ROOTFS}/etc/apt/sources.list"
  cat >"${ROOTFS}/etc/apt/sources.list.d/debian.sources" <<'EOF'
Types: deb
URIs: http://deb.debian.org/debian
Suites: bookworm bookworm-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg

Types: deb
URIs: http://deb.debian.org/debian-security
Suites: bookworm-security
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
EOF
  apt_conf="${ROOTFS}/etc/apt/apt.conf.d"
  cat >"${apt_conf}/docker-clean" <<'EOF'
DPkg::Post-Invoke { "rm -f /var/cache/apt/archives/*.deb /var/cache/apt/archives/partial/*.deb /var/cache/apt/*.bin || true"; };
APT::Update::Post-Invoke { "rm -f /var/cache/apt/archives/*.deb /var/cache/apt/archives/partial/*.deb /var/cache/apt/*.bin || true"; };
Dir::Cache::pkgcache "";
Dir::Cache::srcpkgcache "";
EOF
  echo 'Acquire::Languages "none";' >"${apt_conf}/docker-no-languages"
  echo 'Acquire::GzipIndexes "true";' >"${apt_conf}/docker-gzip-indexes"
  echo 'Apt::AutoRemove::SuggestsImportant "false";' >"${apt_conf}/docker-autoremove-suggests"
  echo 'force-unsafe-io' >"${ROOTFS}/etc/dpkg/dpkg.cfg.d/docker-apt-speedup"
  cat >"${ROOTFS}/etc/dpkg/dpkg.cfg.d/docker" <<'EOF'
path-exclude /usr/share/doc/*
path-include /usr/share/doc/*/copyright
path-exclude /usr/share/groff/*
path-exclude /usr/share/info/*
path-exclude /usr/share/linda/*
path-exclude /usr/share/lintian/overrides/*
path-exclude /usr/share/locale/*
path-exclude /usr/share/man/*
EOF
  find "${ROOTFS}/usr/share/doc" -mindepth 1 -not -type d -not -name copyright -delete
  find "${ROOTFS}/usr/share/doc" -mindepth 1 -type d -empty -delete
  rm -rf "${ROOTFS}"/usr/share/{groff,info,linda,lintian/overrides,locale,man}/*
  rm -rf "${ROOTFS}"/var/cache/apt/archives/*.deb "${ROOTFS}"/var/cache/apt/*.bin \
    "${ROOTFS}"/var/lib/apt/lists/*
  tar -C "${ROOTFS}" -c . | podman import --quiet --change 'CMD ["bash"]' - "${BASE_IMAGE}" \
    >/dev/null || fail "podman import of the debootstrap root file system"
  rm -rf "${ROOTFS}"
  ROOTFS=""
fi

# --- 3. Image ------------------------------------------------------------------------------
step "Building ${IMAGE} from docker/Dockerfile (log: ${OUT_DIR}/image-build.log)"
build_start=$(date +%s)
if ! podman build --isolation=chroot -f docker/Dockerfile -t "${IMAGE}" . \
  >"${OUT_DIR}/image-build.log" 2>&1; then
  tail -n 30 "${OUT_DIR}/image-build.log" >&2
  fail "podman build (see ${OUT_DIR}/image-build.log)"
fi
IMAGE_BUILD_SECONDS=$(($(date +%s) - build_start))
IMAGE_SIZE=$(podman images --format '{{.Size}}' "${IMAGE}" | head -n 1)
say "Image built in ${IMAGE_BUILD_SECONDS} s, ${IMAGE_SIZE}"
image_user=$(podman image inspect --format '{{.Config.User}}' "${IMAGE}")
[[ -n "${image_user}" && "${image_user%%:*}" != root && "${image_user%%:*}" != 0 ]] \
  || fail "the image runs as '${image_user:-root}', not as an unprivileged user"

# --- 4. Host client ------------------------------------------------------------------------
step "Building the host client ${CLI}"
if [[ -f "${BUILD_DIR}/CMakeCache.txt" ]]; then
  cmake -S . -B "${BUILD_DIR}" >/dev/null || fail "cmake configure"
elif command -v ninja >/dev/null 2>&1; then
  cmake -S . -B "${BUILD_DIR}" -G Ninja >/dev/null || fail "cmake configure"
else
  cmake -S . -B "${BUILD_DIR}" >/dev/null || fail "cmake configure"
fi
cmake --build "${BUILD_DIR}" --target neuralmesh -j "${JOBS}" >"${OUT_DIR}/client-build.log" 2>&1 \
  || fail "building the client (see ${OUT_DIR}/client-build.log)"

# --- 5. Run --------------------------------------------------------------------------------
step "Starting the container on 127.0.0.1"
free_port() {
  "${PYTHON}" -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}
# start_container NAME [PODMAN_RUN_OPTION...] -- [SERVER_FLAG...]: runs the image as
# CONTAINER=NAME with its ports published on 127.0.0.1 at free ports; sets ADDRESS and
# METRICS_ADDRESS.
start_container() {
  CONTAINER=$1
  shift
  local options=()
  while [[ $# -gt 0 && "$1" != "--" ]]; do
    options+=("$1")
    shift
  done
  [[ $# -gt 0 ]] && shift
  local port="" metrics_port=""
  # The ports are free when picked; should another process take one before podman binds it,
  # pick others.
  for _ in 1 2 3; do
    port=$(free_port)
    metrics_port=$(free_port)
    [[ "${metrics_port}" != "${port}" ]] || continue
    if podman run -d --name "${CONTAINER}" -p "127.0.0.1:${port}:${CONTAINER_PORT}" \
      -p "127.0.0.1:${metrics_port}:${CONTAINER_METRICS_PORT}" \
      "${options[@]}" "${IMAGE}" "$@" >/dev/null 2>"${WORK_DIR}/run.err"; then
      break
    fi
    podman rm -f -v "${CONTAINER}" >/dev/null 2>&1 || true
    port=""
  done
  [[ -n "${port}" ]] || fail "podman run: $(cat "${WORK_DIR}/run.err")"
  ADDRESS="127.0.0.1:${port}"
  METRICS_ADDRESS="127.0.0.1:${metrics_port}"
}
start_container "neuralmesh-test-$$" --

step "Waiting for grpc.health.v1 to report SERVING on ${ADDRESS}"
# grpc.health.v1.Health/Check with raw bytes, so no stubs are needed: a request naming a
# service is field 1 (string); the answer SERVING is field 1 (enum) = 1, i.e. bytes 08 01.
# A third argument, a CA's PEM file, makes it a TLS call (no token: health checks need none).
cat >"${WORK_DIR}/health.py" <<'EOF'
import sys

import grpc

target, service = sys.argv[1], sys.argv[2].encode()
request = b"\x0a" + bytes([len(service)]) + service if service else b""
if len(sys.argv) > 3:
    with open(sys.argv[3], "rb") as ca:
        channel = grpc.secure_channel(target, grpc.ssl_channel_credentials(ca.read()))
else:
    channel = grpc.insecure_channel(target)
with channel:
    check = channel.unary_unary("/grpc.health.v1.Health/Check",
                                request_serializer=lambda b: b, response_deserializer=lambda b: b)
    try:
        answer = check(request, timeout=2, wait_for_ready=True)
    except grpc.RpcError as error:
        print("health check: %s" % error.code(), file=sys.stderr)
        sys.exit(1)
    if answer != b"\x08\x01":
        print("health check: not SERVING (answer %r)" % answer, file=sys.stderr)
        sys.exit(1)
EOF
# wait_serving [CA_FILE]: waits up to 60 s for CONTAINER's server to report SERVING.
wait_serving() {
  local healthy=0
  for _ in $(seq 1 60); do
    running=$(podman inspect --format '{{.State.Running}}' "${CONTAINER}" 2>/dev/null || echo false)
    [[ "${running}" == true ]] || fail "the container exited at start"
    if "${PYTHON}" "${WORK_DIR}/health.py" "${ADDRESS}" "" "$@" 2>"${WORK_DIR}/health.err" \
      && "${PYTHON}" "${WORK_DIR}/health.py" "${ADDRESS}" neuralmesh.v1.ReconstructionService \
        "$@" 2>"${WORK_DIR}/health.err"; then
      healthy=1
      break
    fi
    sleep 1
  done
  [[ ${healthy} -eq 1 ]] || fail "not SERVING within 60 s: $(cat "${WORK_DIR}/health.err")"
  say "SERVING on ${ADDRESS}: the server and neuralmesh.v1.ReconstructionService"
}
wait_serving

# --- 6. Reconstruction ---------------------------------------------------------------------
step "Reconstructing builtin:torus to ${VERTICES} vertices through the container"
MESH_DIR="${OUT_DIR}/meshes"
status=0
timeout 600 "${CLI}" reconstruct builtin:torus --server "${ADDRESS}" --out-dir "${MESH_DIR}" \
  --vertices "${VERTICES}" >"${OUT_DIR}/reconstruct.out" 2>"${OUT_DIR}/reconstruct.err" \
  || status=$?
cat "${OUT_DIR}/reconstruct.out" >&2
[[ ${status} -eq 0 ]] || fail "the client exited with ${status}: $(tail -n 5 "${OUT_DIR}/reconstruct.err")"
FINAL="${MESH_DIR}/torus.drc"
[[ -s "${FINAL}" ]] || fail "the client wrote no final mesh ${FINAL}"

step "Decoding ${FINAL}"
draco_decoder -i "${FINAL}" -o "${WORK_DIR}/final.obj" >"${OUT_DIR}/draco_decoder.log" 2>&1 \
  || fail "draco_decoder: $(tail -n 3 "${OUT_DIR}/draco_decoder.log")"
decoded_vertices=$(grep -c '^v ' "${WORK_DIR}/final.obj" || true)
decoded_faces=$(grep -c '^f ' "${WORK_DIR}/final.obj" || true)
[[ ${decoded_vertices} -gt 0 && ${decoded_faces} -gt 0 ]] \
  || fail "draco_decoder gave ${decoded_vertices} vertices and ${decoded_faces} faces"
"${CLI}" stats "${FINAL}" >"${OUT_DIR}/stats.out" 2>&1 \
  || fail "neuralmesh stats: $(tail -n 3 "${OUT_DIR}/stats.out")"
say "Final mesh: ${decoded_vertices} vertices, ${decoded_faces} faces (draco_decoder)"

step "Reading the metrics page on ${METRICS_ADDRESS}"
# get.py URL [CA_PEM [TOKEN_FILE]]: prints the body of GET URL, or the status and body of an
# HTTP error (exit 1); with a CA, over HTTPS checking the certificate against it; with a token
# file, as "Authorization: Bearer". urllib without the environment's proxies: the pages are on
# 127.0.0.1.
cat >"${WORK_DIR}/get.py" <<'EOF'
import ssl
import sys
import urllib.error
import urllib.request

handlers = [urllib.request.ProxyHandler({})]
if len(sys.argv) > 2:
    context = ssl.create_default_context(cafile=sys.argv[2])
    handlers.append(urllib.request.HTTPSHandler(context=context))
request = urllib.request.Request(sys.argv[1])
if len(sys.argv) > 3:
    with open(sys.argv[3]) as token:
        request.add_header("Authorization", "Bearer " + token.read().strip())
try:
    reply = urllib.request.build_opener(*handlers).open(request, timeout=10)
    sys.stdout.write(reply.read().decode())
except urllib.error.HTTPError as error:
    sys.stdout.write(f"HTTP {error.code}: {error.read().decode()}")
    sys.exit(1)
EOF
"${PYTHON}" "${WORK_DIR}/get.py" "http://${METRICS_ADDRESS}/metrics" >"${OUT_DIR}/metrics.txt" \
  2>"${WORK_DIR}/metrics.err" || fail "GET /metrics: $(tail -n 3 "${WORK_DIR}/metrics.err")"
for sample in 'neuralmesh_sessions_ended_total{state="finished"} 1' \
  'neuralmesh_points_accepted_total 100000' \
  'grpc_server_handled_total{grpc_service="neuralmesh.v1.ReconstructionService",grpc_method="CreateSession",grpc_type="unary",grpc_code="OK"} 1'; do
  grep -qxF "${sample}" "${OUT_DIR}/metrics.txt" || fail "/metrics lacks the line: ${sample}"
done
say "/metrics: the finished session, its 100000 points and its calls are counted"

# --- 7. Graceful stop ----------------------------------------------------------------------
step "Stopping the container with SIGTERM"
podman stop --time 30 "${CONTAINER}" >/dev/null || fail "podman stop"
exit_code=$(podman inspect --format '{{.State.ExitCode}}' "${CONTAINER}")
podman logs "${CONTAINER}" >"${OUT_DIR}/server.log" 2>&1
[[ "${exit_code}" == 0 ]] || fail "the server exited with status ${exit_code}, not 0"
grep -q 'SIGTERM received, shutting down' "${OUT_DIR}/server.log" \
  || fail "no 'SIGTERM received' in the server's log"
grep -q 'neuralmesh-server: stopped' "${OUT_DIR}/server.log" \
  || fail "no 'neuralmesh-server: stopped' in the server's log"
grep -q "finished: ${VERTICES} vertices" "${OUT_DIR}/server.log" \
  || fail "no 'finished: ${VERTICES} vertices' event in the server's log"
say "The server shut down gracefully (exit status 0)"

# --- 7b. Restart ---------------------------------------------------------------------------
step "Starting the container again: the finished session comes back from its state volume"
podman start "${CONTAINER}" >/dev/null || fail "podman start"
wait_serving
# The server answers while it restores its sessions; until then a listing is UNAVAILABLE, and
# `neuralmesh sessions` asks again (--reconnect_for).
"${CLI}" sessions --server "${ADDRESS}" --reconnect_for 30s \
  >"${OUT_DIR}/sessions-after-restart.out" 2>"${OUT_DIR}/sessions-after-restart.err" \
  || fail "neuralmesh sessions: $(tail -n 3 "${OUT_DIR}/sessions-after-restart.err")"
grep -q "^session " "${OUT_DIR}/sessions-after-restart.out" \
  || fail "neuralmesh sessions printed no table: $(tail -n 3 "${OUT_DIR}/sessions-after-restart.out")"
cat "${OUT_DIR}/sessions-after-restart.out" >&2
SESSION_ID=$(awk '$1 ~ /^s-/ && $3 == "finished" {print $1}' "${OUT_DIR}/sessions-after-restart.out")
[[ -n "${SESSION_ID}" ]] || fail "no finished session after the restart"
WATCH_DIR="${WORK_DIR}/watched"
timeout 120 "${CLI}" watch "${SESSION_ID}" --server "${ADDRESS}" --out-dir "${WATCH_DIR}" \
  >"${OUT_DIR}/watch-after-restart.out" 2>&1 \
  || fail "neuralmesh watch: $(tail -n 3 "${OUT_DIR}/watch-after-restart.out")"
cmp -s "${WATCH_DIR}/${SESSION_ID}.drc" "${FINAL}" \
  || fail "the final mesh served after the restart differs from ${FINAL}"
podman stop --time 30 "${CONTAINER}" >/dev/null || fail "podman stop"
podman logs "${CONTAINER}" >"${OUT_DIR}/server.log" 2>&1
grep -q "${SESSION_ID} restored after a restart: .* finished" "${OUT_DIR}/server.log" \
  || fail "no 'restored after a restart' event in the server's log"
say "Session ${SESSION_ID} came back finished, its final mesh byte for byte"
podman rm -v "${CONTAINER}" >/dev/null
CONTAINER=""

# --- 8. Secured run ------------------------------------------------------------------------
step "Making throw-away TLS certificates and tokens for a secured run"
SECRETS="${WORK_DIR}/secrets"
mkdir -p "${SECRETS}"
(
  cd "${SECRETS}"
  openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -days 1 \
    -subj /CN=neuralmesh-container-test-ca -keyout ca.key -out ca.pem
  openssl req -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes \
    -subj /CN=neuralmesh-container-test -keyout server.key -out server.csr
  printf 'subjectAltName=IP:127.0.0.1,DNS:localhost\n' >server.ext
  openssl x509 -req -in server.csr -CA ca.pem -CAkey ca.key -CAcreateserial -days 1 \
    -extfile server.ext -out server.pem
  # The renewal, from another CA, kept beside the mount until it is copied over.
  mkdir -p ../renewed
  openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -days 1 \
    -subj /CN=neuralmesh-container-test-ca-2 -keyout ../renewed/ca.key -out ../renewed/ca.pem
  openssl req -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes \
    -subj /CN=neuralmesh-container-test -keyout ../renewed/server.key -out ../renewed/server.csr
  openssl x509 -req -in ../renewed/server.csr -CA ../renewed/ca.pem -CAkey ../renewed/ca.key \
    -CAcreateserial -days 1 -extfile server.ext -out ../renewed/server.pem
) >"${OUT_DIR}/openssl.log" 2>&1 || fail "openssl (see ${OUT_DIR}/openssl.log)"
"${PYTHON}" -c 'import secrets; print(secrets.token_hex(24))' >"${WORK_DIR}/token"
"${PYTHON}" -c 'import secrets; print(secrets.token_hex(24))' >"${WORK_DIR}/new_token"
cp "${WORK_DIR}/token" "${SECRETS}/tokens.txt"
"${PYTHON}" -c 'import secrets; print(secrets.token_hex(24))' >"${SECRETS}/metrics_token"
# The server runs as an unprivileged user of the image: it must be able to read the mount.
chmod 755 "${SECRETS}"
chmod 644 "${SECRETS}"/*

step "Starting the container with TLS and an access token, its metrics page over HTTPS"
start_container "neuralmesh-test-secured-$$" -v "${SECRETS}:/secrets:ro" -- \
  --host=0.0.0.0 --port="${CONTAINER_PORT}" --tls_cert_file=/secrets/server.pem \
  --tls_key_file=/secrets/server.key --access_tokens_file=/secrets/tokens.txt \
  --metrics_tls --metrics_token_file=/secrets/metrics_token
wait_serving "${SECRETS}/ca.pem"
grep -q 'TLS, 1 access tokens' <(podman logs "${CONTAINER}" 2>&1) \
  || fail "the server's first line does not say 'TLS, 1 access tokens'"

step "Checking that plaintext and token-less calls are refused"
secured=(--server "${ADDRESS}" --tls_ca_file "${SECRETS}/ca.pem")
# expect_refused MESSAGE NEURALMESH_ARG...: the command fails and its stderr says MESSAGE.
expect_refused() {
  local message=$1
  shift
  if "${CLI}" "$@" >"${WORK_DIR}/refused.out" 2>"${WORK_DIR}/refused.err"; then
    fail "'neuralmesh $*' succeeded"
  fi
  grep -q "${message}" "${WORK_DIR}/refused.err" \
    || fail "'neuralmesh $*' did not say '${message}': $(cat "${WORK_DIR}/refused.err")"
}
expect_refused "does the server want TLS" sessions --server "${ADDRESS}" --connect_timeout 2s
expect_refused "requires an access token" sessions "${secured[@]}"

step "Reconstructing builtin:torus over TLS with the access token"
status=0
timeout 600 "${CLI}" reconstruct builtin:torus "${secured[@]}" --access_token_file \
  "${WORK_DIR}/token" --out-dir "${MESH_DIR}/secured" --vertices "${VERTICES}" \
  >"${OUT_DIR}/reconstruct-secured.out" 2>"${OUT_DIR}/reconstruct-secured.err" || status=$?
[[ ${status} -eq 0 ]] \
  || fail "the client exited with ${status}: $(tail -n 5 "${OUT_DIR}/reconstruct-secured.err")"
[[ -s "${MESH_DIR}/secured/torus.drc" ]] || fail "no final mesh over TLS"
say "Final mesh over TLS: $(tail -n 1 "${OUT_DIR}/reconstruct-secured.out")"

step "Reading the metrics page over HTTPS with its token"
"${PYTHON}" "${WORK_DIR}/get.py" "https://${METRICS_ADDRESS}/metrics" "${SECRETS}/ca.pem" \
  "${SECRETS}/metrics_token" >"${OUT_DIR}/metrics-secured.txt" 2>&1 \
  || fail "GET https://.../metrics: $(tail -n 3 "${OUT_DIR}/metrics-secured.txt")"
grep -qxF 'neuralmesh_sessions{state="finished"} 1' "${OUT_DIR}/metrics-secured.txt" \
  || fail "/metrics over HTTPS lacks the finished session"
if "${PYTHON}" "${WORK_DIR}/get.py" "https://${METRICS_ADDRESS}/metrics" "${SECRETS}/ca.pem" \
  >"${WORK_DIR}/no-token.out" 2>&1; then
  fail "/metrics answered without the token"
fi
grep -q "^HTTP 401" "${WORK_DIR}/no-token.out" \
  || fail "/metrics without the token: $(cat "${WORK_DIR}/no-token.out")"
say "/metrics over HTTPS: 200 with the token, 401 without"

step "Replacing the token and the certificate and sending SIGHUP"
cp "${WORK_DIR}/new_token" "${SECRETS}/tokens.txt"
cp "${WORK_DIR}/renewed/server.pem" "${WORK_DIR}/renewed/server.key" "${SECRETS}/"
chmod 644 "${SECRETS}"/*
podman kill -s HUP "${CONTAINER}" >/dev/null || fail "podman kill -s HUP"
# The tokens are read at once; the certificate after gRPC has taken it on a throw-away port.
for _ in $(seq 1 50); do
  logs=$(podman logs "${CONTAINER}" 2>&1)
  grep -q 'access tokens read again' <<<"${logs}" \
    && grep -q 'TLS certificate and key read again' <<<"${logs}" && break
  sleep 0.2
done
# From the captured log, not a pipe: grep -q would end podman logs with SIGPIPE, which
# pipefail turns into a failure.
grep -q '1 access tokens read again' <<<"${logs}" \
  || fail "the server did not say it read the tokens again"
grep -q 'TLS certificate and key read again' <<<"${logs}" \
  || fail "the server did not say it read the certificate again"
sleep 2  # gRPC takes the new certificate within a second.
expect_refused "certificate verify failed" sessions "${secured[@]}" --access_token_file \
  "${WORK_DIR}/new_token"
secured=(--server "${ADDRESS}" --tls_ca_file "${WORK_DIR}/renewed/ca.pem")
expect_refused "not one this server accepts" sessions "${secured[@]}" --access_token_file \
  "${WORK_DIR}/token"
"${CLI}" sessions "${secured[@]}" --access_token_file "${WORK_DIR}/new_token" \
  >"${OUT_DIR}/sessions-secured.out" 2>&1 || fail "the new token: $(cat "${OUT_DIR}/sessions-secured.out")"
grep -q finished "${OUT_DIR}/sessions-secured.out" || fail "the secured session is not listed"
"${PYTHON}" "${WORK_DIR}/get.py" "https://${METRICS_ADDRESS}/healthz" \
  "${WORK_DIR}/renewed/ca.pem" >"${WORK_DIR}/healthz.out" 2>&1 \
  || fail "the metrics page kept the old certificate: $(tail -n 3 "${WORK_DIR}/healthz.out")"
say "The old token and certificate are refused, the new ones accepted after SIGHUP (and on /metrics)"
podman stop --time 30 "${CONTAINER}" >/dev/null || fail "podman stop"
podman logs "${CONTAINER}" >"${OUT_DIR}/server-secured.log" 2>&1
podman rm -v "${CONTAINER}" >/dev/null
CONTAINER=""
STEP="done"
