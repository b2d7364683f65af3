// The one place where the client turns gRPC statuses into absl::Status.
#ifndef NEURALMESH_CLIENT_GRPC_STATUS_H_
#define NEURALMESH_CLIENT_GRPC_STATUS_H_

#include <grpcpp/support/status.h>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"

namespace neuralmesh::client {

// Keeps the code and message of `status`; `what` names the call ("CreateSession") and is
// prefixed to the message. An UNAVAILABLE status that says nothing more gets a message that
// names the likely cause (no server at the address).
absl::Status FromGrpcStatus(const grpc::Status& status, absl::string_view what);

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_GRPC_STATUS_H_
