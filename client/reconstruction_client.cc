#include "client/reconstruction_client.h"

#include <grpcpp/create_channel.h>
#include <grpcpp/security/credentials.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <thread>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "client/grpc_status.h"
#include "client/proto_conversion.h"
#include "core/status_macros.h"
#include "proto/packing.h"

namespace neuralmesh::client {

using Stub = v1::ReconstructionService::Stub;

namespace {

// The wire format is little-endian float32; copying the host's floats byte for byte is only
// right on a little-endian host.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "packing assumes little-endian");
static_assert(sizeof(Vec3f) == 3 * sizeof(float), "Vec3f must be three packed floats");

// The longest pause between two attempts to connect again.
constexpr absl::Duration kMaxReconnectBackoff = absl::Seconds(4);

int ToMillis(absl::Duration d) {
  return static_cast<int>(std::clamp<int64_t>(absl::ToInt64Milliseconds(d), 1, INT32_MAX));
}

gpr_timespec ToGprDeadline(absl::Duration timeout) {
  return gpr_time_add(gpr_now(GPR_CLOCK_MONOTONIC),
                      gpr_time_from_millis(absl::ToInt64Milliseconds(timeout), GPR_TIMESPAN));
}

// Why the channel has no connection, as gRPC tells it to a call that fails at once (connection
// refused, a TLS handshake that failed and why), with a guess at the cause where gRPC only saw
// the server close the connection; empty when the call tells nothing.
std::string LastConnectionError(const std::shared_ptr<grpc::Channel>& channel,
                                const ClientSecurity& security) {
  grpc::ClientContext context;
  context.set_deadline(ToGprDeadline(absl::Seconds(1)));
  v1::ListSessionsResponse response;
  const grpc::Status status = v1::ReconstructionService::NewStub(channel)->ListSessions(
      &context, v1::ListSessionsRequest(), &response);
  if (status.error_code() != grpc::StatusCode::UNAVAILABLE || status.error_message().empty()) {
    return "";
  }
  std::string hint;
  if (absl::StrContains(status.error_message(), "Socket closed")) {
    if (!security.tls.enabled) {
      hint = "; does the server want TLS (--tls, --tls_ca_file)?";
    } else if (security.tls.certificate_chain.empty()) {
      hint = "; does the server want a client certificate (--tls_cert_file, --tls_key_file)?";
    }
  }
  return absl::StrCat(" (", status.error_message(), hint, ")");
}

}  // namespace

class ReconstructionClient::OpenCall {
 public:
  // Whether the call runs after CancelCalls (a Cancel of the session) or is ended at once.
  enum Kind { kEndedAfterCancelCalls, kRunsAfterCancelCalls };
  OpenCall(ReconstructionClient& client, grpc::ClientContext& context,
           Kind kind = kEndedAfterCancelCalls)
      : client_(client), context_(context) {
    absl::MutexLock lock(&client_.calls_mu_);
    if (kind == kEndedAfterCancelCalls && client_.calls_cancelled_) context_.TryCancel();
    client_.open_calls_.push_back(&context_);
  }
  ~OpenCall() {
    absl::MutexLock lock(&client_.calls_mu_);
    auto& open = client_.open_calls_;
    open.erase(std::find(open.begin(), open.end(), &context_));
  }
  OpenCall(const OpenCall&) = delete;
  OpenCall& operator=(const OpenCall&) = delete;

 private:
  ReconstructionClient& client_;
  grpc::ClientContext& context_;
};

template <typename Request, typename Response>
absl::StatusOr<Response> ReconstructionClient::UnaryCall(StubMethod<Request, Response> method,
                                                         const Request& request,
                                                         const char* name,
                                                         const UnaryCallOptions& options) {
  grpc::ClientContext context;
  const OpenCall open(*this, context,
                      options.runs_after_cancel_calls ? OpenCall::kRunsAfterCancelCalls
                                                      : OpenCall::kEndedAfterCancelCalls);
  SetDeadline(context, options.timeout);
  context.set_wait_for_ready(options.wait_for_ready);
  Response response;
  const grpc::Status status = (stub_.get()->*method)(&context, request, &response);
  if (!status.ok()) return FromGrpcStatus(status, name);
  return response;
}

absl::StatusOr<std::unique_ptr<ReconstructionClient>> ReconstructionClient::Connect(
    const std::string& address, const ClientOptions& options) {
  if (address.empty()) return absl::InvalidArgumentError("empty server address");
  grpc::ChannelArguments args;
  args.SetInt(GRPC_ARG_KEEPALIVE_TIME_MS, ToMillis(options.keepalive_time));
  args.SetInt(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, ToMillis(options.keepalive_timeout));
  // Keep pinging while only the server sends (a Watch): gRPC stops after two pings otherwise.
  args.SetInt(GRPC_ARG_HTTP2_MAX_PINGS_WITHOUT_DATA, 0);
  // After a lost connection gRPC tries again with a growing pause, by default up to two
  // minutes; a client that waits for its server to come back (AwaitSession) should notice
  // within seconds.
  args.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, ToMillis(kMaxReconnectBackoff));
  args.SetMaxReceiveMessageSize(options.max_message_bytes);
  if (!options.security.tls.server_name.empty()) {
    args.SetSslTargetNameOverride(options.security.tls.server_name);
  }
  absl::StatusOr<std::shared_ptr<grpc::ChannelCredentials>> credentials =
      MakeChannelCredentials(options.security);
  if (!credentials.ok()) return credentials.status();
  std::shared_ptr<grpc::Channel> channel = grpc::CreateCustomChannel(address, *credentials, args);
  if (!channel->WaitForConnected(ToGprDeadline(options.connect_timeout))) {
    return absl::UnavailableError(absl::StrCat(
        "cannot reach a neuralmesh-server at ", address, " within ",
        absl::FormatDuration(options.connect_timeout), LastConnectionError(channel, options.security)));
  }
  auto client = std::make_unique<ReconstructionClient>(std::move(channel), options);
  client->address_ = address;
  return client;
}

ReconstructionClient::ReconstructionClient(std::shared_ptr<grpc::Channel> channel,
                                           const ClientOptions& options)
    : options_(options),
      channel_(std::move(channel)),
      stub_(v1::ReconstructionService::NewStub(channel_)) {}

void ReconstructionClient::SetDeadline(grpc::ClientContext& context, absl::Duration timeout) {
  if (timeout == absl::InfiniteDuration()) return;
  context.set_deadline(ToGprDeadline(timeout));
}

absl::StatusOr<v1::Session> ReconstructionClient::CreateSession(const v1::SessionConfig& config,
                                                                const std::string& name,
                                                                const TriangleMesh* start_mesh) {
  v1::CreateSessionRequest request;
  *request.mutable_config() = config;
  request.set_name(name);
  if (start_mesh != nullptr) *request.mutable_start_mesh() = ToProto(*start_mesh);
  return UnaryCall(&Stub::CreateSession, request, "CreateSession", {options_.call_timeout});
}

absl::StatusOr<v1::UploadPointsResponse> ReconstructionClient::UploadPoints(
    const std::string& session_id, const PointCloud& cloud, size_t batch_size,
    const UploadProgress& progress, size_t first_point) {
  if (cloud.empty()) return absl::InvalidArgumentError("UploadPoints: no points to upload");
  CloudUpload upload(cloud, CloudUpload::Order::kStored);
  return UploadPoints(session_id, upload, batch_size, progress, first_point);
}

absl::StatusOr<v1::UploadPointsResponse> ReconstructionClient::UploadPoints(
    const std::string& session_id, PointUpload& upload, size_t batch_size,
    const UploadProgress& progress, uint64_t first_point) {
  if (batch_size == 0) return absl::InvalidArgumentError("UploadPoints: batch size must be > 0");
  absl::StatusOr<v1::PointBatch> batch = upload.Batch(first_point, batch_size);
  if (!batch.ok()) {
    // A first point beyond the upload is the caller's argument; other errors are the input's.
    const absl::StatusCode code = absl::IsOutOfRange(batch.status())
                                      ? absl::StatusCode::kInvalidArgument
                                      : batch.status().code();
    return absl::Status(code, absl::StrCat("UploadPoints: ", batch.status().message()));
  }
  v1::UploadPointsResponse response;
  response.set_session_id(session_id);
  // A resumed upload whose every point the session has already: nothing to send.
  if (batch->packed().positions().empty()) return response;
  grpc::ClientContext context;
  const OpenCall open(*this, context);
  std::unique_ptr<grpc::ClientWriter<v1::UploadPointsRequest>> writer =
      stub_->UploadPoints(&context, &response);
  v1::UploadPointsRequest request;
  request.set_session_id(session_id);
  absl::Status batch_status;
  while (true) {
    const uint64_t points = batch->packed().positions().size() / (3 * sizeof(float));
    *request.mutable_batch() = *std::move(batch);
    // A failed write means the call is over (the server rejected a batch or went away);
    // Finish() below returns why.
    if (!writer->Write(request)) break;
    if (progress) progress(upload.done(), upload.total());
    batch = upload.Batch(request.batch().first_point().value() + points, batch_size);
    if (!batch.ok()) {
      batch_status = batch.status();
      context.TryCancel();
      break;
    }
    if (batch->packed().positions().empty()) break;
  }
  writer->WritesDone();
  const grpc::Status status = writer->Finish();
  if (!batch_status.ok()) return batch_status;
  if (!status.ok()) return FromGrpcStatus(status, "UploadPoints");
  return response;
}

absl::Status ReconstructionClient::Watch(const std::string& session_id, uint64_t after_sequence,
                                         const UpdateCallback& on_update) {
  grpc::ClientContext context;
  const OpenCall open(*this, context);
  v1::WatchSessionRequest request;
  request.set_session_id(session_id);
  request.set_after_sequence(after_sequence);
  std::unique_ptr<grpc::ClientReader<v1::MeshUpdate>> reader =
      stub_->WatchSession(&context, request);
  v1::MeshUpdate update;
  bool stopped = false;
  while (reader->Read(&update)) {
    if (!on_update(update)) {
      stopped = true;
      context.TryCancel();
      break;
    }
  }
  const grpc::Status status = reader->Finish();
  if (stopped) return absl::OkStatus();
  return FromGrpcStatus(status, "WatchSession");
}

absl::StatusOr<ReconstructResult> ReconstructionClient::Reconstruct(
    const v1::SessionConfig& config, const std::string& name, const PointCloud& cloud,
    size_t batch_size, const UpdateCallback& on_update, const UploadProgress& progress) {
  if (cloud.empty()) return absl::InvalidArgumentError("Reconstruct: no points to upload");
  if (batch_size == 0) return absl::InvalidArgumentError("Reconstruct: batch size must be > 0");
  grpc::ClientContext context;
  const OpenCall open(*this, context);
  std::unique_ptr<grpc::ClientReaderWriter<v1::ReconstructRequest, v1::ReconstructResponse>>
      stream = stub_->Reconstruct(&context);

  // gRPC's synchronous streams allow one writing and one reading thread at a time. The points
  // go out from this thread while the calling thread reads, so the callbacks can take their
  // time: the server never waits for a reader (latest wins). A failed write means the call is
  // over (the server ended it, or the reader below cancelled it); Finish says why.
  std::thread sender([&] {
    v1::ReconstructRequest request;
    v1::CreateSessionRequest* create = request.mutable_start()->mutable_create();
    *create->mutable_config() = config;
    create->set_name(name);
    if (!stream->Write(request)) return;
    for (size_t begin = 0; begin < cloud.size(); begin += batch_size) {
      const size_t end = std::min(cloud.size(), begin + batch_size);
      *request.mutable_points() = PackPointBatch(cloud, begin, end);
      if (!stream->Write(request)) return;
    }
    // Half-closing finishes the session: the server learns to the target and sends the final
    // mesh before it ends the call.
    stream->WritesDone();
  });

  ReconstructResult result;
  bool final_received = false;
  bool stopped = false;
  v1::ReconstructResponse response;
  while (!stopped && stream->Read(&response)) {
    switch (response.kind_case()) {
      case v1::ReconstructResponse::kSession:
        result.session = std::move(*response.mutable_session());
        break;
      case v1::ReconstructResponse::kAck:
        result.last_ack = response.ack();
        if (progress) {  // Points the server dropped as outliers were received all the same.
          progress(result.last_ack.points_accepted() + result.last_ack.points_held_back(),
                   cloud.size());
        }
        break;
      case v1::ReconstructResponse::kUpdate: {
        const bool final = response.update().kind() == v1::UPDATE_KIND_FINAL;
        // After the final mesh only the call's OK can follow, so there is nothing to stop.
        stopped = !on_update(response.update()) && !final;
        if (final) {
          final_received = true;
          result.final_mesh = std::move(*response.mutable_update());
        }
        break;
      }
      case v1::ReconstructResponse::KIND_NOT_SET:
        break;
    }
  }
  if (stopped) context.TryCancel();
  sender.join();
  const grpc::Status status = stream->Finish();

  const std::string& id = result.session.session_id();
  const std::string what = id.empty() ? "Reconstruct" : absl::StrCat("Reconstruct of session ", id);
  if (stopped) {
    return absl::CancelledError(absl::StrCat(
        what, ": stopped by the update callback; the session goes on until it is cancelled"));
  }
  if (!status.ok()) return FromGrpcStatus(status, what);
  if (!final_received) {
    // The server sends the final mesh before OK; anything else is a broken server.
    return absl::InternalError(absl::StrCat(what, ": the call ended without the final mesh"));
  }
  return result;
}

absl::StatusOr<v1::Session> ReconstructionClient::GetSession(const std::string& session_id) {
  return GetSession(session_id, options_.call_timeout, /*wait_for_ready=*/false);
}

absl::StatusOr<v1::Session> ReconstructionClient::AwaitSession(const std::string& session_id,
                                                               absl::Duration timeout) {
  return GetSession(session_id, timeout, /*wait_for_ready=*/true);
}

absl::StatusOr<v1::Session> ReconstructionClient::GetSession(const std::string& session_id,
                                                             absl::Duration timeout,
                                                             bool wait_for_ready) {
  v1::GetSessionRequest request;
  request.set_session_id(session_id);
  return UnaryCall(&Stub::GetSession, request, "GetSession", {timeout, wait_for_ready});
}

absl::StatusOr<std::vector<v1::Session>> ReconstructionClient::ListSessions() {
  return ListSessions(options_.call_timeout, /*wait_for_ready=*/false);
}

absl::StatusOr<std::vector<v1::Session>> ReconstructionClient::AwaitSessions(
    absl::Duration timeout) {
  return ListSessions(timeout, /*wait_for_ready=*/true);
}

absl::StatusOr<std::vector<v1::Session>> ReconstructionClient::ListSessions(
    absl::Duration timeout, bool wait_for_ready) {
  NM_ASSIGN_OR_RETURN(const v1::ListSessionsResponse response,
                      UnaryCall(&Stub::ListSessions, v1::ListSessionsRequest(), "ListSessions",
                                {timeout, wait_for_ready}));
  return std::vector<v1::Session>(response.sessions().begin(), response.sessions().end());
}

absl::StatusOr<v1::Session> ReconstructionClient::Finish(const std::string& session_id) {
  v1::FinishSessionRequest request;
  request.set_session_id(session_id);
  return UnaryCall(&Stub::FinishSession, request, "FinishSession", {options_.call_timeout});
}

absl::StatusOr<v1::Session> ReconstructionClient::Cancel(const std::string& session_id) {
  return Cancel(session_id, options_.call_timeout);
}

absl::StatusOr<v1::Session> ReconstructionClient::Cancel(const std::string& session_id,
                                                         absl::Duration timeout) {
  v1::CancelSessionRequest request;
  request.set_session_id(session_id);
  return UnaryCall(&Stub::CancelSession, request, "CancelSession",
                   {timeout, /*wait_for_ready=*/false, /*runs_after_cancel_calls=*/true});
}

absl::Status ReconstructionClient::Delete(const std::string& session_id) {
  v1::DeleteSessionRequest request;
  request.set_session_id(session_id);
  return UnaryCall(&Stub::DeleteSession, request, "DeleteSession", {options_.call_timeout})
      .status();
}

absl::StatusOr<v1::Session> ReconstructionClient::Transfer(const std::string& session_id,
                                                           const std::string& new_owner) {
  v1::TransferSessionRequest request;
  request.set_session_id(session_id);
  request.set_new_owner(new_owner);
  return UnaryCall(&Stub::TransferSession, request, "TransferSession", {options_.call_timeout});
}

absl::StatusOr<v1::MeshUpdate> ReconstructionClient::GetMesh(const std::string& session_id,
                                                             v1::MeshVersion version, bool wait,
                                                             absl::Duration timeout) {
  v1::GetMeshRequest request;
  request.set_session_id(session_id);
  request.set_version(version);
  request.set_wait(wait);
  return UnaryCall(&Stub::GetMesh, request, "GetMesh", {timeout});
}

bool ReconstructionClient::calls_cancelled() const {
  absl::MutexLock lock(&calls_mu_);
  return calls_cancelled_;
}

void ReconstructionClient::CancelCalls() {
  absl::MutexLock lock(&calls_mu_);
  calls_cancelled_ = true;
  for (grpc::ClientContext* context : open_calls_) context->TryCancel();
}

}  // namespace neuralmesh::client
