// Tests of client/grpc_status.h (named client_* because the server has a grpc_status of its
// own).
#include "client/grpc_status.h"
#include "gtest/gtest.h"

namespace neuralmesh::client {
namespace {

TEST(ClientGrpcStatusTest, OkStaysOk) {
  EXPECT_TRUE(FromGrpcStatus(grpc::Status::OK, "Anything").ok());
}

TEST(ClientGrpcStatusTest, KeepsTheCodeAndPrefixesTheCall) {
  const absl::Status status =
      FromGrpcStatus(grpc::Status(grpc::StatusCode::NOT_FOUND, "no session 'x'"), "GetSession");
  EXPECT_TRUE(absl::IsNotFound(status)) << status;
  EXPECT_EQ(status.message(), "GetSession: no session 'x'");
}

TEST(ClientGrpcStatusTest, EveryCodeMapsToTheSameAbslCode) {
  for (int code = 1; code <= 16; ++code) {
    const absl::Status status =
        FromGrpcStatus(grpc::Status(static_cast<grpc::StatusCode>(code), "m"), "Call");
    EXPECT_EQ(static_cast<int>(status.code()), code) << status;
  }
}

TEST(ClientGrpcStatusTest, UnavailableSaysThatNoServerMayBeThere) {
  const absl::Status status = FromGrpcStatus(
      grpc::Status(grpc::StatusCode::UNAVAILABLE, "failed to connect"), "ListSessions");
  EXPECT_TRUE(absl::IsUnavailable(status));
  EXPECT_NE(status.message().find("neuralmesh-server"), absl::string_view::npos) << status;
  EXPECT_NE(status.message().find("failed to connect"), absl::string_view::npos) << status;
}

}  // namespace
}  // namespace neuralmesh::client
