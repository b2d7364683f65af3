#include "server/update_channel.h"

#include <utility>

namespace neuralmesh::server {

uint64_t UpdateChannel::Publish(std::shared_ptr<v1::MeshUpdate> update) {
  absl::MutexLock lock(&mu_);
  if (closed_.has_value()) return 0;
  update->set_sequence(++sequence_);
  latest_ = std::move(update);
  for (const auto& [handle, subscriber] : subscribers_) subscriber->OnUpdate(latest_);
  return sequence_;
}

void UpdateChannel::Restore(MeshUpdatePtr update) {
  absl::MutexLock lock(&mu_);
  sequence_ = update->sequence();
  latest_ = std::move(update);
}

void UpdateChannel::Close(const absl::Status& status) {
  absl::MutexLock lock(&mu_);
  if (closed_.has_value()) return;
  closed_ = status;
  for (const auto& [handle, subscriber] : subscribers_) subscriber->OnClose(status);
}

uint64_t UpdateChannel::Subscribe(UpdateSubscriber* subscriber, uint64_t after_sequence) {
  absl::MutexLock lock(&mu_);
  const uint64_t handle = next_handle_++;
  subscribers_.emplace(handle, subscriber);
  if (latest_ != nullptr && latest_->sequence() > after_sequence) subscriber->OnUpdate(latest_);
  if (closed_.has_value()) subscriber->OnClose(*closed_);
  return handle;
}

void UpdateChannel::Unsubscribe(uint64_t handle) {
  absl::MutexLock lock(&mu_);
  subscribers_.erase(handle);
}

MeshUpdatePtr UpdateChannel::latest() const {
  absl::MutexLock lock(&mu_);
  return latest_;
}

uint64_t UpdateChannel::next_sequence() const {
  absl::MutexLock lock(&mu_);
  return sequence_ + 1;
}

std::optional<absl::Status> UpdateChannel::close_status() const {
  absl::MutexLock lock(&mu_);
  return closed_;
}

size_t UpdateChannel::subscribers() const {
  absl::MutexLock lock(&mu_);
  return subscribers_.size();
}

}  // namespace neuralmesh::server
