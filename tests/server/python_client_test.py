#!/usr/bin/env python3
"""A neuralmesh.v1 client in Python, against the .proto only (not our C++ client).

Generates stubs with Debian's python3-grpc-tools into a temporary directory, then, against a
running server: checks the health service and server reflection, creates a session (with the
paper's early phase, which the session echoes; an invalid one is refused), uploads a
sphere in batches (client streaming), watches it (server streaming), finishes it, fetches the
final mesh, checks that a NaN batch is rejected with INVALID_ARGUMENT, runs one Reconstruct
call (bidirectional) and hands a session to another client. With --root_cert and --token it
does all of it over TLS with the access token, after checking that calls without the token
are UNAUTHENTICATED while the health service stays open. Exits 0 on success.

Usage: python_client_test.py --target=127.0.0.1:PORT --proto_root=proto
           [--root_cert=ca.pem --token=TOKEN]
"""
import argparse
import atexit
import math
import os
import random
import shutil
import struct
import subprocess
import sys
import tempfile
import threading


def generate_stubs(proto_root, out_dir):
    import grpc_tools
    well_known = os.path.join(os.path.dirname(grpc_tools.__file__), "_proto")
    command = [sys.executable, "-m", "grpc_tools.protoc", "-I", proto_root, "-I", well_known,
               "--python_out", out_dir, "--grpc_python_out", out_dir,
               os.path.join(proto_root, "neuralmesh", "v1", "reconstruction.proto")]
    subprocess.run(command, check=True)
    # Python packages for the generated module path neuralmesh/v1/.
    for package in ("neuralmesh", os.path.join("neuralmesh", "v1")):
        open(os.path.join(out_dir, package, "__init__.py"), "a").close()
    sys.path.insert(0, out_dir)


def sphere_points(n, seed):
    rng = random.Random(seed)
    out = bytearray()
    for _ in range(n):
        z = rng.uniform(-1.0, 1.0)
        phi = rng.uniform(0.0, 2.0 * math.pi)
        s = math.sqrt(1.0 - z * z)
        out += struct.pack("<3f", s * math.cos(phi), s * math.sin(phi), z)
    return bytes(out)


def color_of_position(x, y, z):
    """Each channel 255 (c + 1) / 2, as the C++ tests colour points (tests/testing/shapes.h)."""
    return tuple(min(255, max(0, round(255.0 * (c + 1.0) / 2.0))) for c in (x, y, z))


def colors_of(points):
    """PackedPoints.colors for packed positions: three bytes a point."""
    out = bytearray()
    for i in range(0, len(points), 12):
        out += bytes(color_of_position(*struct.unpack_from("<3f", points, i)))
    return bytes(out)


def ply_vertex_colors(path):
    """(x, y, z, r, g, b) of each vertex of a binary PLY of float x, y, z and uchar red, green,
    blue, as draco_decoder writes a coloured mesh."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode()
    check("property uchar red" in header, "the decoded mesh has no colours:\n" + header)
    count = int(header.split("element vertex ")[1].split()[0])
    return [struct.unpack_from("<3f3B", data, end + 15 * i) for i in range(count)]


def check(condition, message):
    if not condition:
        print("FAILED: " + message, file=sys.stderr)
        sys.exit(1)


def raw_unary(channel, method, request_bytes):
    call = channel.unary_unary(method, request_serializer=lambda b: b,
                               response_deserializer=lambda b: b)
    return call(request_bytes, timeout=10)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--target", required=True)
    parser.add_argument("--proto_root", required=True)
    parser.add_argument("--root_cert", help="PEM of the CA of a TLS server")
    parser.add_argument("--token", help="the access token of a server that asks for one")
    args = parser.parse_args()

    out_dir = tempfile.mkdtemp(prefix="nm_py_")
    atexit.register(shutil.rmtree, out_dir, ignore_errors=True)
    generate_stubs(args.proto_root, out_dir)
    import grpc
    from neuralmesh.v1 import reconstruction_pb2 as pb
    from neuralmesh.v1 import reconstruction_pb2_grpc as pb_grpc

    options = [("grpc.max_receive_message_length", 64 << 20)]
    if args.root_cert:
        with open(args.root_cert, "rb") as f:
            tls = grpc.ssl_channel_credentials(root_certificates=f.read())
        without_token = grpc.secure_channel(args.target, tls, options=options)
        grpc.channel_ready_future(without_token).result(timeout=10)
        check(raw_unary(without_token, "/grpc.health.v1.Health/Check", b"") == b"\x08\x01",
              "the health check needs no token")
        try:
            pb_grpc.ReconstructionServiceStub(without_token).ListSessions(
                pb.ListSessionsRequest(), timeout=10)
            check(False, "a call without the access token was answered")
        except grpc.RpcError as e:
            check(e.code() == grpc.StatusCode.UNAUTHENTICATED and
                  "requires an access token" in e.details(),
                  "a call without the token gave %s: %s" % (e.code(), e.details()))
        credentials = grpc.composite_channel_credentials(
            tls, grpc.access_token_call_credentials(args.token))
        channel = grpc.secure_channel(args.target, credentials, options=options)
    else:
        channel = grpc.insecure_channel(args.target, options=options)
    grpc.channel_ready_future(channel).result(timeout=10)

    # grpc.health.v1.Health/Check with an empty request: status SERVING (field 1 = 1).
    check(raw_unary(channel, "/grpc.health.v1.Health/Check", b"") == b"\x08\x01",
          "health check is not SERVING")
    # Server reflection: list_services (field 7) names our service.
    reflect = channel.stream_stream(
        "/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo",
        request_serializer=lambda b: b, response_deserializer=lambda b: b)
    answers = list(reflect(iter([b"\x3a\x00"]), timeout=10))
    check(any(b"neuralmesh.v1.ReconstructionService" in a for a in answers),
          "reflection does not list neuralmesh.v1.ReconstructionService")

    service = pb_grpc.ReconstructionServiceStub(channel)
    config = pb.SessionConfig(target_vertices=300)
    config.refresh_interval_ms.value = 50
    config.learner.alpha_w.value = 0.06
    # The paper's early phase (its David setting, scaled down): C_vs = 300 up to 200 vertices.
    config.learner.early_phase_vertices.value = 200
    config.learner.early_c_vs.value = 300
    session = service.CreateSession(pb.CreateSessionRequest(config=config, name="python"),
                                 timeout=10)
    check(session.session_id.startswith("s-"), "unexpected session id " + session.session_id)
    check(session.config.learner.c_vs.value == 100, "defaults are not echoed")
    check(session.config.learner.early_phase_vertices.value == 200 and
          session.config.learner.early_c_vs.value == 300 and
          session.config.learner.early_c_ec.value == 8,
          "the early phase is not echoed: %s" % session.config.learner)
    try:
        bad = pb.SessionConfig(target_vertices=300)
        bad.learner.early_c_ec.value = 0
        service.CreateSession(pb.CreateSessionRequest(config=bad), timeout=10)
        check(False, "early_c_ec = 0 was accepted")
    except grpc.RpcError as e:
        check(e.code() == grpc.StatusCode.INVALID_ARGUMENT and "early_c_ec" in e.details(),
              "early_c_ec = 0 gave %s: %s" % (e.code(), e.details()))
    sid = session.session_id

    updates = []
    errors = []

    def watch():
        try:
            for update in service.WatchSession(pb.WatchSessionRequest(session_id=sid), timeout=120):
                updates.append(update)
        except grpc.RpcError as e:  # Recorded and checked below.
            errors.append(e)

    watcher = threading.Thread(target=watch)
    watcher.start()

    points = sphere_points(6000, 1)
    batches = [points[i:i + 12 * 600] for i in range(0, len(points), 12 * 600)]

    def requests():  # With a colour per point.
        for index, chunk in enumerate(batches):
            yield pb.UploadPointsRequest(
                session_id=sid if index == 0 else "",
                batch=pb.PointBatch(packed=pb.PackedPoints(positions=chunk,
                                                           colors=colors_of(chunk))))

    ack = service.UploadPoints(requests(), timeout=60)
    check(ack.total_points == 6000 and ack.batches_accepted == 10,
          "upload acknowledged %d points in %d batches" % (ack.total_points,
                                                           ack.batches_accepted))

    # A batch sent again with its place in the upload (after a lost connection) adds nothing.
    resent = pb.PointBatch(packed=pb.PackedPoints(positions=batches[9]))
    resent.first_point.value = 5400
    again = service.UploadPoints(iter([pb.UploadPointsRequest(session_id=sid, batch=resent)]),
                              timeout=10)
    check(again.points_accepted == 0 and again.total_points == 6000,
          "a resent batch added %d points" % again.points_accepted)
    check(service.GetSession(pb.GetSessionRequest(session_id=sid), timeout=10).points_taken == 6000,
          "points_taken is not 6000")

    # A NaN batch is rejected with INVALID_ARGUMENT and the session keeps its points.
    nan_batch = struct.pack("<6f", 0.0, 0.0, 0.0, float("nan"), 0.0, 0.0)
    try:
        service.UploadPoints(iter([pb.UploadPointsRequest(
            session_id=sid, batch=pb.PointBatch(packed=pb.PackedPoints(positions=nan_batch)))]),
            timeout=10)
        check(False, "a NaN batch was accepted")
    except grpc.RpcError as e:
        check(e.code() == grpc.StatusCode.INVALID_ARGUMENT,
              "NaN batch gave %s: %s" % (e.code(), e.details()))
    check(service.GetSession(pb.GetSessionRequest(session_id=sid)).learning.points_received == 6000,
          "the rejected batch changed the session")

    service.FinishSession(pb.FinishSessionRequest(session_id=sid), timeout=10)
    final = service.GetMesh(pb.GetMeshRequest(session_id=sid, version=pb.MESH_VERSION_FINAL,
                                           wait=True), timeout=120)
    watcher.join(timeout=120)
    check(not errors, "watch failed: %s" % errors)
    check(final.kind == pb.UPDATE_KIND_FINAL and final.vertex_count == 300,
          "final mesh has %d vertices" % final.vertex_count)
    check(final.draco_mesh[:5] == b"DRACO", "the mesh is not Draco data")
    check(len(updates) >= 2 and updates[-1].sequence == final.sequence,
          "the watcher did not end with the final mesh")
    check(all(a.sequence < b.sequence for a, b in zip(updates, updates[1:])),
          "sequence numbers do not increase")

    # The reference Draco decoder reads the final mesh, and its vertices' colours are those of
    # their positions.
    drc = os.path.join(out_dir, "final.drc")
    obj = os.path.join(out_dir, "final.obj")
    ply = os.path.join(out_dir, "final.ply")
    with open(drc, "wb") as f:
        f.write(final.draco_mesh)
    subprocess.run(["draco_decoder", "-i", drc, "-o", obj], check=True,
                   stdout=subprocess.DEVNULL)
    with open(obj) as f:
        faces = sum(1 for line in f if line.startswith("f "))
    check(faces == final.face_count, "draco_decoder read %d faces, expected %d" %
          (faces, final.face_count))
    subprocess.run(["draco_decoder", "-i", drc, "-o", ply], check=True,
                   stdout=subprocess.DEVNULL)
    vertices = ply_vertex_colors(ply)
    check(len(vertices) == final.vertex_count, "draco_decoder read %d coloured vertices" %
          len(vertices))
    worst = max(abs(a - b) for v in vertices
                for a, b in zip(v[3:], color_of_position(*v[:3])))
    check(worst <= 8, "a vertex colour is %d levels from its position's colour" % worst)

    # Reconstruct: points in, meshes out, in one bidirectional call, with outlier removal
    # dropping a stray point sent alone in the last batch.
    config = pb.SessionConfig(target_vertices=100)
    config.outlier_removal.SetInParent()
    stray = struct.pack("<3f", 0.0, 0.0, 40.0)

    def stream():
        yield pb.ReconstructRequest(start=pb.ReconstructStart(
            create=pb.CreateSessionRequest(config=config)))
        for chunk in batches[:4] + [stray]:
            yield pb.ReconstructRequest(points=pb.PointBatch(
                packed=pb.PackedPoints(positions=chunk)))

    responses = list(service.Reconstruct(stream(), timeout=120))
    check(responses[0].WhichOneof("kind") == "session", "Reconstruct did not start with a session")
    check(responses[-1].WhichOneof("kind") == "update" and
          responses[-1].update.kind == pb.UPDATE_KIND_FINAL and
          responses[-1].update.vertex_count == 100, "Reconstruct did not end with the final mesh")
    acks = [r.ack for r in responses if r.WhichOneof("kind") == "ack"]
    check(acks and acks[-1].points_held_back >= 1 and
          acks[-1].points_accepted + acks[-1].points_held_back == 2401,
          "outlier removal: the last ack counts %d accepted, %d held back" %
          ((acks[-1].points_accepted, acks[-1].points_held_back) if acks else (0, 0)))
    # Finished: nothing is held any more, and every point held back was accepted later or
    # removed; the stray, which nothing came near, was removed.
    learning = service.GetSession(pb.GetSessionRequest(
        session_id=responses[0].session.session_id), timeout=10).learning
    check(learning.outliers_held == 0 and learning.points_removed_as_outliers >= 1 and
          learning.points_removed_as_outliers + learning.outliers_accepted_later ==
          acks[-1].points_held_back and
          learning.points_received == acks[-1].points_accepted + learning.outliers_accepted_later,
          "outlier removal: the finished session counts %d held, %d removed, %d accepted later" %
          (learning.outliers_held, learning.points_removed_as_outliers,
           learning.outliers_accepted_later))

    listed = service.ListSessions(pb.ListSessionsRequest(), timeout=10)
    check(len(listed.sessions) == 2, "ListSessions returned %d sessions" % len(listed.sessions))
    # Handing a session to another client: the answer and later reads name the new owner.
    handed = service.TransferSession(pb.TransferSessionRequest(session_id=sid, new_owner="bob"),
                                     timeout=10)
    check(handed.owner == "bob", "TransferSession answered owner %r" % handed.owner)
    check(service.GetSession(pb.GetSessionRequest(session_id=sid), timeout=10).owner == "bob",
          "GetSession does not name the new owner")
    try:
        service.TransferSession(pb.TransferSessionRequest(session_id=sid), timeout=10)
        check(False, "a transfer to nobody was accepted")
    except grpc.RpcError as e:
        check(e.code() == grpc.StatusCode.INVALID_ARGUMENT and "new_owner is empty" in e.details(),
              "a transfer to nobody gave %s: %s" % (e.code(), e.details()))
    service.DeleteSession(pb.DeleteSessionRequest(session_id=sid), timeout=10)
    try:
        service.GetSession(pb.GetSessionRequest(session_id=sid), timeout=10)
        check(False, "a deleted session was found")
    except grpc.RpcError as e:
        check(e.code() == grpc.StatusCode.NOT_FOUND, "deleted session gave %s" % e.code())
    print("python client: OK (%d updates, final %d vertices, %d faces)" %
          (len(updates), final.vertex_count, final.face_count))


if __name__ == "__main__":
    main()
