#include "client/grpc_status.h"

#include "absl/strings/str_cat.h"

namespace neuralmesh::client {

absl::Status FromGrpcStatus(const grpc::Status& status, absl::string_view what) {
  if (status.ok()) return absl::OkStatus();
  // grpc::StatusCode and absl::StatusCode share their numbering (both follow
  // google.rpc.Code), so the code converts by value.
  const auto code = static_cast<absl::StatusCode>(status.error_code());
  std::string message = status.error_message();
  if (code == absl::StatusCode::kUnavailable) {
    message = absl::StrCat("server unavailable (is neuralmesh-server running there?): ", message);
  } else if (code == absl::StatusCode::kDeadlineExceeded) {
    message = absl::StrCat("deadline exceeded: ", message);
  }
  return absl::Status(code, absl::StrCat(what, ": ", message));
}

}  // namespace neuralmesh::client
