// Helpers shared by the server tests: test servers, shapes as point batches, and synchronous
// calls that collect a whole stream.
#ifndef NEURALMESH_TESTS_SERVER_SERVER_TEST_SUPPORT_H_
#define NEURALMESH_TESTS_SERVER_SERVER_TEST_SUPPORT_H_

#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/synchronization/mutex.h"
#include "absl/synchronization/notification.h"
#include "core/analysis/geometric_error.h"
#include "core/point_cloud.h"
#include "core/random.h"
#include "core/sampling/implicit_surfaces.h"
#include "core/sampling/sample_points.h"
#include "neuralmesh/v1/reconstruction.grpc.pb.h"
#include "proto/packing.h"
#include "server/event_log.h"
#include "server/proto_conversion.h"
#include "server/server.h"

namespace neuralmesh::server::testing {

// The lines an EventLog wrote, for checking them.
class CapturedEvents {
 public:
  EventLog::Sink Sink() {
    return [this](const std::string& line) {
      absl::MutexLock lock(&mu_);
      lines_.push_back(line);
    };
  }
  std::vector<std::string> lines() const {
    absl::MutexLock lock(&mu_);
    return lines_;
  }
  // Waits up to 10 s for a line that contains `text`; returns it, or "" when none came.
  std::string Await(const std::string& text) const {
    absl::MutexLock lock(&mu_);
    std::string found;
    auto has = [&]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
      for (const std::string& line : lines_) {
        if (line.find(text) != std::string::npos) {
          found = line;
          return true;
        }
      }
      return false;
    };
    mu_.AwaitWithTimeout(absl::Condition(&has), absl::Seconds(10));
    return found;
  }

 private:
  mutable absl::Mutex mu_;
  std::vector<std::string> lines_ ABSL_GUARDED_BY(mu_);
};

// A server on 127.0.0.1 with a picked port, or in-process only when `listen` is false.
inline std::unique_ptr<ReconstructionServer> StartServer(bool listen, ServerOptions options = {}) {
  options.address = listen ? "127.0.0.1:0" : "";
  absl::StatusOr<std::unique_ptr<ReconstructionServer>> server =
      ReconstructionServer::Start(options);
  EXPECT_TRUE(server.ok()) << "the test server did not start: " << server.status();
  return server.ok() ? *std::move(server) : nullptr;
}

inline std::unique_ptr<v1::ReconstructionService::Stub> InProcessService(
    ReconstructionServer& server) {
  return v1::ReconstructionService::NewStub(server.InProcessChannel());
}

inline std::unique_ptr<v1::ReconstructionService::Stub> NetworkService(
    ReconstructionServer& server) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(64 << 20);
  return v1::ReconstructionService::NewStub(
      grpc::CreateCustomChannel(server.target(), grpc::InsecureChannelCredentials(), args));
}

// Area-uniform points of a torus (R = 1, r = 0.4) or a sphere (r = 1) around the origin.
inline PointCloud TorusPoints(size_t n, uint64_t seed) {
  auto torus = MakeTorus(Vec3(0, 0, 0), 1.0, 0.4);
  EXPECT_TRUE(torus.ok());
  return SamplePoints(**torus, n, seed);
}
inline PointCloud SpherePoints(size_t n, uint64_t seed) {
  auto sphere = MakeSphere(Vec3(0, 0, 0), 1.0);
  EXPECT_TRUE(sphere.ok());
  return SamplePoints(**sphere, n, seed);
}

// Points [begin, end) of `cloud` as a packed batch that does not say where it starts in the
// upload (PackPointBatch's do).
inline v1::PointBatch Batch(const PointCloud& cloud, size_t begin, size_t end) {
  v1::PointBatch batch;
  *batch.mutable_packed() = PackPoints(cloud, begin, end);
  return batch;
}

// All of `cloud` as such a batch.
inline v1::PointBatch Batch(const PointCloud& cloud) { return Batch(cloud, 0, cloud.size()); }

inline v1::CreateSessionRequest CreateRequest(uint64_t target, uint32_t refresh_ms = 250) {
  v1::CreateSessionRequest request;
  request.mutable_config()->set_target_vertices(target);
  request.mutable_config()->mutable_refresh_interval_ms()->set_value(refresh_ms);
  request.set_name("test");
  return request;
}

// A session whose learner stalls on TorusPoints(2000, 9): Step 3 after every Basic Step, so
// collapses win over splits; collecting, it pauses for more points, finishing, it fails.
inline v1::CreateSessionRequest StallingRequest() {
  v1::CreateSessionRequest request = CreateRequest(100);
  request.mutable_config()->mutable_learner()->mutable_c_ec()->set_value(0.01);
  request.mutable_config()->mutable_learner()->mutable_c_vs()->set_value(10);
  return request;
}

inline std::string MustCreate(v1::ReconstructionService::Stub& stub,
                              const v1::CreateSessionRequest& request) {
  grpc::ClientContext context;
  v1::Session session;
  grpc::Status status = stub.CreateSession(&context, request, &session);
  EXPECT_TRUE(status.ok()) << "CreateSession failed: " << status.error_message();
  return session.session_id();
}

// Uploads `cloud` in `batches` equal batches through one UploadPoints call.
inline grpc::Status Upload(v1::ReconstructionService::Stub& stub, const std::string& id,
                           const PointCloud& cloud, size_t batches,
                           v1::UploadPointsResponse* response) {
  grpc::ClientContext context;
  auto writer = stub.UploadPoints(&context, response);
  const size_t n = cloud.size();
  for (size_t b = 0; b < batches; ++b) {
    v1::UploadPointsRequest request;
    if (b == 0) request.set_session_id(id);
    *request.mutable_batch() = Batch(cloud, n * b / batches, n * (b + 1) / batches);
    if (!writer->Write(request)) break;
  }
  writer->WritesDone();
  return writer->Finish();
}

// Sends one raw request through its own UploadPoints call.
inline grpc::Status UploadOne(v1::ReconstructionService::Stub& stub,
                              const v1::UploadPointsRequest& request,
                              v1::UploadPointsResponse* response) {
  grpc::ClientContext context;
  auto writer = stub.UploadPoints(&context, response);
  writer->Write(request);
  writer->WritesDone();
  return writer->Finish();
}

inline v1::Session GetSession(v1::ReconstructionService::Stub& stub, const std::string& id,
                              grpc::Status* status_out = nullptr) {
  grpc::ClientContext context;
  v1::GetSessionRequest request;
  request.set_session_id(id);
  v1::Session session;
  grpc::Status status = stub.GetSession(&context, request, &session);
  if (status_out != nullptr) *status_out = status;
  return session;
}

inline grpc::Status Finish(v1::ReconstructionService::Stub& stub, const std::string& id) {
  grpc::ClientContext context;
  v1::FinishSessionRequest request;
  request.set_session_id(id);
  v1::Session session;
  return stub.FinishSession(&context, request, &session);
}

inline grpc::Status Cancel(v1::ReconstructionService::Stub& stub, const std::string& id,
                           v1::Session* session_out = nullptr) {
  grpc::ClientContext context;
  v1::CancelSessionRequest request;
  request.set_session_id(id);
  v1::Session session;
  return stub.CancelSession(&context, request, session_out != nullptr ? session_out : &session);
}

inline grpc::Status Delete(v1::ReconstructionService::Stub& stub, const std::string& id) {
  grpc::ClientContext context;
  v1::DeleteSessionRequest request;
  request.set_session_id(id);
  v1::DeleteSessionResponse response;
  return stub.DeleteSession(&context, request, &response);
}

inline grpc::Status WaitFinal(v1::ReconstructionService::Stub& stub, const std::string& id,
                              v1::MeshUpdate* update, absl::Duration timeout = absl::Seconds(60)) {
  grpc::ClientContext context;
  context.set_deadline(absl::ToChronoTime(absl::Now() + timeout));
  v1::GetMeshRequest request;
  request.set_session_id(id);
  request.set_version(v1::MESH_VERSION_FINAL);
  request.set_wait(true);
  return stub.GetMesh(&context, request, update);
}

// Reads a whole WatchSession stream.
inline grpc::Status WatchAll(v1::ReconstructionService::Stub& stub, const std::string& id,
                             std::vector<v1::MeshUpdate>* updates,
                             absl::Duration timeout = absl::Seconds(60)) {
  grpc::ClientContext context;
  context.set_deadline(absl::ToChronoTime(absl::Now() + timeout));
  v1::WatchSessionRequest request;
  request.set_session_id(id);
  auto reader = stub.WatchSession(&context, request);
  v1::MeshUpdate update;
  while (reader->Read(&update)) updates->push_back(update);
  return reader->Finish();
}

// grpc.health.v1.Health/Check of `service` ("": the server as a whole) through `channel`;
// the response's bytes in `response` (08 01 is SERVING).
inline grpc::Status CheckHealth(const std::shared_ptr<grpc::Channel>& channel,
                                const std::string& service, std::string* response_bytes) {
  grpc::GenericStub generic(channel);
  // grpc.health.v1.HealthCheckRequest{service}: field 1, length-delimited.
  std::string request_bytes;
  if (!service.empty()) {
    request_bytes = absl::StrCat(std::string(1, '\x0a'),
                                 std::string(1, static_cast<char>(service.size())), service);
  }
  grpc::Slice slice(request_bytes);
  grpc::ByteBuffer request(&slice, 1);
  grpc::ByteBuffer response;
  grpc::ClientContext context;
  context.set_deadline(absl::ToChronoTime(absl::Now() + absl::Seconds(10)));
  absl::Notification done;
  grpc::Status status;
  generic.UnaryCall(&context, "/grpc.health.v1.Health/Check", grpc::StubOptions(), &request,
                    &response, [&](grpc::Status s) {
                      status = s;
                      done.Notify();
                    });
  done.WaitForNotification();
  if (!status.ok()) return status;
  std::vector<grpc::Slice> slices;
  if (!response.Dump(&slices).ok()) return grpc::Status(grpc::StatusCode::INTERNAL, "no bytes");
  response_bytes->clear();
  for (const grpc::Slice& s : slices) response_bytes->append(s.begin(), s.end());
  return status;
}

// Symmetric Chamfer-L1 from `mesh` to the torus of TorusPoints, relative to the bounding-box
// diagonal (core/analysis/geometric_error.h, 50,000 samples, one thread).
inline absl::StatusOr<double> ChamferToTorus(const TriangleMesh& mesh) {
  absl::StatusOr<std::unique_ptr<ImplicitSurface>> torus = MakeTorus(Vec3(0, 0, 0), 1.0, 0.4);
  if (!torus.ok()) return torus.status();
  GeometricErrorOptions options;
  options.samples = 50000;
  options.threads = 1;
  absl::StatusOr<GeometricError> error =
      ComputeGeometricError(mesh, (*torus)->ReferenceMesh(20), options);
  if (!error.ok()) return error.status();
  return error->chamfer_l1;
}

// Largest distance from the mesh's vertices to `surface`.
inline double MaxVertexDistance(const TriangleMesh& mesh, const ImplicitSurface& surface) {
  double worst = 0;
  for (const Vec3f& p : mesh.positions) {
    worst = std::max(worst, surface.Distance(Vec3(p[0], p[1], p[2])));
  }
  return worst;
}

}  // namespace neuralmesh::server::testing

#endif  // NEURALMESH_TESTS_SERVER_SERVER_TEST_SUPPORT_H_
