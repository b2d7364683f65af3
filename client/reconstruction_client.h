// A small typed client of the neuralmesh.v1 ReconstructionService
// (proto/neuralmesh/v1/reconstruction.proto): one method per rpc, absl::Status results, point
// clouds uploaded in batches, and session updates delivered to a callback.
//
//   NM_ASSIGN_OR_RETURN(auto client, ReconstructionClient::Connect("127.0.0.1:50051"));
//   NM_ASSIGN_OR_RETURN(v1::Session s, client->CreateSession(config, "scan"));
//   std::thread watcher([&] { client->Watch(s.session_id(), 0, on_update); });
//   client->UploadPoints(s.session_id(), cloud, 10000, on_progress);
//   client->Finish(s.session_id());
//   watcher.join();
//
// or, in one call that creates the session, streams the points and returns the final mesh:
//
//   NM_ASSIGN_OR_RETURN(ReconstructResult r,
//                       client->Reconstruct(config, "scan", cloud, 10000, on_update));
//
// Thread-safety: all methods may be called concurrently (gRPC stubs are thread-safe); a
// typical client watches on one thread while it uploads on another.
#ifndef NEURALMESH_CLIENT_RECONSTRUCTION_CLIENT_H_
#define NEURALMESH_CLIENT_RECONSTRUCTION_CLIENT_H_

#include <grpcpp/channel.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "client/channel_credentials.h"
#include "client/point_upload.h"
#include "core/point_cloud.h"
#include "core/triangle_mesh.h"
#include "neuralmesh/v1/reconstruction.grpc.pb.h"

namespace neuralmesh::client {

namespace v1 = ::neuralmesh::v1;

// What a Reconstruct call delivered.
struct ReconstructResult {
  v1::Session session;        // The session the call created (the call's first response).
  v1::PointsAck last_ack;     // The server's last acknowledgement of the points received.
  v1::MeshUpdate final_mesh;  // The final mesh (kind UPDATE_KIND_FINAL).
};

struct ClientOptions {
  // How long Connect waits for the server to accept a connection.
  absl::Duration connect_timeout = absl::Seconds(5);
  // Deadline of each simple rpc (not of UploadPoints, Watch, Reconstruct or a waiting GetMesh).
  absl::Duration call_timeout = absl::Seconds(30);
  // While a call is open on a channel that Connect made, the client pings the server after
  // `keepalive_time` without a frame from it and drops the connection when the ping is not
  // answered within `keepalive_timeout`: a server that stops answering (frozen, or cut off
  // without a reset) ends UploadPoints, Watch and Reconstruct with UNAVAILABLE instead of
  // leaving them waiting forever. neuralmesh-server accepts pings up to once a second.
  absl::Duration keepalive_time = absl::Seconds(20);
  absl::Duration keepalive_timeout = absl::Seconds(10);
  // The largest message the client takes, as neuralmesh-server's --max_message_bytes (whose
  // default it shares). gRPC's own default, 4 MiB, would refuse the meshes of sessions past
  // about two million vertices (Draco takes about 2 bytes a vertex).
  int max_message_bytes = 64 << 20;
  // TLS and the access token of the channel that Connect opens (none: plaintext).
  ClientSecurity security;
};

class ReconstructionClient {
 public:
  // Opens a channel to `address` ("host:port"), secured as `options.security` says, and waits
  // until it is connected. Returns UNAVAILABLE naming the address and gRPC's last error (no
  // server there, a failed TLS handshake) when no connection is made within
  // `options.connect_timeout`; INVALID_ARGUMENT for an empty address or security parts that
  // do not go together.
  static absl::StatusOr<std::unique_ptr<ReconstructionClient>> Connect(
      const std::string& address, const ClientOptions& options = {});

  // Uses an existing channel (for example an in-process one in tests).
  ReconstructionClient(std::shared_ptr<grpc::Channel> channel, const ClientOptions& options);

  const std::string& address() const { return address_; }
  // The channel, for more clients of the same connection (each with its own CancelCalls).
  const std::shared_ptr<grpc::Channel>& channel() const { return channel_; }
  const ClientOptions& options() const { return options_; }

  // CreateSession, learning from `start_mesh` when it is not null
  // (CreateSessionRequest.start_mesh). INVALID_ARGUMENT for an invalid config or start mesh,
  // RESOURCE_EXHAUSTED when the server is full.
  absl::StatusOr<v1::Session> CreateSession(const v1::SessionConfig& config,
                                            const std::string& name,
                                            const TriangleMesh* start_mesh = nullptr);

  // Called after each batch is written, with the points written so far and the total (for a
  // file read where it lies, its records read so far and their number).
  using UploadProgress = std::function<void(uint64_t points_sent, uint64_t points_total)>;

  // Streams `cloud` into the session in batches of at most `batch_size` points (packed
  // float32, with the weights and normals the cloud carries), each marked with its place in
  // the cloud (PointBatch.first_point), from point `first_point` on: to resume an upload that
  // lost its connection, pass the session's points_taken (points it has already are skipped,
  // so resending is harmless). Returns the server's acknowledgement; on failure the server's
  // status (the batches before the bad one stay accepted); with nothing left to send, an
  // empty acknowledgement and no call. INVALID_ARGUMENT for an empty cloud, a zero batch size
  // or a first point beyond the cloud.
  absl::StatusOr<v1::UploadPointsResponse> UploadPoints(const std::string& session_id,
                                                        const PointCloud& cloud, size_t batch_size,
                                                        const UploadProgress& progress = {},
                                                        size_t first_point = 0);
  // The same for the points of `upload` (a file's records read where they lie:
  // FileRecordsUpload, LazFileUpload), with its progress (PointUpload::done and total).
  // INVALID_ARGUMENT for a zero batch size or a first point beyond the upload; the upload's
  // errors (a LAZ chunk that does not decode: INVALID_ARGUMENT) for the first batch, prefixed,
  // and for a later one as they are, after ending the call (the batches before it stay
  // accepted).
  absl::StatusOr<v1::UploadPointsResponse> UploadPoints(const std::string& session_id,
                                                        PointUpload& upload, size_t batch_size,
                                                        const UploadProgress& progress = {},
                                                        uint64_t first_point = 0);

  // Called with each published mesh; returning false ends the watch early.
  using UpdateCallback = std::function<bool(const v1::MeshUpdate&)>;

  // Watches the session, calling `on_update` for every update with a sequence number above
  // `after_sequence`, until the stream ends. Returns OK when the stream ended with OK (after
  // the final mesh) or `on_update` stopped it; otherwise the stream's status: CANCELLED (the
  // session was cancelled), NOT_FOUND (deleted or unknown), ABORTED (learning failed),
  // UNAVAILABLE (server gone).
  absl::Status Watch(const std::string& session_id, uint64_t after_sequence,
                     const UpdateCallback& on_update);

  // The Reconstruct rpc, everything in one bidirectional call: creates a session from
  // `config` (labelled `name`), streams `cloud` into it in batches of at most `batch_size`
  // points, half-closes (which finishes the session) and calls `on_update` with every mesh
  // update the server sends, coarse to fine, the final mesh last. `progress`, when set, gets
  // the points the server has acknowledged; acknowledgements are latest wins, so not every
  // batch is reported, but the last one is. Both callbacks run on the calling thread while
  // the points go out from a thread of the call's own; a slow callback holds back neither the
  // upload nor the learning (the server skips to the newest update meanwhile).
  //
  // Returns the session, the last acknowledgement and the final mesh when the call ended with
  // OK. Otherwise, before any call: INVALID_ARGUMENT for an empty cloud or a zero batch size;
  // from the server, its status, prefixed with "Reconstruct" and the session id once known:
  // INVALID_ARGUMENT for an invalid config or a bad batch (the session keeps the batches
  // accepted before and stays open: cancel or delete it), RESOURCE_EXHAUSTED when the server
  // or the session is full, CANCELLED when the session was cancelled, NOT_FOUND when it was
  // deleted, INTERNAL when its learning failed, UNAVAILABLE when the server went away.
  // CANCELLED also when `on_update` returned false before the final mesh: the call is
  // cancelled, but not the session, which the message names.
  absl::StatusOr<ReconstructResult> Reconstruct(const v1::SessionConfig& config,
                                                const std::string& name, const PointCloud& cloud,
                                                size_t batch_size, const UpdateCallback& on_update,
                                                const UploadProgress& progress = {});

  absl::StatusOr<v1::Session> GetSession(const std::string& session_id);
  // GetSession that first waits up to `timeout` for the channel to have a connection again
  // (gRPC's wait-for-ready), for a client riding out a lost connection: UNAVAILABLE or
  // DEADLINE_EXCEEDED when the server did not answer within `timeout`.
  absl::StatusOr<v1::Session> AwaitSession(const std::string& session_id, absl::Duration timeout);
  absl::StatusOr<std::vector<v1::Session>> ListSessions();
  // ListSessions that first waits up to `timeout` for a connection, as AwaitSession does.
  absl::StatusOr<std::vector<v1::Session>> AwaitSessions(absl::Duration timeout);
  absl::StatusOr<v1::Session> Finish(const std::string& session_id);
  absl::StatusOr<v1::Session> Cancel(const std::string& session_id);
  // The same with its own deadline (for a best-effort cancel that must not wait long).
  absl::StatusOr<v1::Session> Cancel(const std::string& session_id, absl::Duration timeout);
  absl::Status Delete(const std::string& session_id);
  // TransferSession: hands the session to the client `new_owner`.
  absl::StatusOr<v1::Session> Transfer(const std::string& session_id,
                                       const std::string& new_owner);

  // GetMesh; with `wait`, blocks up to `timeout` until the mesh exists (DEADLINE_EXCEEDED
  // after).
  absl::StatusOr<v1::MeshUpdate> GetMesh(const std::string& session_id, v1::MeshVersion version,
                                         bool wait, absl::Duration timeout);

  // Ends every call of this client in flight at once, without waiting for the server, and
  // every call started later except Cancel: each returns CANCELLED. The sessions go on; Cancel
  // still reaches the server, to stop one. For a client that is being interrupted.
  void CancelCalls();
  // Whether CancelCalls was called.
  bool calls_cancelled() const;

 private:
  // Registers a call's context for CancelCalls while the call is open.
  class OpenCall;

  // How a unary call is made: its deadline (none when infinite), whether it waits for the
  // channel to become ready, and whether it goes on after CancelCalls or is ended at once.
  struct UnaryCallOptions {
    absl::Duration timeout;
    bool wait_for_ready = false;
    bool runs_after_cancel_calls = false;
  };
  // A unary method of the stub (&Stub::GetSession, ...).
  template <typename Request, typename Response>
  using StubMethod = grpc::Status (v1::ReconstructionService::Stub::*)(grpc::ClientContext*,
                                                                      const Request&, Response*);
  // Makes the unary call `method` of the stub with `request`; a failure's message names the
  // call `name` (FromGrpcStatus).
  template <typename Request, typename Response>
  absl::StatusOr<Response> UnaryCall(StubMethod<Request, Response> method, const Request& request,
                                     const char* name, const UnaryCallOptions& options);

  absl::StatusOr<v1::Session> GetSession(const std::string& session_id, absl::Duration timeout,
                                         bool wait_for_ready);
  absl::StatusOr<std::vector<v1::Session>> ListSessions(absl::Duration timeout,
                                                        bool wait_for_ready);
  // A context whose deadline is `timeout` from now (none when infinite).
  static void SetDeadline(grpc::ClientContext& context, absl::Duration timeout);

  std::string address_;
  ClientOptions options_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::ReconstructionService::Stub> stub_;
  mutable absl::Mutex calls_mu_;
  std::vector<grpc::ClientContext*> open_calls_ ABSL_GUARDED_BY(calls_mu_);
  bool calls_cancelled_ ABSL_GUARDED_BY(calls_mu_) = false;
};

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_RECONSTRUCTION_CLIENT_H_
