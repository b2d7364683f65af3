#include "server/call_log_interceptor.h"

#include <string>
#include <utility>

#include <grpcpp/server_context.h>
#include <grpcpp/support/interceptor.h>
#include <grpcpp/support/status.h>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/strip.h"
#include "absl/time/clock.h"
#include "server/session_access.h"

namespace neuralmesh::server {
namespace {

using grpc::experimental::InterceptionHookPoints;
using grpc::experimental::ServerRpcInfo;

constexpr size_t kMaxMessageBytes = 200;

// "GetSession" of "/neuralmesh.v1.ReconstructionService/GetSession"; other services' methods
// keep their service ("grpc.health.v1.Health/Check").
std::string MethodName(absl::string_view full_method) {
  absl::ConsumePrefix(&full_method, "/");
  absl::ConsumePrefix(&full_method, "neuralmesh.v1.ReconstructionService/");
  return std::string(full_method);
}

// `message` on one line, at most kMaxMessageBytes of it.
std::string OneLine(absl::string_view message) {
  std::string out(message.substr(0, kMaxMessageBytes));
  for (char& c : out) {
    if (absl::ascii_iscntrl(static_cast<unsigned char>(c))) c = ' ';
  }
  if (message.size() > kMaxMessageBytes) out += "...";
  return out;
}

class CallLogInterceptor : public grpc::experimental::Interceptor {
 public:
  CallLogInterceptor(ServerRpcInfo* info, std::shared_ptr<EventLog> log, CallLogLevel level)
      : info_(info), log_(std::move(log)), level_(level) {}

  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    // Once per call (as in rpc_metrics_interceptor.cc, other batches may run beside it).
    if (methods->QueryInterceptionHookPoint(InterceptionHookPoints::PRE_SEND_STATUS)) {
      const grpc::Status status = methods->GetSendStatus();
      if (level_ == CallLogLevel::kAll || !status.ok()) Write(status);
    }
    methods->Proceed();
  }

 private:
  void Write(const grpc::Status& status) const {
    std::string line = absl::StrCat("call ", MethodName(info_->method()));
    if (const grpc::ServerContextBase* context = info_->server_context(); context != nullptr) {
      absl::StrAppend(&line, " from ", context->peer());
      const Caller caller = CallerOf(*context);
      if (!caller.client.empty()) absl::StrAppend(&line, " (client ", caller.client, ")");
    }
    absl::StrAppend(&line, ": ",
                    absl::StatusCodeToString(static_cast<absl::StatusCode>(status.error_code())));
    if (!status.error_message().empty()) {
      absl::StrAppend(&line, " (", OneLine(status.error_message()), ")");
    }
    absl::StrAppend(
        &line, absl::StrFormat(" in %.1f ms", absl::ToDoubleMilliseconds(absl::Now() - start_)));
    log_->RecordLine(line);
  }

  ServerRpcInfo* const info_;
  const std::shared_ptr<EventLog> log_;
  const CallLogLevel level_;
  const absl::Time start_ = absl::Now();
};

class CallLogFactory : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  CallLogFactory(std::shared_ptr<EventLog> log, CallLogLevel level)
      : log_(std::move(log)), level_(level) {}

  grpc::experimental::Interceptor* CreateServerInterceptor(ServerRpcInfo* info) override {
    return new CallLogInterceptor(info, log_, level_);
  }

 private:
  const std::shared_ptr<EventLog> log_;
  const CallLogLevel level_;
};

}  // namespace

absl::StatusOr<CallLogLevel> ParseCallLogLevel(absl::string_view text) {
  if (text == "none") return CallLogLevel::kNone;
  if (text == "errors") return CallLogLevel::kErrors;
  if (text == "all") return CallLogLevel::kAll;
  return absl::InvalidArgumentError(
      absl::StrCat("unknown call log level \"", text, "\"; use none, errors or all"));
}

std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface> CallLogInterceptorFactory(
    std::shared_ptr<EventLog> log, CallLogLevel level) {
  return std::make_unique<CallLogFactory>(std::move(log), level);
}

}  // namespace neuralmesh::server
