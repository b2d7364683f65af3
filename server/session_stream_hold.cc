#include "server/session_stream_hold.h"

#include <utility>

namespace neuralmesh::server {

bool SessionStreamHold::Register(LiveReactor* reactor) {
  if (!reactors_->Add(reactor)) return false;
  registered_ = reactor;
  return true;
}

void SessionStreamHold::Attach(std::shared_ptr<Session> session) {
  session_ = std::move(session);
  session_->AddStream();
  streaming_ = true;
}

void SessionStreamHold::Subscribe(UpdateSubscriber* subscriber, uint64_t after_sequence) {
  subscription_ = session_->updates().Subscribe(subscriber, after_sequence);
}

void SessionStreamHold::Release() {
  if (subscription_.has_value()) session_->updates().Unsubscribe(*subscription_);
  subscription_.reset();
  if (streaming_) session_->RemoveStream();
  streaming_ = false;
  if (registered_ != nullptr) reactors_->Remove(registered_);
  registered_ = nullptr;
}

}  // namespace neuralmesh::server
