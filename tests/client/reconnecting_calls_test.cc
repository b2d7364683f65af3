// client/reconnecting_calls.h: uploads, watches and finishes that ride out lost connections,
// through a TCP proxy (tests/client/tcp_proxy.h) in front of a server on 127.0.0.1 that cuts
// the connections, refuses new ones, or lets them through again; and a listing that waits out
// a server restoring its sessions (a fake server).
#include "client/reconnecting_calls.h"

#include <gmock/gmock.h>
#include <grpcpp/server_builder.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <memory>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/clock.h"
#include "core/io/draco_codec.h"
#include "core/sampling/implicit_surfaces.h"
#include "server/server.h"
#include "tests/client/tcp_proxy.h"
#include "tests/server/server_test_support.h"

namespace neuralmesh::client {
namespace {

using ::neuralmesh::server::ReconstructionServer;
using ::neuralmesh::server::testing::SpherePoints;
using ::neuralmesh::server::testing::StartServer;
using ::neuralmesh::testing::TcpProxy;
using ::testing::HasSubstr;

constexpr size_t kPoints = 60000;
constexpr size_t kBatch = 1000;

int PortOf(const std::string& address) { return std::stoi(address.substr(address.rfind(':') + 1)); }

v1::SessionConfig SphereConfig(uint64_t target) {
  v1::SessionConfig config;
  config.set_target_vertices(target);
  config.mutable_refresh_interval_ms()->set_value(50);
  return config;
}

// The notices a reconnecting call gave, for the test to read (calls may come from two threads).
class Notices {
 public:
  ReconnectOptions Options(absl::Duration give_up_after) {
    ReconnectOptions options;
    options.give_up_after = give_up_after;
    options.notify = [this](const std::string& notice) {
      absl::MutexLock lock(&mu_);
      text_ += notice + "\n";
    };
    return options;
  }
  std::string text() const {
    absl::MutexLock lock(&mu_);
    return text_;
  }

 private:
  mutable absl::Mutex mu_;
  std::string text_;
};

class ReconnectingCallsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    server_ = StartServer(/*listen=*/true);
    ASSERT_NE(server_, nullptr);
    proxy_ = std::make_unique<TcpProxy>(PortOf(server_->target()));
    absl::StatusOr<std::unique_ptr<ReconstructionClient>> through_proxy =
        ReconstructionClient::Connect(absl::StrCat("127.0.0.1:", proxy_->port()));
    ASSERT_TRUE(through_proxy.ok()) << through_proxy.status();
    client_ = *std::move(through_proxy);
    absl::StatusOr<std::unique_ptr<ReconstructionClient>> direct =
        ReconstructionClient::Connect(server_->target());
    ASSERT_TRUE(direct.ok()) << direct.status();
    direct_ = *std::move(direct);
  }

  std::string CreateSession(uint64_t target) {
    absl::StatusOr<v1::Session> session = direct_->CreateSession(SphereConfig(target), "sphere");
    EXPECT_TRUE(session.ok()) << session.status();
    return session.ok() ? session->session_id() : "";
  }

  // An upload progress callback that runs `cut` after the batch that ends at `at_point`, once
  // (a resumed upload may send that batch again).
  static ReconstructionClient::UploadProgress At(size_t at_point, std::function<void()> cut) {
    auto done = std::make_shared<bool>(false);
    return [at_point, cut = std::move(cut), done](uint64_t sent, uint64_t) {
      if (sent == at_point && !*done) {
        *done = true;
        cut();
      }
    };
  }

  // Cuts the connections and refuses new ones, as a server that went away; after `delay`, on a
  // thread of its own, runs `then`.
  std::thread CutAndRefuse(absl::Duration delay, std::function<void()> then) {
    proxy_->SetRefusing(true);
    proxy_->CutNow();
    return std::thread([delay, then = std::move(then)] {
      absl::SleepFor(delay);
      then();
    });
  }

  std::unique_ptr<ReconstructionServer> server_;
  std::unique_ptr<TcpProxy> proxy_;
  std::unique_ptr<ReconstructionClient> client_;  // Through the proxy.
  std::unique_ptr<ReconstructionClient> direct_;  // Straight to the server.
  const PointCloud cloud_ = SpherePoints(kPoints, /*seed=*/21);
};

TEST_F(ReconnectingCallsTest, AnUploadGoesOnFromThePointsTheSessionTookAndEndsOnTheSphere) {
  const std::string id = CreateSession(400);
  Notices notices;
  absl::StatusOr<v1::UploadPointsResponse> uploaded = UploadPointsReconnecting(
      *client_, id, cloud_, kBatch, At(20 * kBatch, [&] { proxy_->CutNow(); }), 0,
      notices.Options(absl::Seconds(30)));
  ASSERT_TRUE(uploaded.ok()) << uploaded.status() << "\n" << notices.text();
  EXPECT_EQ(uploaded->total_points(), kPoints);
  EXPECT_THAT(notices.text(), HasSubstr("lost (UploadPoints"));
  // From the points the session had taken at the cut: whole batches, none when the batches
  // before the cut were still on their way.
  std::smatch match;
  const std::string text = notices.text();
  ASSERT_TRUE(std::regex_search(
      text, match,
      std::regex(absl::StrCat("reconnected: the upload into session ", id,
                              " goes on at point ([0-9]+) of 60000"))))
      << text;
  EXPECT_EQ(std::stoull(match[1]) % kBatch, 0u);
  EXPECT_LE(std::stoull(match[1]), 20 * kBatch);

  absl::StatusOr<v1::Session> finished = FinishReconnecting(*client_, id, notices.Options(absl::Seconds(30)));
  ASSERT_TRUE(finished.ok()) << finished.status();
  absl::StatusOr<v1::MeshUpdate> final_mesh =
      direct_->GetMesh(id, v1::MESH_VERSION_FINAL, /*wait=*/true, absl::Seconds(60));
  ASSERT_TRUE(final_mesh.ok()) << final_mesh.status();
  EXPECT_EQ(final_mesh->learning().points_received(), kPoints) << "every point exactly once";
  absl::StatusOr<TriangleMesh> mesh = DecodeMesh(final_mesh->draco_mesh());
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->positions.size(), 400u);
  absl::StatusOr<std::unique_ptr<ImplicitSurface>> sphere = MakeSphere(Vec3(0, 0, 0), 1.0);
  ASSERT_TRUE(sphere.ok());
  EXPECT_LT(server::testing::MaxVertexDistance(*mesh, **sphere), 0.05);
}

// A connection that keeps breaking. gRPC takes writes ahead of the network, so a cut may end
// the call only later, and several cuts may end one call; whatever the order, every point
// arrives once.
TEST_F(ReconnectingCallsTest, AnUploadRidesOutAConnectionThatKeepsBreaking) {
  const std::string id = CreateSession(400);
  Notices notices;
  size_t cuts = 0;
  uint64_t last_cut_at = 0;
  absl::StatusOr<v1::UploadPointsResponse> uploaded = UploadPointsReconnecting(
      *client_, id, cloud_, kBatch,
      [&](uint64_t sent, uint64_t) {
        if (sent % (15 * kBatch) == 0 && sent > last_cut_at && sent < kPoints) {
          last_cut_at = sent;
          ++cuts;
          proxy_->CutNow();
        }
      },
      0, notices.Options(absl::Seconds(30)));
  ASSERT_TRUE(uploaded.ok()) << uploaded.status() << "\n" << notices.text();
  EXPECT_EQ(cuts, 3u);
  EXPECT_THAT(notices.text(), HasSubstr("reconnected: the upload into session"));
  absl::StatusOr<v1::Session> session = direct_->GetSession(id);
  ASSERT_TRUE(session.ok()) << session.status();
  EXPECT_EQ(session->points_taken(), kPoints);
}

TEST_F(ReconnectingCallsTest, AWatchGoesOnAfterItsLastUpdateToTheFinalMesh) {
  const std::string id = CreateSession(3000);
  std::vector<uint64_t> sequences;
  bool final_received = false;
  Notices notices;
  std::thread watcher([&] {
    const absl::Status watched = WatchReconnecting(
        *client_, id, 0,
        [&](const v1::MeshUpdate& update) {
          sequences.push_back(update.sequence());
          if (sequences.size() == 2) proxy_->CutNow();
          final_received = update.kind() == v1::UPDATE_KIND_FINAL;
          return true;
        },
        notices.Options(absl::Seconds(30)));
    EXPECT_TRUE(watched.ok()) << watched;
  });
  ASSERT_TRUE(direct_->UploadPoints(id, cloud_, kBatch).ok());
  ASSERT_TRUE(direct_->Finish(id).ok());
  watcher.join();
  EXPECT_TRUE(final_received);
  ASSERT_GE(sequences.size(), 3u);
  for (size_t i = 1; i < sequences.size(); ++i) EXPECT_GT(sequences[i], sequences[i - 1]);
  EXPECT_THAT(notices.text(), HasSubstr("lost (WatchSession"));
  // Updates already on their way arrive before the cut shows, so the watch goes on after the
  // second update or a later one: the last it delivered before the reconnect.
  std::smatch match;
  const std::string text = notices.text();
  ASSERT_TRUE(std::regex_search(
      text, match,
      std::regex(absl::StrCat("reconnected: watching session ", id, " again after update ([0-9]+)"))))
      << text;
  const uint64_t resumed_after = std::stoull(match[1]);
  EXPECT_GE(resumed_after, sequences[1]);
  EXPECT_NE(std::find(sequences.begin(), sequences.end(), resumed_after), sequences.end());
}

TEST_F(ReconnectingCallsTest, AnUploadGivesUpWhenTheServerStaysAwayAndTheSessionKeepsItsPoints) {
  const std::string id = CreateSession(400);
  Notices notices;
  const absl::Time start = absl::Now();
  absl::StatusOr<v1::UploadPointsResponse> uploaded = UploadPointsReconnecting(
      *client_, id, cloud_, kBatch,
      At(20 * kBatch,
         [&] {
           proxy_->SetRefusing(true);
           proxy_->CutNow();
         }),
      0, notices.Options(absl::Seconds(2)));
  const absl::Duration took = absl::Now() - start;
  ASSERT_FALSE(uploaded.ok());
  EXPECT_TRUE(absl::IsUnavailable(uploaded.status())) << uploaded.status();
  EXPECT_THAT(uploaded.status().message(), HasSubstr("did not answer again within 2s"));
  EXPECT_GE(took, absl::Seconds(2));
  EXPECT_LT(took, absl::Seconds(20));
  EXPECT_THAT(notices.text(), HasSubstr("reconnecting for up to 2s"));
  absl::StatusOr<v1::Session> kept = direct_->GetSession(id);
  ASSERT_TRUE(kept.ok()) << kept.status();
  EXPECT_TRUE(kept->state() == v1::SESSION_STATE_COLLECTING ||
              kept->state() == v1::SESSION_STATE_LEARNING)
      << v1::SessionState_Name(kept->state());
  EXPECT_LE(kept->points_taken(), 20 * kBatch);
}

TEST_F(ReconnectingCallsTest, AServerThatComesBackLateStillGetsTheWholeUpload) {
  const std::string id = CreateSession(400);
  Notices notices;
  std::thread back;
  absl::StatusOr<v1::UploadPointsResponse> uploaded = UploadPointsReconnecting(
      *client_, id, cloud_, kBatch,
      At(20 * kBatch,
         [&] { back = CutAndRefuse(absl::Seconds(2), [&] { proxy_->SetRefusing(false); }); }),
      0, notices.Options(absl::Seconds(30)));
  back.join();
  ASSERT_TRUE(uploaded.ok()) << uploaded.status() << "\n" << notices.text();
  absl::StatusOr<v1::Session> session = direct_->GetSession(id);
  ASSERT_TRUE(session.ok()) << session.status();
  EXPECT_EQ(session->points_taken(), kPoints);
}

TEST_F(ReconnectingCallsTest, ASessionTheServerNoLongerHasEndsTheUploadWithNotFound) {
  const std::string id = CreateSession(400);
  Notices notices;
  absl::StatusOr<v1::UploadPointsResponse> uploaded = UploadPointsReconnecting(
      *client_, id, cloud_, kBatch,
      At(20 * kBatch,
         [&] {
           proxy_->CutNow();
           ASSERT_TRUE(direct_->Delete(id).ok());
         }),
      0, notices.Options(absl::Seconds(30)));
  ASSERT_FALSE(uploaded.ok());
  EXPECT_TRUE(absl::IsNotFound(uploaded.status())) << uploaded.status();
  EXPECT_THAT(uploaded.status().message(),
              HasSubstr(absl::StrCat("session ", id, " is no longer on 127.0.0.1:")));
}

TEST_F(ReconnectingCallsTest, WithoutAWindowTheFirstLostConnectionEndsTheUpload) {
  const std::string id = CreateSession(400);
  Notices notices;
  absl::StatusOr<v1::UploadPointsResponse> uploaded = UploadPointsReconnecting(
      *client_, id, cloud_, kBatch, At(20 * kBatch, [&] { proxy_->CutNow(); }), 0,
      notices.Options(absl::ZeroDuration()));
  ASSERT_FALSE(uploaded.ok());
  EXPECT_TRUE(absl::IsUnavailable(uploaded.status())) << uploaded.status();
  EXPECT_EQ(notices.text(), "");
}

TEST_F(ReconnectingCallsTest, CancelCallsEndsAReconnectAtOnce) {
  const std::string id = CreateSession(400);
  Notices notices;
  std::thread canceller;
  const absl::Time start = absl::Now();
  absl::StatusOr<v1::UploadPointsResponse> uploaded = UploadPointsReconnecting(
      *client_, id, cloud_, kBatch,
      At(20 * kBatch,
         [&] {
           canceller = CutAndRefuse(absl::Milliseconds(500), [&] { client_->CancelCalls(); });
         }),
      0, notices.Options(absl::Seconds(60)));
  canceller.join();
  ASSERT_FALSE(uploaded.ok());
  EXPECT_TRUE(absl::IsCancelled(uploaded.status())) << uploaded.status();
  EXPECT_LT(absl::Now() - start, absl::Seconds(20)) << "not the 60 s window";
}

// A finish whose connection is lost asks again once the server answers; a finish the session
// took already (its answer lost) is not sent twice.
TEST_F(ReconnectingCallsTest, AFinishIsAskedAgainUnlessTheSessionIsFinishingAlready) {
  for (const bool finished_meanwhile : {false, true}) {
    SCOPED_TRACE(finished_meanwhile ? "finished meanwhile" : "not finished");
    const std::string id = CreateSession(400);
    ASSERT_TRUE(direct_->UploadPoints(id, cloud_, kBatch).ok());
    std::thread back =
        CutAndRefuse(absl::Milliseconds(500), [&] { proxy_->SetRefusing(false); });
    if (finished_meanwhile) {
      EXPECT_TRUE(direct_->Finish(id).ok());  // While the proxy refuses.
    }
    Notices notices;
    absl::StatusOr<v1::Session> finished =
        FinishReconnecting(*client_, id, notices.Options(absl::Seconds(30)));
    back.join();
    ASSERT_TRUE(finished.ok()) << finished.status() << "\n" << notices.text();
    EXPECT_TRUE(finished->state() == v1::SESSION_STATE_FINISHING ||
                finished->state() == v1::SESSION_STATE_FINISHED)
        << v1::SessionState_Name(finished->state());
    EXPECT_EQ(absl::StrContains(notices.text(), "is finishing"), finished_meanwhile)
        << notices.text();
  }
}

// A server restoring its sessions after a restart: ListSessions answers UNAVAILABLE, as
// server/session_manager.h does, for the first `restoring` calls, then the list.
class RestoringService final : public v1::ReconstructionService::Service {
 public:
  explicit RestoringService(int restoring) : restoring_(restoring) {}
  grpc::Status ListSessions(grpc::ServerContext*, const v1::ListSessionsRequest*,
                            v1::ListSessionsResponse* response) override {
    absl::MutexLock lock(&mu_);
    if (++calls_ <= restoring_) {
      return grpc::Status(grpc::StatusCode::UNAVAILABLE,
                          absl::StrCat("the server is restoring its sessions after a restart (",
                                       calls_ - 1, " of 2 done); try again in a moment"));
    }
    response->add_sessions()->set_session_id("s-restored");
    return grpc::Status::OK;
  }
  int calls() const {
    absl::MutexLock lock(&mu_);
    return calls_;
  }

 private:
  const int restoring_;
  mutable absl::Mutex mu_;
  int calls_ ABSL_GUARDED_BY(mu_) = 0;
};

// RestoringService on 127.0.0.1, and a client of it.
class RestoringServer {
 public:
  explicit RestoringServer(int restoring) : service_(restoring) {
    grpc::ServerBuilder builder;
    int port = 0;
    builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
    builder.RegisterService(&service_);
    server_ = builder.BuildAndStart();
    absl::StatusOr<std::unique_ptr<ReconstructionClient>> client =
        ReconstructionClient::Connect(absl::StrCat("127.0.0.1:", port));
    EXPECT_TRUE(client.ok()) << client.status();
    if (client.ok()) client_ = *std::move(client);
  }
  ~RestoringServer() { server_->Shutdown(); }
  // Null when it could not connect.
  ReconstructionClient* client() const { return client_.get(); }
  int calls() const { return service_.calls(); }

 private:
  RestoringService service_;
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<ReconstructionClient> client_;
};

TEST(ListSessionsReconnectingTest, AListingWaitsUntilTheServerHasRestoredItsSessions) {
  RestoringServer server(/*restoring=*/2);
  ASSERT_NE(server.client(), nullptr);
  Notices notices;
  absl::StatusOr<std::vector<v1::Session>> sessions =
      ListSessionsReconnecting(*server.client(), notices.Options(absl::Seconds(30)));
  ASSERT_TRUE(sessions.ok()) << sessions.status();
  ASSERT_EQ(sessions->size(), 1u);
  EXPECT_EQ((*sessions)[0].session_id(), "s-restored");
  EXPECT_EQ(server.calls(), 3);
  EXPECT_THAT(notices.text(), HasSubstr("restoring its sessions after a restart (0 of 2 done)"));
}

TEST(ListSessionsReconnectingTest, GivesUpWhenTheRestoreOutlastsTheWindowOrAtOnceWithoutOne) {
  RestoringServer server(/*restoring=*/1000000);
  ASSERT_NE(server.client(), nullptr);
  Notices notices;
  const absl::Status late =
      ListSessionsReconnecting(*server.client(), notices.Options(absl::Seconds(1))).status();
  EXPECT_TRUE(absl::IsUnavailable(late)) << late;
  EXPECT_THAT(late.message(), HasSubstr("did not answer again within 1s"));
  EXPECT_GT(server.calls(), 1);

  const int before = server.calls();
  const absl::Status at_once =
      ListSessionsReconnecting(*server.client(), notices.Options(absl::ZeroDuration())).status();
  EXPECT_TRUE(absl::IsUnavailable(at_once)) << at_once;
  EXPECT_THAT(at_once.message(), HasSubstr("restoring its sessions"));
  EXPECT_EQ(server.calls(), before + 1);
}

}  // namespace
}  // namespace neuralmesh::client
