#include "client/web/mesh_relay.h"

#include <utility>

#include "absl/time/clock.h"

namespace neuralmesh::client::web {

MeshRelay::MeshRelay(std::shared_ptr<grpc::Channel> channel, const ClientOptions& options,
                     std::string session_id)
    : session_id_(std::move(session_id)),
      client_(std::move(channel), options),
      last_used_(absl::Now()) {
  thread_ = std::thread([this] { Run(); });
}

MeshRelay::~MeshRelay() { Stop(); }

void MeshRelay::Run() {
  const absl::Status status = client_.Watch(session_id_, 0, [this](const v1::MeshUpdate& update) {
    auto latest = std::make_shared<const v1::MeshUpdate>(update);
    absl::MutexLock lock(&mu_);
    state_.latest = std::move(latest);
    return !stopped_;
  });
  absl::MutexLock lock(&mu_);
  state_.ended = true;
  state_.end_status = stopped_ ? absl::CancelledError("the viewer is shutting down") : status;
}

MeshRelay::State MeshRelay::WaitForNewer(uint64_t after_sequence, absl::Duration timeout) {
  absl::MutexLock lock(&mu_);
  last_used_ = absl::Now();
  auto ready = [this, after_sequence]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
    return state_.ended || stopped_ ||
           (state_.latest != nullptr && state_.latest->sequence() > after_sequence);
  };
  mu_.AwaitWithTimeout(absl::Condition(&ready), timeout);
  last_used_ = absl::Now();
  State state = state_;
  if (stopped_ && !state.ended) {
    state.ended = true;
    state.end_status = absl::CancelledError("the viewer is shutting down");
  }
  return state;
}

MeshRelay::State MeshRelay::Peek() const {
  absl::MutexLock lock(&mu_);
  return state_;
}

absl::Time MeshRelay::last_used() const {
  absl::MutexLock lock(&mu_);
  return last_used_;
}

void MeshRelay::Stop() {
  {
    absl::MutexLock lock(&mu_);
    if (stopped_) return;
    stopped_ = true;
  }
  client_.CancelCalls();
  thread_.join();
}

}  // namespace neuralmesh::client::web
