// Measures the reconstruction service over loopback (127.0.0.1, a real TCP port):
//  1. ingest throughput: points per second through one UploadPoints stream;
//  2. latency from the first batch to the first mesh (Reconstruct, median of 5);
//  3. Draco encode time and bytes per vertex of every LOD milestone;
//  4. learning: one session to --lod_target vertices end to end, and Basic Steps per second
//     with 1, 2 and 8 concurrent sessions, against the same learner run locally in this
//     process (what the local CLI does) on the same points and, for rates, at the same age.
// Targets (issue): >= 10M points/s ingested; first mesh within 100 ms; <= 8 bytes per vertex
// at 11-bit quantization; one session under the server >= 90% of the local learning rate.
//
//   build/bin/service-bench [--ingest_points=20000000] [--lod_target=20000] [--learn_seconds=3]
//                           [--lod_milestones=10,20,50] [--only_lods]
#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "bench/bench_flags.h"
#include "bench/first_touch.h"
#include "core/learning/learner.h"
#include "core/sampling/growing_point_cloud.h"
#include "core/sampling/implicit_surfaces.h"
#include "core/sampling/sample_points.h"
#include "neuralmesh/v1/reconstruction.grpc.pb.h"
#include "proto/packing.h"
#include "server/proto_conversion.h"
#include "server/server.h"

ABSL_FLAG(int64_t, ingest_points, 20000000, "Points sent in the ingest measurement.");
ABSL_FLAG(int64_t, batch_points, 1 << 18, "Points per batch in the ingest measurement.");
ABSL_FLAG(int64_t, lod_target, 20000, "Target vertex count of the LOD measurement.");
ABSL_FLAG(double, learn_seconds, 3.0, "Measurement window of the learning-rate measurement.");
ABSL_FLAG(int, worker_threads, 2, "The server's learning threads.");
ABSL_FLAG(int, lod_refresh_ms, 250, "Refresh interval of the LOD session (0: milestones only).");
ABSL_FLAG(std::vector<std::string>, lod_milestones, {},
          "Milestones of the LOD session, e.g. 10,20,50 (the target is appended); empty: the "
          "server's default series.");
ABSL_FLAG(bool, only_lods, false, "Run the LOD and learning-rate measurements only.");
ABSL_FLAG(std::string, state_dir, "",
          "Run the server with this state directory (neuralmesh-server --state_dir; it should be "
          "empty) and, after the ingest, measure a restart that restores the ingested session.");
ABSL_FLAG(bool, state_sync, true, "With --state_dir: neuralmesh-server --state_sync.");

namespace neuralmesh {
namespace {

using server::ReconstructionServer;
using server::ServerOptions;
// gRPC's generated client class of the service.
using Service = v1::ReconstructionService::Stub;

PointCloud Torus(size_t n, uint64_t seed) {
  auto torus = MakeTorus(Vec3(0, 0, 0), 1.0, 0.4);
  return SamplePoints(**torus, n, seed);
}

v1::PointBatch Batch(const PointCloud& cloud, size_t begin, size_t end) {
  v1::PointBatch batch;
  *batch.mutable_packed() = PackPoints(cloud, begin, end);
  return batch;
}

std::string Create(Service& service, uint64_t target,
                   v1::FinalPass final_pass = v1::FINAL_PASS_AUTO, int refresh_ms = 250,
                   const std::vector<uint64_t>& milestones = {}) {
  grpc::ClientContext context;
  v1::CreateSessionRequest request;
  request.mutable_config()->set_target_vertices(target);
  for (uint64_t m : milestones) request.mutable_config()->add_lod_milestones(m);
  request.mutable_config()->mutable_refresh_interval_ms()->set_value(refresh_ms);
  request.mutable_config()->set_final_pass(final_pass);
  v1::Session session;
  grpc::Status status = service.CreateSession(&context, request, &session);
  if (!status.ok()) {
    std::fprintf(stderr, "CreateSession: %s\n", status.error_message().c_str());
    std::exit(1);
  }
  return session.session_id();
}

void Upload(Service& service, const std::string& id,
            const std::vector<v1::UploadPointsRequest>& requests) {
  grpc::ClientContext context;
  v1::UploadPointsResponse response;
  auto writer = service.UploadPoints(&context, &response);
  for (size_t i = 0; i < requests.size(); ++i) {
    if (i == 0) {
      v1::UploadPointsRequest first = requests[0];
      first.set_session_id(id);
      writer->Write(first);
    } else {
      writer->Write(requests[i]);
    }
  }
  writer->WritesDone();
  grpc::Status status = writer->Finish();
  if (!status.ok()) {
    std::fprintf(stderr, "UploadPoints: %s\n", status.error_message().c_str());
    std::exit(1);
  }
}

v1::Session Get(Service& service, const std::string& id) {
  grpc::ClientContext context;
  v1::GetSessionRequest request;
  request.set_session_id(id);
  v1::Session session;
  service.GetSession(&context, request, &session);
  return session;
}

void Delete(Service& service, const std::string& id) {
  grpc::ClientContext context;
  v1::DeleteSessionRequest request;
  request.set_session_id(id);
  v1::DeleteSessionResponse response;
  service.DeleteSession(&context, request, &response);
}

// Returns the session, which holds the points.
std::string MeasureIngest(Service& service) {
  const size_t total = static_cast<size_t>(absl::GetFlag(FLAGS_ingest_points));
  const size_t batch = static_cast<size_t>(absl::GetFlag(FLAGS_batch_points));
  const PointCloud source = Torus(std::min<size_t>(total, 1 << 20), 1);
  std::vector<v1::UploadPointsRequest> requests;
  for (size_t sent = 0; sent < total; sent += batch) {
    const size_t n = std::min(batch, total - sent);
    const size_t begin = sent % source.size();
    const size_t end = std::min(begin + n, source.size());
    v1::UploadPointsRequest request;
    *request.mutable_batch() = Batch(source, begin, end);
    requests.push_back(std::move(request));
  }
  size_t points = 0;
  for (const auto& r : requests) points += r.batch().packed().positions().size() / 12;
  const double first_touch = bench::FirstTouchBytesPerSecond(points * 12);
  std::printf("memory first touch: %.0f MB/s; the session's %.0f MB of fresh memory for the "
              "points take %.2f s of the ingest\n",
              first_touch / 1e6, points * 12.0 / 1e6,
              first_touch > 0 ? points * 12.0 / first_touch : 0.0);
  // A small target: learning pauses quickly and leaves the cores to ingestion.
  const std::string id = Create(service, 1000);
  const absl::Time start = absl::Now();
  Upload(service, id, requests);
  const double seconds = absl::ToDoubleSeconds(absl::Now() - start);
  const v1::Session session = Get(service, id);
  std::printf("ingest: %zu points in %zu batches over one stream: %.3f s, %.1f M points/s "
              "(%.0f MB/s); session holds %llu points   [target >= 10 M points/s]\n",
              points, requests.size(), seconds, points / seconds / 1e6,
              points * 12.0 / seconds / 1e6,
              static_cast<unsigned long long>(session.learning().points_received()));
  return id;
}

std::unique_ptr<Service> Connect(const ReconstructionServer& server) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(64 << 20);
  args.SetMaxSendMessageSize(64 << 20);
  return v1::ReconstructionService::NewStub(
      grpc::CreateCustomChannel(server.target(), grpc::InsecureChannelCredentials(), args));
}

void MeasureFirstMesh(Service& service) {
  const PointCloud points = Torus(10000, 2);
  std::vector<double> latencies;
  for (int run = 0; run < 5; ++run) {
    grpc::ClientContext context;
    auto stream = service.Reconstruct(&context);
    v1::ReconstructRequest start;
    start.mutable_start()->mutable_create()->mutable_config()->set_target_vertices(5000);
    stream->Write(start);
    v1::ReconstructResponse response;
    if (!stream->Read(&response) || !response.has_session()) {
      std::fprintf(stderr, "Reconstruct did not start\n");
      std::exit(1);
    }
    const std::string id = response.session().session_id();
    v1::ReconstructRequest request;
    *request.mutable_points() = Batch(points, 0, points.size());
    const absl::Time t0 = absl::Now();
    stream->Write(request);
    while (stream->Read(&response) && !response.has_update()) {
    }
    latencies.push_back(absl::ToDoubleMilliseconds(absl::Now() - t0));
    context.TryCancel();
    stream->Finish();
    Delete(service, id);
  }
  std::sort(latencies.begin(), latencies.end());
  std::printf("first mesh: %.1f ms after the first batch of 10000 points (median of 5; "
              "min %.1f, max %.1f)   [target <= 100 ms]\n",
              latencies[2], latencies.front(), latencies.back());
}

// Returns the wall time from the upload to the final mesh and the Basic Steps taken.
std::pair<double, uint64_t> MeasureLods(Service& service,
                                        const PointCloud& points) {
  const uint64_t target = static_cast<uint64_t>(absl::GetFlag(FLAGS_lod_target));
  std::vector<uint64_t> milestones;
  for (const std::string& m : absl::GetFlag(FLAGS_lod_milestones)) {
    uint64_t value = 0;
    if (!absl::SimpleAtoi(m, &value)) {
      std::fprintf(stderr, "--lod_milestones: \"%s\" is not a vertex count\n", m.c_str());
      std::exit(1);
    }
    milestones.push_back(value);
  }
  const std::string id = Create(service, target, v1::FINAL_PASS_CONTINUE,
                                absl::GetFlag(FLAGS_lod_refresh_ms), milestones);
  std::vector<v1::MeshUpdate> updates;
  std::thread watcher([&] {
    grpc::ClientContext context;
    v1::WatchSessionRequest request;
    request.set_session_id(id);
    auto reader = service.WatchSession(&context, request);
    v1::MeshUpdate update;
    while (reader->Read(&update)) updates.push_back(update);
    reader->Finish();
  });
  std::vector<v1::UploadPointsRequest> requests;
  for (size_t b = 0; b < points.size(); b += 100000) {
    v1::UploadPointsRequest r;
    *r.mutable_batch() = Batch(points, b, std::min(points.size(), b + 100000));
    requests.push_back(std::move(r));
  }
  const absl::Time start = absl::Now();
  Upload(service, id, requests);
  {
    grpc::ClientContext context;
    v1::FinishSessionRequest request;
    request.set_session_id(id);
    v1::Session session;
    service.FinishSession(&context, request, &session);
  }
  watcher.join();
  const double seconds = absl::ToDoubleSeconds(absl::Now() - start);
  std::printf("LODs (11-bit positions, Draco speed 5, refresh every %d ms):\n",
              absl::GetFlag(FLAGS_lod_refresh_ms));
  std::printf("  %-9s %9s %9s %10s %8s %10s\n", "kind", "vertices", "faces", "bytes", "B/vert",
              "encode ms");
  double worst = 0;
  for (const v1::MeshUpdate& u : updates) {
    if (u.kind() == v1::UPDATE_KIND_REFRESH) continue;
    const double per_vertex = static_cast<double>(u.draco_mesh().size()) / u.vertex_count();
    worst = std::max(worst, per_vertex);
    std::printf("  %-9s %9llu %9llu %10zu %8.2f %10.2f\n",
                u.kind() == v1::UPDATE_KIND_FINAL ? "final" : "milestone",
                static_cast<unsigned long long>(u.vertex_count()),
                static_cast<unsigned long long>(u.face_count()), u.draco_mesh().size(),
                per_vertex, u.encode_time_us() / 1000.0);
  }
  std::printf("  at most %.2f bytes per vertex over the LODs   [target <= 8 bytes per vertex at "
              "11 bits]\n",
              worst);
  const uint64_t steps = updates.empty() ? 0 : updates.back().learning().basic_steps();
  if (!updates.empty()) {
    const v1::LearningState& learning = updates.back().learning();
    std::printf("  the session's learning thread: %llu Basic Steps in %.2f s of learning "
                "(%.0f steps/s); wall time from upload to final mesh %.2f s\n",
                static_cast<unsigned long long>(learning.basic_steps()),
                learning.learning_seconds(), learning.steps_per_second(), seconds);
  }
  Delete(service, id);
  return {seconds, steps};
}

// Learns from scratch to --lod_target vertices in this process, as the local CLI does;
// returns the wall time in seconds.
double LocalToTarget(const PointCloud& points) {
  GrowingPointCloud cloud(points.size());
  if (!cloud.Append(points.positions).ok()) std::exit(1);
  auto learner = Learner::Create(LearnerOptions(), &cloud);
  StopCriteria to_target;
  to_target.target_vertices = static_cast<size_t>(absl::GetFlag(FLAGS_lod_target));
  const absl::Time start = absl::Now();
  if (!(*learner)->Run(to_target).ok()) std::exit(1);
  return absl::ToDoubleSeconds(absl::Now() - start);
}

// The Basic Steps per second of a learner on `points` in this process (what the local CLI
// runs), over `window` after it has learned for `age`. A Basic Step costs more on a larger
// mesh, so a rate is only comparable with one measured at the same age.
double LocalRate(const PointCloud& points, absl::Duration age, absl::Duration window) {
  GrowingPointCloud cloud(points.size());
  if (!cloud.Append(points.positions).ok()) std::exit(1);
  auto learner = Learner::Create(LearnerOptions(), &cloud);
  StopCriteria warm;
  warm.time_budget = age;
  if (!(*learner)->Run(warm).ok()) std::exit(1);
  const uint64_t before = (*learner)->progress().basic_steps;
  StopCriteria measure;
  measure.time_budget = window;
  const absl::Time start = absl::Now();
  if (!(*learner)->Run(measure).ok()) std::exit(1);
  return ((*learner)->progress().basic_steps - before) /
         absl::ToDoubleSeconds(absl::Now() - start);
}

void MeasureLearning(Service& service, const PointCloud& points,
                     double lod_wall_seconds, uint64_t lod_steps, double local_to_target) {
  const absl::Duration window = absl::Seconds(absl::GetFlag(FLAGS_learn_seconds));
  const absl::Duration warmup = absl::Milliseconds(500);
  std::printf("learning, local learner: to %lld vertices in %.2f s "
              "(mean of a run before and one after the server session)\n",
              static_cast<long long>(absl::GetFlag(FLAGS_lod_target)), local_to_target);
  std::printf("learning, one server session to %lld vertices (upload, learning, snapshots, "
              "encoding, final mesh): %.2f s, %.0f steps/s wall = %.0f%% of local\n",
              static_cast<long long>(absl::GetFlag(FLAGS_lod_target)), lod_wall_seconds,
              lod_steps / lod_wall_seconds, 100.0 * local_to_target / lod_wall_seconds);

  std::vector<v1::UploadPointsRequest> requests;
  for (size_t b = 0; b < points.size(); b += 100000) {
    v1::UploadPointsRequest r;
    *r.mutable_batch() = Batch(points, b, std::min(points.size(), b + 100000));
    requests.push_back(std::move(r));
  }
  // Steady rates: the sessions' learners are measured over a window that starts once the
  // upload and a warm-up are over; the local reference is a learner of the same age.
  double local_rate = 0;
  for (int sessions : {1, 2, 8}) {
    std::vector<std::string> ids;
    // Targets high enough that no session finishes inside the window.
    for (int i = 0; i < sessions; ++i) ids.push_back(Create(service, points.size() / 2));
    const absl::Time upload_start = absl::Now();
    for (const std::string& id : ids) Upload(service, id, requests);
    absl::SleepFor(warmup);
    std::vector<uint64_t> before;
    for (const std::string& id : ids) before.push_back(Get(service, id).learning().basic_steps());
    const absl::Time start = absl::Now();
    absl::SleepFor(window);
    double total = 0, least = 1e300, most = 0;
    for (size_t i = 0; i < ids.size(); ++i) {
      const uint64_t after = Get(service, ids[i]).learning().basic_steps();
      const double rate = (after - before[i]) / absl::ToDoubleSeconds(absl::Now() - start);
      total += rate;
      least = std::min(least, rate);
      most = std::max(most, rate);
    }
    for (const std::string& id : ids) Delete(service, id);
    if (sessions == 1) {
      local_rate = LocalRate(points, start - upload_start, window);
      std::printf("learning, local learner of the same age (%.2f s): %.0f Basic Steps/s\n",
                  absl::ToDoubleSeconds(start - upload_start), local_rate);
    }
    std::printf("learning, %d concurrent session%s on %d worker threads: %.0f steps/s in total "
                "(%.0f%% of local), per session %.0f..%.0f\n",
                sessions, sessions > 1 ? "s" : "", absl::GetFlag(FLAGS_worker_threads), total,
                100.0 * total / local_rate, least, most);
  }
  std::printf("  [target: one session >= 90%% of the local rate]\n");
}

}  // namespace
}  // namespace neuralmesh

int main(int argc, char** argv) {
  neuralmesh::ParseBenchFlags(
      argc, argv,
      "Measures the reconstruction service over loopback: ingest, first-mesh latency, "
      "Draco sizes and learning rates; see bench/service_bench.cc");
  using namespace neuralmesh;
  ServerOptions options;
  options.address = "127.0.0.1:0";
  options.worker_threads = absl::GetFlag(FLAGS_worker_threads);
  options.limits.max_points_per_session =
      std::max<size_t>(static_cast<size_t>(absl::GetFlag(FLAGS_ingest_points)), 1 << 22);
  options.limits.max_batch_points = static_cast<size_t>(absl::GetFlag(FLAGS_batch_points));
  options.state_dir = absl::GetFlag(FLAGS_state_dir);
  options.state_sync = absl::GetFlag(FLAGS_state_sync);
  absl::StatusOr<std::unique_ptr<ReconstructionServer>> server =
      ReconstructionServer::Start(options);
  if (!server.ok()) {
    std::fprintf(stderr, "%s\n", server.status().ToString().c_str());
    return 1;
  }
  auto service = Connect(**server);
  std::printf("neuralmesh service benchmark over %s, %d worker threads, %u hardware threads%s\n",
              (*server)->target().c_str(), options.worker_threads,
              std::thread::hardware_concurrency(),
              options.state_dir.empty()
                  ? ""
                  : absl::StrCat(", state directory ", options.state_dir,
                                 options.state_sync ? " (synced)" : " (not synced)")
                        .c_str());

  if (!absl::GetFlag(FLAGS_only_lods)) {
    const std::string ingested = MeasureIngest(*service);
    if (!options.state_dir.empty()) {
      // A restart: the new server listens at once and restores the ingested session meanwhile.
      (*server)->Shutdown();
      server->reset();
      const absl::Time start = absl::Now();
      server = ReconstructionServer::Start(options);
      if (!server.ok()) {
        std::fprintf(stderr, "%s\n", server.status().ToString().c_str());
        return 1;
      }
      const double up_seconds = absl::ToDoubleSeconds(absl::Now() - start);
      const server::RestoreReport restored = (*server)->WaitForRestore();
      const double restore_seconds = absl::ToDoubleSeconds(restored.took);
      std::printf("restart: the server up in %.3f s; %zu session of %zu points restored in "
                  "%.3f s (%.1f M points/s) while it answered\n",
                  up_seconds, restored.sessions, restored.points, restore_seconds,
                  restore_seconds > 0 ? restored.points / restore_seconds / 1e6 : 0.0);
      service = Connect(**server);
    }
    Delete(*service, ingested);
    MeasureFirstMesh(*service);
  }
  const PointCloud points = Torus(400000, 3);
  // Local runs right before and after the server's, so that load from other processes on
  // the machine weighs on both sides alike.
  const double local_before = LocalToTarget(points);
  const auto [lod_seconds, lod_steps] = MeasureLods(*service, points);
  const double local_after = LocalToTarget(points);
  MeasureLearning(*service, points, lod_seconds, lod_steps, (local_before + local_after) / 2);
  (*server)->Shutdown();
  return 0;
}
