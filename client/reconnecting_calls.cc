#include "client/reconnecting_calls.h"

#include <algorithm>
#include <functional>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "core/status_macros.h"

namespace neuralmesh::client {
namespace {

// Pauses between attempts that got nowhere (the server answered, the call was lost again at
// once): the first, doubled each time up to the longest.
constexpr absl::Duration kFirstPause = absl::Milliseconds(250);
constexpr absl::Duration kLongestPause = absl::Seconds(4);
// How often a pause looks whether the client's calls were cancelled.
constexpr absl::Duration kPauseSlice = absl::Milliseconds(50);

// One call's way back after lost connections: the window of `give_up_after` from its last
// progress, and the pauses between attempts that got nowhere.
class Reconnection {
 public:
  Reconnection(ReconstructionClient& client, const std::string& session_id,
               const ReconnectOptions& options)
      : client_(client), session_id_(session_id), options_(options) {}

  // The call got further: a later loss gets a whole window again.
  void Progressed() {
    window_end_ = absl::InfiniteFuture();
    pause_ = absl::ZeroDuration();
  }

  void Notify(const std::string& notice) const {
    if (options_.notify) options_.notify(notice);
  }

  // After a call ended with `status`: once the server answers again, the session as it has it
  // now. `status` itself when it is not a lost connection or reconnecting is off; UNAVAILABLE
  // when the window ends first; NOT_FOUND when the server no longer has the session;
  // CANCELLED when the client's calls are cancelled meanwhile.
  absl::StatusOr<v1::Session> Recover(const absl::Status& status) {
    return AskAgain<v1::Session>(status, [this](absl::Duration left) {
      absl::StatusOr<v1::Session> session = client_.AwaitSession(session_id_, left);
      if (absl::IsNotFound(session.status())) {
        return absl::StatusOr<v1::Session>(absl::NotFoundError(absl::StrCat(
            "session ", session_id_, " is no longer on ", Server(),
            " after the connection was lost (a restarted server keeps no sessions)")));
      }
      return session;
    });
  }

  // After a call ended with `status`: `ask(time left)` until it answers with anything but
  // UNAVAILABLE or DEADLINE_EXCEEDED, pausing between attempts; as Recover otherwise.
  template <typename T>
  absl::StatusOr<T> AskAgain(const absl::Status& status,
                             const std::function<absl::StatusOr<T>(absl::Duration)>& ask) {
    if (!absl::IsUnavailable(status) || options_.give_up_after <= absl::ZeroDuration()) {
      return status;
    }
    if (window_end_ == absl::InfiniteFuture()) {
      window_end_ = absl::Now() + options_.give_up_after;
      Notify(absl::StrCat("connection to ", Server(), " lost (", status.message(),
                          "); reconnecting for up to ", absl::FormatDuration(options_.give_up_after)));
    }
    while (true) {
      if (!Pause()) break;
      pause_ = pause_ == absl::ZeroDuration() ? kFirstPause : std::min(2 * pause_, kLongestPause);
      absl::StatusOr<T> answer = ask(window_end_ - absl::Now());
      if (answer.ok()) return answer;
      if (!absl::IsUnavailable(answer.status()) && !absl::IsDeadlineExceeded(answer.status())) {
        return answer.status();
      }
    }
    if (client_.calls_cancelled()) {
      return absl::CancelledError(
          absl::StrCat(status.message(), "; cancelled while reconnecting"));
    }
    return absl::UnavailableError(absl::StrCat(status.message(), "; ", Server(),
                                               " did not answer again within ",
                                               absl::FormatDuration(options_.give_up_after)));
  }

 private:
  std::string Server() const {
    return client_.address().empty() ? "the server" : client_.address();
  }

  // Sleeps the current pause, or less when the window ends or the client's calls are
  // cancelled first; false in those two cases.
  bool Pause() const {
    const absl::Time until = std::min(absl::Now() + pause_, window_end_);
    for (absl::Time now = absl::Now(); now < until; now = absl::Now()) {
      if (client_.calls_cancelled()) return false;
      absl::SleepFor(std::min(kPauseSlice, until - now));
    }
    return !client_.calls_cancelled() && absl::Now() < window_end_;
  }

  ReconstructionClient& client_;
  const std::string& session_id_;
  const ReconnectOptions& options_;
  absl::Time window_end_ = absl::InfiniteFuture();  // None while the call gets on.
  absl::Duration pause_ = absl::ZeroDuration();
};

}  // namespace

absl::StatusOr<v1::UploadPointsResponse> UploadPointsReconnecting(
    ReconstructionClient& client, const std::string& session_id, const PointCloud& cloud,
    size_t batch_size, const ReconstructionClient::UploadProgress& progress, size_t first_point,
    const ReconnectOptions& options) {
  if (cloud.empty()) return absl::InvalidArgumentError("UploadPoints: no points to upload");
  CloudUpload upload(cloud, CloudUpload::Order::kStored);
  return UploadPointsReconnecting(client, session_id, upload, batch_size, progress, first_point,
                                  options);
}

absl::StatusOr<v1::UploadPointsResponse> UploadPointsReconnecting(
    ReconstructionClient& client, const std::string& session_id, PointUpload& upload,
    size_t batch_size, const ReconstructionClient::UploadProgress& progress, uint64_t first_point,
    const ReconnectOptions& options) {
  Reconnection reconnection(client, session_id, options);
  uint64_t from = first_point;
  while (true) {
    absl::StatusOr<v1::UploadPointsResponse> response =
        client.UploadPoints(session_id, upload, batch_size, progress, from);
    if (response.ok()) return response;
    NM_ASSIGN_OR_RETURN(const v1::Session session, reconnection.Recover(response.status()));
    if (!upload.SkipTo(session.points_taken()).ok()) {
      return absl::FailedPreconditionError(absl::StrCat(
          "session ", session_id, " has taken ", session.points_taken(), " points, more than the ",
          upload.size().value_or(0), " of this upload: another client uploads into it"));
    }
    if (session.points_taken() > from) reconnection.Progressed();
    from = session.points_taken();
    reconnection.Notify(absl::StrCat(
        "reconnected: the upload into session ", session_id, " goes on at point ", from,
        upload.size().has_value() ? absl::StrCat(" of ", *upload.size()) : std::string()));
  }
}

absl::Status WatchReconnecting(ReconstructionClient& client, const std::string& session_id,
                               uint64_t after_sequence,
                               const ReconstructionClient::UpdateCallback& on_update,
                               const ReconnectOptions& options) {
  Reconnection reconnection(client, session_id, options);
  uint64_t last_sequence = after_sequence;
  while (true) {
    const absl::Status status =
        client.Watch(session_id, last_sequence, [&](const v1::MeshUpdate& update) {
          last_sequence = update.sequence();
          reconnection.Progressed();
          return on_update(update);
        });
    if (status.ok()) return status;
    NM_RETURN_IF_ERROR(reconnection.Recover(status).status());
    reconnection.Notify(absl::StrCat("reconnected: watching session ", session_id,
                                     " again after update ", last_sequence));
  }
}

absl::StatusOr<v1::Session> FinishReconnecting(ReconstructionClient& client,
                                               const std::string& session_id,
                                               const ReconnectOptions& options) {
  Reconnection reconnection(client, session_id, options);
  while (true) {
    absl::StatusOr<v1::Session> finished = client.Finish(session_id);
    if (finished.ok()) return finished;
    NM_ASSIGN_OR_RETURN(v1::Session session, reconnection.Recover(finished.status()));
    if (session.state() == v1::SESSION_STATE_FINISHING ||
        session.state() == v1::SESSION_STATE_FINISHED) {
      reconnection.Notify(absl::StrCat("reconnected: session ", session_id, " is finishing"));
      return session;
    }
  }
}

absl::StatusOr<v1::Session> GetSessionReconnecting(ReconstructionClient& client,
                                                  const std::string& session_id,
                                                  const ReconnectOptions& options) {
  absl::StatusOr<v1::Session> session = client.GetSession(session_id);
  if (session.ok()) return session;
  Reconnection reconnection(client, session_id, options);
  return reconnection.Recover(session.status());
}

absl::StatusOr<std::vector<v1::Session>> ListSessionsReconnecting(
    ReconstructionClient& client, const ReconnectOptions& options) {
  absl::StatusOr<std::vector<v1::Session>> sessions = client.ListSessions();
  if (sessions.ok()) return sessions;
  const std::string no_session;
  Reconnection reconnection(client, no_session, options);
  return reconnection.AskAgain<std::vector<v1::Session>>(
      sessions.status(), [&client](absl::Duration left) { return client.AwaitSessions(left); });
}

}  // namespace neuralmesh::client
