// The one place where absl::Status becomes grpc::Status. Domain classes in server/ return
// absl::Status; only the service layer converts, through this header.
#ifndef NEURALMESH_SERVER_GRPC_STATUS_H_
#define NEURALMESH_SERVER_GRPC_STATUS_H_

#include <grpcpp/support/status.h>

#include "absl/status/status.h"

namespace neuralmesh::server {

// Maps the code one to one (Abseil's and gRPC's canonical codes share their numbers) and keeps
// the message.
grpc::Status ToGrpcStatus(const absl::Status& status);

// The inverse, for tests and in-process callers.
absl::Status FromGrpcStatus(const grpc::Status& status);

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_GRPC_STATUS_H_
