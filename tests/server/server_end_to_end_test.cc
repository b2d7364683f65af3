// End to end over a real 127.0.0.1 port: a torus streamed in 100 batches, every mesh decoded
// by the Draco library and by Debian's draco_decoder, the health service, and the
// neuralmesh-server binary shutting down on SIGTERM during open streams.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/synchronization/notification.h"
#include "core/analysis/geometric_error.h"
#include "core/io/draco_codec.h"
#include "tests/server/server_test_support.h"
#include "tests/testing/temp_dir.h"

namespace neuralmesh::server {
namespace {

namespace fs = std::filesystem;

// Decodes `draco` with the draco_decoder binary; returns the face count of the OBJ it writes,
// or -1 when the decoder fails.
int DecodeWithReferenceDecoder(const std::string& draco, const fs::path& dir, int index) {
  const fs::path input = dir / absl::StrCat("mesh", index, ".drc");
  const fs::path output = dir / absl::StrCat("mesh", index, ".obj");
  {
    std::ofstream out(input, std::ios::binary);
    out.write(draco.data(), static_cast<std::streamsize>(draco.size()));
  }
  const std::string command = absl::StrCat("draco_decoder -i ", input.string(), " -o ",
                                           output.string(), " > /dev/null 2>&1");
  if (std::system(command.c_str()) != 0) return -1;
  std::ifstream in(output);
  std::string line;
  int faces = 0;
  while (std::getline(in, line)) faces += line.rfind("f ", 0) == 0 ? 1 : 0;
  return faces;
}

TEST(ServerEndToEndTest, TorusInAHundredBatchesOverLoopback) {
  ASSERT_EQ(std::system("command -v draco_decoder > /dev/null"), 0)
      << "Debian's draco package (draco_decoder) is required";
  std::unique_ptr<ReconstructionServer> server = testing::StartServer(/*listen=*/true);
  ASSERT_NE(server, nullptr);
  ASSERT_GT(server->port(), 0);
  auto service = testing::NetworkService(*server);

  auto torus = MakeTorus(Vec3(0, 0, 0), 1.0, 0.4);
  ASSERT_TRUE(torus.ok());
  const PointCloud points = SamplePoints(**torus, 40000, 21);
  const std::string id = testing::MustCreate(*service, testing::CreateRequest(2000));

  std::vector<v1::MeshUpdate> updates;
  grpc::Status watch_status;
  std::thread watcher([&] { watch_status = testing::WatchAll(*service, id, &updates); });
  v1::UploadPointsResponse response;
  grpc::Status upload = testing::Upload(*service, id, points, 100, &response);
  ASSERT_TRUE(upload.ok()) << upload.error_message();
  EXPECT_EQ(response.batches_accepted(), 100u);
  EXPECT_EQ(response.total_points(), 40000u);
  ASSERT_TRUE(testing::Finish(*service, id).ok());
  watcher.join();
  ASSERT_TRUE(watch_status.ok()) << watch_status.error_message();

  // At least four milestone meshes with increasing vertex counts, then the final one.
  std::vector<uint64_t> counts;
  for (const v1::MeshUpdate& u : updates) {
    if (u.kind() == v1::UPDATE_KIND_MILESTONE || u.kind() == v1::UPDATE_KIND_FINAL) {
      counts.push_back(u.vertex_count());
    }
  }
  ASSERT_GE(counts.size(), 4u);
  for (size_t i = 1; i < counts.size(); ++i) {
    EXPECT_GT(counts[i], counts[i - 1]) << "milestone vertex counts must increase";
  }
  ASSERT_EQ(updates.back().kind(), v1::UPDATE_KIND_FINAL);
  EXPECT_EQ(updates.back().vertex_count(), 2000u);

  // The stream's budget, 8 bytes per vertex at 11 bits, holds for every level of detail of the
  // default series and for every refresh between them (the first batch allows 200 vertices,
  // so no refresh shows a mesh below the first milestone).
  const v1::Session session = testing::GetSession(*service, id);
  EXPECT_THAT(session.config().lod_milestones(),
              ::testing::ElementsAre(50, 100, 200, 500, 1000, 2000))
      << "the default series";
  EXPECT_EQ(session.config().draco().position_quantization_bits().value(), 11);
  for (const v1::MeshUpdate& u : updates) {
    const double per_vertex = static_cast<double>(u.draco_mesh().size()) / u.vertex_count();
    std::printf(
        "update %llu: %s %llu vertices, %zu bytes, %.2f bytes/vertex\n",
        static_cast<unsigned long long>(u.sequence()), v1::UpdateKind_Name(u.kind()).c_str(),
        static_cast<unsigned long long>(u.vertex_count()), u.draco_mesh().size(), per_vertex);
    EXPECT_LE(per_vertex, 8.0) << "update " << u.sequence() << " (" << v1::UpdateKind_Name(u.kind())
                               << ", " << u.vertex_count() << " vertices) takes "
                               << u.draco_mesh().size() << " bytes";
  }

  const fs::path dir = neuralmesh::testing::MakeTempDir("decoded");
  for (size_t i = 0; i < updates.size(); ++i) {
    const v1::MeshUpdate& u = updates[i];
    absl::StatusOr<TriangleMesh> mesh = DecodeMesh(u.draco_mesh());
    ASSERT_TRUE(mesh.ok()) << "update " << u.sequence() << ": " << mesh.status();
    EXPECT_EQ(mesh->faces.size(), u.face_count()) << "update " << u.sequence();
    EXPECT_EQ(DecodeWithReferenceDecoder(u.draco_mesh(), dir, static_cast<int>(i)),
              static_cast<int>(u.face_count()))
        << "draco_decoder cannot decode update " << u.sequence();
    EXPECT_EQ(u.quantization_epoch(), 0u);
  }

  // The final mesh is close to the true torus.
  absl::StatusOr<TriangleMesh> final_mesh = DecodeMesh(updates.back().draco_mesh());
  ASSERT_TRUE(final_mesh.ok());
  absl::StatusOr<double> chamfer = testing::ChamferToTorus(*final_mesh);
  ASSERT_TRUE(chamfer.ok()) << chamfer.status();
  EXPECT_LT(*chamfer, 0.02) << "the final mesh is too far from the torus (2% of the diagonal)";
  const double bytes_per_vertex =
      static_cast<double>(updates.back().draco_mesh().size()) / updates.back().vertex_count();
  std::printf("final mesh: %llu vertices, genus %d, chamfer %.5f, %.2f bytes/vertex\n",
              static_cast<unsigned long long>(updates.back().vertex_count()),
              updates.back().report().genus(), *chamfer, bytes_per_vertex);
}

TEST(ServerEndToEndTest, TheEventLogNamesTheClientAndHowEachSessionEnded) {
  testing::CapturedEvents events;
  ServerOptions options;
  options.event_sink = events.Sink();
  std::unique_ptr<ReconstructionServer> server = testing::StartServer(/*listen=*/true, options);
  ASSERT_NE(server, nullptr);
  auto service = testing::NetworkService(*server);
  const std::string finished = testing::MustCreate(*service, testing::CreateRequest(300));
  v1::UploadPointsResponse response;
  ASSERT_TRUE(testing::Upload(*service, finished, testing::TorusPoints(4000, 3), 2, &response).ok());
  ASSERT_TRUE(testing::Finish(*service, finished).ok());
  v1::MeshUpdate final_mesh;
  ASSERT_TRUE(testing::WaitFinal(*service, finished, &final_mesh).ok());
  const std::string cancelled = testing::MustCreate(*service, testing::CreateRequest(300));
  ASSERT_TRUE(testing::Cancel(*service, cancelled).ok());
  ASSERT_TRUE(testing::Delete(*service, finished).ok());

  const std::string created = events.Await(absl::StrCat(finished, " created"));
  EXPECT_THAT(created, ::testing::HasSubstr(absl::StrCat(
                           "session ", finished,
                           " created by ipv4:127.0.0.1:")));  // The client's own port follows.
  EXPECT_THAT(created, ::testing::EndsWith(": \"test\", target 300 vertices"));
  EXPECT_THAT(events.Await(absl::StrCat(finished, " finished")),
              ::testing::HasSubstr("finished: 300 vertices, "));
  EXPECT_THAT(events.Await(absl::StrCat(cancelled, " cancelled")),
              ::testing::HasSubstr("cancelled: "));
  EXPECT_FALSE(events.Await(absl::StrCat(finished, " deleted")).empty());
  EXPECT_EQ(events.lines().size(), 5u);
}

TEST(ServerEndToEndTest, HealthServiceReportsServing) {
  std::unique_ptr<ReconstructionServer> server = testing::StartServer(/*listen=*/true);
  ASSERT_NE(server, nullptr);
  auto channel = grpc::CreateChannel(server->target(), grpc::InsecureChannelCredentials());
  for (const std::string service : {"", "neuralmesh.v1.ReconstructionService"}) {
    std::string bytes;
    const grpc::Status status = testing::CheckHealth(channel, service, &bytes);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(bytes, std::string("\x08\x01", 2)) << "status SERVING for \"" << service << "\"";
  }
}

// Starts build/bin/neuralmesh-server on a picked port and returns its pid and port.
struct Child {
  pid_t pid = -1;
  int port = 0;
};

Child StartServerBinary() {
  const char* bin_dir = std::getenv("NEURALMESH_BIN_DIR");
  const std::string binary =
      absl::StrCat(bin_dir != nullptr ? bin_dir : "build/bin", "/neuralmesh-server");
  int pipe_fds[2];
  if (pipe(pipe_fds) != 0) return {};
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(pipe_fds[1], STDOUT_FILENO);
    close(pipe_fds[0]);
    close(pipe_fds[1]);
    execl(binary.c_str(), binary.c_str(), "--host=127.0.0.1", "--port=0", "--worker_threads=2",
          static_cast<char*>(nullptr));
    _exit(127);
  }
  close(pipe_fds[1]);
  Child child;
  child.pid = pid;
  FILE* out = fdopen(pipe_fds[0], "r");
  char line[512];
  if (out != nullptr && std::fgets(line, sizeof(line), out) != nullptr) {
    const char* colon = std::strrchr(line, ':');
    if (colon != nullptr) child.port = std::atoi(colon + 1);
  }
  // Keep draining the child's output so that it never blocks on a full pipe.
  std::thread([out] {
    char buffer[512];
    while (out != nullptr && std::fgets(buffer, sizeof(buffer), out) != nullptr) {
    }
    if (out != nullptr) std::fclose(out);
  }).detach();
  return child;
}

TEST(ServerEndToEndTest, BinaryShutsDownOnSigtermDuringOpenStreams) {
  Child child = StartServerBinary();
  ASSERT_GT(child.pid, 0);
  ASSERT_GT(child.port, 0) << "the server did not print its port";
  auto service = v1::ReconstructionService::NewStub(grpc::CreateChannel(
      absl::StrCat("127.0.0.1:", child.port), grpc::InsecureChannelCredentials()));
  const std::string id = testing::MustCreate(*service, testing::CreateRequest(100000));
  v1::UploadPointsResponse response;
  ASSERT_TRUE(testing::Upload(*service, id, testing::TorusPoints(20000, 22), 4, &response).ok());

  grpc::Status watch_status, upload_status;
  std::vector<v1::MeshUpdate> updates;
  absl::Time watch_end, upload_end;
  std::thread watcher([&] {
    watch_status = testing::WatchAll(*service, id, &updates);
    watch_end = absl::Now();
  });
  std::thread uploader([&] {
    grpc::ClientContext context;
    v1::UploadPointsResponse r;
    auto writer = service->UploadPoints(&context, &r);
    v1::UploadPointsRequest request;
    request.set_session_id(id);
    *request.mutable_batch() = testing::Batch(testing::TorusPoints(100, 23), 0, 100);
    writer->Write(request);
    upload_status = writer->Finish();  // Never half-closed: only the shutdown ends it.
    upload_end = absl::Now();
  });
  absl::SleepFor(absl::Milliseconds(500));
  const absl::Time start = absl::Now();
  ASSERT_EQ(kill(child.pid, SIGTERM), 0);
  int wstatus = 0;
  pid_t waited = 0;
  while ((waited = waitpid(child.pid, &wstatus, WNOHANG)) == 0 &&
         absl::Now() - start < absl::Seconds(20)) {
    absl::SleepFor(absl::Milliseconds(20));
  }
  if (waited == 0) {
    kill(child.pid, SIGKILL);
    waitpid(child.pid, &wstatus, 0);
    FAIL() << "the server did not exit within 20 s of SIGTERM";
  }
  const absl::Time exited = absl::Now();
  watcher.join();
  uploader.join();
  std::printf("after SIGTERM: watch ended %.3f s, upload ended %.3f s, process exited %.3f s\n",
              absl::ToDoubleSeconds(watch_end - start), absl::ToDoubleSeconds(upload_end - start),
              absl::ToDoubleSeconds(exited - start));
  EXPECT_TRUE(WIFEXITED(wstatus) && WEXITSTATUS(wstatus) == 0) << "exit status " << wstatus;
  EXPECT_LT(absl::Now() - start, absl::Seconds(6));
  EXPECT_EQ(watch_status.error_code(), grpc::StatusCode::UNAVAILABLE)
      << watch_status.error_message();
  EXPECT_EQ(upload_status.error_code(), grpc::StatusCode::UNAVAILABLE)
      << upload_status.error_message();
  EXPECT_FALSE(updates.empty()) << "the watcher saw meshes before the shutdown";
}

}  // namespace
}  // namespace neuralmesh::server
