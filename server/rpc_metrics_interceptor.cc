#include "server/rpc_metrics_interceptor.h"

#include <string>

#include <grpcpp/support/interceptor.h>
#include <grpcpp/support/status.h>

#include "absl/time/clock.h"

namespace neuralmesh::server {
namespace {

using grpc::experimental::InterceptionHookPoints;
using grpc::experimental::ServerRpcInfo;

RpcType TypeOf(ServerRpcInfo::Type type) {
  switch (type) {
    case ServerRpcInfo::Type::UNARY:
      return RpcType::kUnary;
    case ServerRpcInfo::Type::CLIENT_STREAMING:
      return RpcType::kClientStream;
    case ServerRpcInfo::Type::SERVER_STREAMING:
      return RpcType::kServerStream;
    case ServerRpcInfo::Type::BIDI_STREAMING:
      return RpcType::kBidiStream;
  }
  return RpcType::kUnary;
}

class RpcMetricsInterceptor : public grpc::experimental::Interceptor {
 public:
  RpcMetricsInterceptor(ServerRpcInfo* info, ServerMetrics* metrics)
      : metrics_(metrics),
        method_(info->method() != nullptr ? info->method() : ""),
        type_(TypeOf(info->type())) {
    metrics_->CountRpcStarted(method_, type_);
  }

  // gRPC destroys the interceptor when the call is over.
  ~RpcMetricsInterceptor() override {
    if (!handled_) Handled(grpc::StatusCode::CANCELLED);
  }

  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    // Batches of one call may be intercepted on several threads at once (a read beside a
    // write), but the status is sent once: handled_ is touched here and in the destructor only.
    if (methods->QueryInterceptionHookPoint(InterceptionHookPoints::PRE_SEND_STATUS)) {
      Handled(methods->GetSendStatus().error_code());
    }
    methods->Proceed();
  }

 private:
  void Handled(grpc::StatusCode code) {
    handled_ = true;
    metrics_->CountRpcHandled(method_, type_, static_cast<int>(code), absl::Now() - start_);
  }

  ServerMetrics* const metrics_;
  const std::string method_;
  const RpcType type_;
  const absl::Time start_ = absl::Now();
  bool handled_ = false;
};

class RpcMetricsFactory : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  explicit RpcMetricsFactory(ServerMetrics* metrics) : metrics_(metrics) {}

  grpc::experimental::Interceptor* CreateServerInterceptor(ServerRpcInfo* info) override {
    return new RpcMetricsInterceptor(info, metrics_);
  }

 private:
  ServerMetrics* const metrics_;
};

}  // namespace

std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>
RpcMetricsInterceptorFactory(ServerMetrics* metrics) {
  return std::make_unique<RpcMetricsFactory>(metrics);
}

}  // namespace neuralmesh::server
