// A gRPC server interceptor that writes a line to the event log (event_log.h) for each call
// that ends, or each that ends with an error (neuralmesh-server --log_calls):
//
//   2026-12-05T01:30:13.002Z call GetSession from ipv4:10.0.0.7:41240 (client alice): NOT_FOUND
//   (no session with id "s-1") in 0.2 ms
//
// (one line): the method, gRPC's peer address, the client name of the call's access token
// when it has one, the status code and message, and the time from the start of the call. A
// message is cut to its first 200 bytes, control characters replaced by spaces. Calls refused
// for their token or certificate never reach the interceptor (rpc_metrics_interceptor.h).
#ifndef NEURALMESH_SERVER_CALL_LOG_INTERCEPTOR_H_
#define NEURALMESH_SERVER_CALL_LOG_INTERCEPTOR_H_

#include <memory>

#include <grpcpp/support/server_interceptor.h>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "server/event_log.h"

namespace neuralmesh::server {

enum class CallLogLevel {
  kNone,    // No call is written.
  kErrors,  // Calls that end with any status but OK.
  kAll,     // Every call.
};

// "none", "errors" or "all"; INVALID_ARGUMENT naming the three otherwise.
absl::StatusOr<CallLogLevel> ParseCallLogLevel(absl::string_view text);

// The interceptor creator to give a grpc::ServerBuilder; writes to `log` the calls `level`
// names.
std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface> CallLogInterceptorFactory(
    std::shared_ptr<EventLog> log, CallLogLevel level);

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_CALL_LOG_INTERCEPTOR_H_
