// The neuralmesh.v1.ReconstructionService on gRPC's callback API. Unary calls finish inline;
// each streaming call gets a reactor that deletes itself in OnDone. The flow control of every
// streaming reactor is explained in reconstruction_service.cc, next to the reactor.
#ifndef NEURALMESH_SERVER_RECONSTRUCTION_SERVICE_H_
#define NEURALMESH_SERVER_RECONSTRUCTION_SERVICE_H_

#include <cstddef>

#include "neuralmesh/v1/reconstruction.grpc.pb.h"
#include "server/executor.h"
#include "server/reactor_registry.h"
#include "server/session_manager.h"

namespace neuralmesh::server {

class ReconstructionService final : public v1::ReconstructionService::CallbackService {
 public:
  // `manager`, `reactors` and `filter` must outlive the service; `filter` runs the ingestion of
  // batches into sessions that filter outliers (off_thread_work.h), and must outlive every
  // task queued on it, dropping the queued ones at its shutdown if it likes.
  ReconstructionService(SessionManager* manager, ReactorRegistry* reactors, Executor* filter);

  grpc::ServerUnaryReactor* CreateSession(grpc::CallbackServerContext* context,
                                          const v1::CreateSessionRequest* request,
                                          v1::Session* response) override;
  grpc::ServerReadReactor<v1::UploadPointsRequest>* UploadPoints(
      grpc::CallbackServerContext* context, v1::UploadPointsResponse* response) override;
  grpc::ServerWriteReactor<v1::MeshUpdate>* WatchSession(
      grpc::CallbackServerContext* context, const v1::WatchSessionRequest* request) override;
  grpc::ServerBidiReactor<v1::ReconstructRequest, v1::ReconstructResponse>* Reconstruct(
      grpc::CallbackServerContext* context) override;
  grpc::ServerUnaryReactor* GetSession(grpc::CallbackServerContext* context,
                                       const v1::GetSessionRequest* request,
                                       v1::Session* response) override;
  grpc::ServerUnaryReactor* ListSessions(grpc::CallbackServerContext* context,
                                         const v1::ListSessionsRequest* request,
                                         v1::ListSessionsResponse* response) override;
  grpc::ServerUnaryReactor* FinishSession(grpc::CallbackServerContext* context,
                                          const v1::FinishSessionRequest* request,
                                          v1::Session* response) override;
  grpc::ServerUnaryReactor* CancelSession(grpc::CallbackServerContext* context,
                                          const v1::CancelSessionRequest* request,
                                          v1::Session* response) override;
  grpc::ServerUnaryReactor* DeleteSession(grpc::CallbackServerContext* context,
                                          const v1::DeleteSessionRequest* request,
                                          v1::DeleteSessionResponse* response) override;
  grpc::ServerUnaryReactor* TransferSession(grpc::CallbackServerContext* context,
                                            const v1::TransferSessionRequest* request,
                                            v1::Session* response) override;
  grpc::ServerUnaryReactor* GetMesh(grpc::CallbackServerContext* context,
                                    const v1::GetMeshRequest* request,
                                    v1::MeshUpdate* response) override;

 private:
  SessionManager* const manager_;
  ReactorRegistry* const reactors_;
  Executor* const filter_;
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_RECONSTRUCTION_SERVICE_H_
