// What a streaming reactor of the reconstruction service holds while its call lives, and lets
// go of once, from its last reaction: its place in the ReactorRegistry (so that shutdown can
// abort it), its session counted as streamed to (Session::AddStream: a session with open
// streams is not reaped as idle), and its subscription to the session's meshes.
//
//   hold_.Register(this) ... hold_.Attach(session); hold_.Subscribe(this, after);
//   void OnDone() override { hold_.Release(); delete this; }
//
// Not thread-safe: the reactor sets it up from its constructor and its reads, which gRPC
// serialises, and releases it after every other reaction.
#ifndef NEURALMESH_SERVER_SESSION_STREAM_HOLD_H_
#define NEURALMESH_SERVER_SESSION_STREAM_HOLD_H_

#include <cstdint>
#include <memory>
#include <optional>

#include "server/reactor_registry.h"
#include "server/session.h"
#include "server/update_channel.h"

namespace neuralmesh::server {

class SessionStreamHold {
 public:
  explicit SessionStreamHold(ReactorRegistry* reactors) : reactors_(reactors) {}

  SessionStreamHold(const SessionStreamHold&) = delete;
  SessionStreamHold& operator=(const SessionStreamHold&) = delete;

  // ReactorRegistry::Add. False once the server shuts down: the call must then end with
  // UNAVAILABLE.
  bool Register(LiveReactor* reactor);

  // Holds `session`, counted as streamed to until Release. Once.
  void Attach(std::shared_ptr<Session> session);

  // Subscribes `subscriber` to the attached session's meshes after `after_sequence`
  // (UpdateChannel::Subscribe, which may call it back at once). Once.
  void Subscribe(UpdateSubscriber* subscriber, uint64_t after_sequence);

  // The attached session; null before Attach.
  const std::shared_ptr<Session>& session() const { return session_; }
  bool subscribed() const { return subscription_.has_value(); }

  // Unsubscribes, ends the session's streaming count and unregisters, in that order: after it,
  // neither the session's channel nor the registry calls the reactor again. Idempotent.
  void Release();

 private:
  ReactorRegistry* const reactors_;
  LiveReactor* registered_ = nullptr;
  std::shared_ptr<Session> session_;
  bool streaming_ = false;
  std::optional<uint64_t> subscription_;
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_SESSION_STREAM_HOLD_H_
