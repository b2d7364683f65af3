#include "server/session_manager.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

namespace neuralmesh::server {
namespace {

SessionConfig SmallConfig() {
  SessionConfig config;
  config.target_vertices = 100;
  return config;
}

class SessionManagerTest : public ::testing::Test {
 protected:
  void TearDown() override {
    pool_.Shutdown();
    encoder_.Shutdown();
  }
  WorkerPool pool_{1, absl::Milliseconds(10)};
  Executor encoder_{1};
};

// Between the manager's shutdown and the server's, calls on sessions that existed get the
// UNAVAILABLE the API promises at shutdown, not a NOT_FOUND that says they never did.
TEST_F(SessionManagerTest, AfterShutdownCallsAreUnavailableNotNotFound) {
  SessionManager manager(SessionLimits(), &pool_, &encoder_);
  absl::StatusOr<std::shared_ptr<Session>> session = manager.Create(SmallConfig(), "s");
  ASSERT_TRUE(session.ok()) << session.status();
  const std::string id = (*session)->id();
  manager.Shutdown(absl::UnavailableError("the server is shutting down"));
  EXPECT_TRUE(absl::IsUnavailable(manager.Get(id).status())) << manager.Get(id).status();
  EXPECT_TRUE(absl::IsUnavailable(manager.Delete(id)));
  EXPECT_TRUE(absl::IsUnavailable(manager.List().status()));
  EXPECT_TRUE(absl::IsUnavailable(manager.Create(SmallConfig(), "late").status()));
}

}  // namespace
}  // namespace neuralmesh::server
