// A gRPC server interceptor that counts every call with ServerMetrics: started when the call
// begins, handled with the status the server sends (CANCELLED when the call ends without one,
// as when its client goes away), and the handling time of unary calls.
//
//   creators.push_back(RpcMetricsInterceptorFactory(metrics));
//   builder.experimental().SetInterceptorCreators(std::move(creators));
//
// Calls refused before they reach the services (an access token or client certificate the
// server does not take) are not counted: gRPC answers them before any interceptor runs.
#ifndef NEURALMESH_SERVER_RPC_METRICS_INTERCEPTOR_H_
#define NEURALMESH_SERVER_RPC_METRICS_INTERCEPTOR_H_

#include <memory>

#include <grpcpp/support/server_interceptor.h>

#include "server/server_metrics.h"

namespace neuralmesh::server {

// The interceptor creator to give a grpc::ServerBuilder; `metrics` must outlive the server.
std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>
RpcMetricsInterceptorFactory(ServerMetrics* metrics);

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_RPC_METRICS_INTERCEPTOR_H_
