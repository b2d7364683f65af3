#include "server/session_manager.h"

#include <algorithm>
#include <utility>

#include "absl/random/random.h"
#include "absl/strings/ascii.h"
#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/learning/initial_mesh.h"
#include "core/status_macros.h"
#include "server/proto_conversion.h"
#include "server/session_restore.h"

namespace neuralmesh::server {
namespace {

constexpr size_t kMaxNameBytes = 256;
constexpr size_t kMaxQuotedIdBytes = 64;

absl::Status UnknownSession(absl::string_view id) {
  return absl::NotFoundError(absl::StrCat("no session with id ", QuotedSessionId(id)));
}

// "created by [client OWNER at ]PEER: "NAME", target N vertices" and the options that change
// how it learns.
std::string CreationEvent(const SessionConfig& config, absl::string_view name,
                          absl::string_view peer, absl::string_view owner,
                          const std::optional<TriangleMesh>& start_mesh) {
  std::string event = "created";
  if (!owner.empty()) absl::StrAppend(&event, " by client ", owner, peer.empty() ? "" : " at");
  if (!peer.empty()) absl::StrAppend(&event, owner.empty() ? " by " : " ", peer);
  absl::StrAppend(&event, ": \"", absl::CHexEscape(name), "\", target ", config.target_vertices,
                  " vertices");
  if (start_mesh.has_value()) {
    absl::StrAppend(&event, ", from a start mesh of ", start_mesh->positions.size(), " vertices");
  } else if (config.learner.initial_mesh == InitialMesh::kDisc) {
    absl::StrAppend(&event, ", disc start");
  }
  if (config.outlier_removal.has_value()) absl::StrAppend(&event, ", outlier removal");
  return event;
}

}  // namespace

absl::Status CheckStartMesh(const TriangleMesh& start_mesh, const SessionConfig& config) {
  if (start_mesh.positions.size() >= config.target_vertices) {
    return absl::InvalidArgumentError(absl::StrCat(
        "start_mesh has ", start_mesh.positions.size(), " vertices; it must have fewer than "
        "target_vertices (", config.target_vertices, ")"));
  }
  absl::StatusOr<Mesh> mesh = MakeStartMesh(start_mesh);
  if (!mesh.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("start_mesh: ", mesh.status().message()));
  }
  return absl::OkStatus();
}

std::string QuotedSessionId(absl::string_view id) {
  if (id.size() <= kMaxQuotedIdBytes) return absl::StrCat("\"", id, "\"");
  return absl::StrCat("\"", id.substr(0, kMaxQuotedIdBytes), "...\" (", id.size(), " bytes)");
}

SessionManager::SessionManager(const SessionLimits& limits, WorkerPool* pool, Executor* encoder,
                               std::shared_ptr<EventLog> log, SessionStore* store,
                               ServerMetrics* metrics)
    : limits_(limits),
      pool_(pool),
      encoder_(encoder),
      log_(std::move(log)),
      store_(store),
      metrics_(metrics) {
  {
    absl::MutexLock lock(&mu_);
    absl::BitGen gen;
    id_state_ = absl::Uniform<uint64_t>(gen);
  }
  if (limits_.idle_timeout != absl::InfiniteDuration()) {
    reaper_ = std::thread([this] { ReaperLoop(); });
  }
}

SessionManager::~SessionManager() {
  Shutdown(absl::UnavailableError("the server is shutting down"));
}

std::string SessionManager::NewIdLocked() {
  // SplitMix64 over a random start: unpredictable enough for a label, unique per server.
  while (true) {
    uint64_t z = (id_state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    std::string id = absl::StrFormat("s-%016x", z);
    if (sessions_.count(id) == 0 && unrestored_.count(id) == 0) return id;
  }
}

absl::StatusOr<std::shared_ptr<Session>> SessionManager::Create(
    SessionConfig config, std::string name, absl::string_view peer, std::string owner,
    std::optional<TriangleMesh> start_mesh) {
  if (name.size() > kMaxNameBytes) {
    return absl::InvalidArgumentError(
        absl::StrCat("name has ", name.size(), " bytes; at most 256 are allowed"));
  }
  NM_RETURN_IF_ERROR(ResolveSessionConfig(limits_.max_points_per_session, config));
  if (start_mesh.has_value()) NM_RETURN_IF_ERROR(CheckStartMesh(*start_mesh, config));
  const std::string event = CreationEvent(config, name, peer, owner, start_mesh);
  std::shared_ptr<Session> session;
  {
    absl::MutexLock lock(&mu_);
    if (shutdown_) return absl::UnavailableError("the server is shutting down");
    if (HeldLocked("") >= limits_.max_sessions) {
      return absl::ResourceExhaustedError(absl::StrCat(
          "the server holds its maximum of ", limits_.max_sessions,
          " sessions; delete finished or cancelled ones first"));
    }
    if (!owner.empty() && limits_.max_sessions_per_client > 0) {
      if (HeldLocked(owner) >= limits_.max_sessions_per_client) {
        return absl::ResourceExhaustedError(absl::StrCat(
            "client ", owner, " holds its maximum of ", limits_.max_sessions_per_client,
            " sessions; delete finished or cancelled ones first"));
      }
    }
    std::string id = NewIdLocked();
    session = std::make_shared<Session>(id, std::move(name), std::move(config),
                                        limits_.max_points_per_session, pool_, encoder_, log_,
                                        std::move(owner));
    if (store_ != nullptr) {
      storage::v1::StoredSession stored;
      stored.set_session_id(id);
      stored.set_name(session->name());
      stored.set_owner(session->owner());
      *stored.mutable_config() = SessionConfigToProto(session->config());
      stored.set_create_time_us(absl::ToUnixMicros(session->create_time()));
      stored.set_state(v1::SESSION_STATE_COLLECTING);
      absl::StatusOr<std::unique_ptr<SessionRecord>> record = store_->Create(stored);
      // A start mesh is the session's first checkpoint: a restart learns on from it.
      if (record.ok() && start_mesh.has_value()) {
        if (absl::Status written = (*record)->WriteCheckpoint(*start_mesh, v1::LearningState());
            !written.ok()) {
          (*record)->Remove().IgnoreError();  // A session it could not keep is no session.
          record = written;
        }
      }
      if (!record.ok()) {
        return absl::Status(record.status().code(),
                            absl::StrCat("the server cannot keep a new session on disk: ",
                                         record.status().message()));
      }
      session->AttachRecord(*std::move(record));
    }
    if (start_mesh.has_value()) session->SetStartMesh(*std::move(start_mesh));
    session->AttachMetrics(metrics_);
    sessions_.emplace(id, session);
    order_.emplace(created_++, id);
  }
  if (metrics_ != nullptr) metrics_->CountSessionCreated();
  if (log_ != nullptr) log_->Record(session->id(), event);
  return session;
}

absl::StatusOr<std::shared_ptr<Session>> SessionManager::Transfer(
    absl::string_view id, std::string new_owner, absl::string_view by,
    absl::FunctionRef<absl::Status(const Session&)> allowed) {
  if (id.empty()) return absl::InvalidArgumentError("session_id is empty");
  if (new_owner.empty()) return absl::InvalidArgumentError("new_owner is empty");
  if (new_owner.size() > kMaxNameBytes) {
    return absl::InvalidArgumentError(absl::StrCat("new_owner has ", new_owner.size(),
                                                   " bytes; at most 256 are allowed"));
  }
  if (std::any_of(new_owner.begin(), new_owner.end(),
                  [](char c) { return absl::ascii_iscntrl(static_cast<unsigned char>(c)); })) {
    return absl::InvalidArgumentError(
        absl::StrCat("new_owner \"", absl::CHexEscape(new_owner), "\" holds control characters"));
  }
  std::shared_ptr<Session> session;
  std::string previous;
  {
    absl::MutexLock lock(&mu_);
    if (shutdown_) return absl::UnavailableError("the server is shutting down");
    auto it = sessions_.find(std::string(id));
    if (it == sessions_.end()) return NotHeldLocked(id);
    session = it->second;
    session->Touch();
    if (absl::Status may = allowed(*session); !may.ok()) return may;
    previous = session->owner();
    if (previous == new_owner) return session;
    if (limits_.max_sessions_per_client > 0 &&
        HeldLocked(new_owner) >= limits_.max_sessions_per_client) {
      return absl::ResourceExhaustedError(absl::StrCat(
          "client ", new_owner, " holds its maximum of ", limits_.max_sessions_per_client,
          " sessions; it must delete some before it can take session ", id));
    }
    if (session->record() != nullptr) {
      if (absl::Status written = session->record()->SetOwner(new_owner); !written.ok()) {
        return absl::Status(written.code(), absl::StrCat("the server cannot keep the new owner "
                                                         "on disk: ", written.message()));
      }
    }
    session->SetOwner(new_owner);
  }
  if (log_ != nullptr) {
    std::string event = "handed";
    if (!previous.empty()) absl::StrAppend(&event, " from client ", previous);
    absl::StrAppend(&event, " to client ", new_owner);
    if (!by.empty()) absl::StrAppend(&event, " by ", by);
    log_->Record(session->id(), event);
  }
  return session;
}

absl::StatusOr<std::shared_ptr<Session>> SessionManager::Get(absl::string_view id) const {
  if (id.empty()) return absl::InvalidArgumentError("session_id is empty");
  absl::MutexLock lock(&mu_);
  if (shutdown_) return absl::UnavailableError("the server is shutting down");
  auto it = sessions_.find(std::string(id));
  if (it == sessions_.end()) return NotHeldLocked(id);
  // Touched under the lock, so that the reaper, which checks idleness again under it before it
  // deletes, never deletes a session a caller has just got.
  it->second->Touch();
  return it->second;
}

absl::StatusOr<std::vector<std::shared_ptr<Session>>> SessionManager::List() const {
  absl::MutexLock lock(&mu_);
  if (shutdown_) return absl::UnavailableError("the server is shutting down");
  if (!unrestored_.empty()) {
    return absl::UnavailableError(
        absl::StrCat("the server is restoring its sessions after a restart (",
                     RestoredOfStoredLocked(), " done); try again in a moment"));
  }
  std::vector<std::shared_ptr<Session>> out;
  out.reserve(order_.size());
  for (const auto& [index, id] : order_) out.push_back(sessions_.at(id));
  return out;
}

SessionManager::Census SessionManager::TakeCensus() const {
  Census census;
  absl::MutexLock lock(&mu_);
  census.sessions.reserve(order_.size());
  for (const auto& [index, id] : order_) {
    if (auto it = sessions_.find(id); it != sessions_.end()) census.sessions.push_back(it->second);
  }
  census.to_restore = unrestored_.size();
  return census;
}

absl::Status SessionManager::Delete(absl::string_view id) {
  return DeleteUnlessActive(id, std::nullopt);
}

absl::Status SessionManager::DeleteIfIdle(absl::string_view id, absl::Time idle_at) {
  return DeleteUnlessActive(id, idle_at);
}

absl::Status SessionManager::DeleteUnlessActive(absl::string_view id,
                                                std::optional<absl::Time> idle_at) {
  if (id.empty()) return absl::InvalidArgumentError("session_id is empty");
  std::shared_ptr<Session> session;
  {
    absl::MutexLock lock(&mu_);
    if (shutdown_) return absl::UnavailableError("the server is shutting down");
    auto it = sessions_.find(std::string(id));
    if (it == sessions_.end()) return NotHeldLocked(id);
    if (idle_at.has_value() && !it->second->IdleSince(*idle_at, limits_.idle_timeout)) {
      return absl::FailedPreconditionError(absl::StrCat("session ", id, " is active again"));
    }
    session = std::move(it->second);
    sessions_.erase(it);
    for (auto o = order_.begin(); o != order_.end(); ++o) {
      if (o->second == session->id()) {
        order_.erase(o);
        break;
      }
    }
  }
  if (metrics_ != nullptr) metrics_->CountSessionDeleted(/*idle=*/idle_at.has_value());
  if (log_ != nullptr) {
    log_->Record(session->id(),
                 idle_at.has_value()
                     ? absl::StrCat("deleted: idle for ", absl::FormatDuration(limits_.idle_timeout))
                     : std::string("deleted"));
  }
  session->Terminate(absl::NotFoundError(absl::StrCat("session ", id, " was deleted")));
  if (session->record() != nullptr) {
    if (absl::Status removed = session->record()->Remove(); !removed.ok() && log_ != nullptr) {
      log_->Record(session->id(), absl::StrCat("its files stay, and a restart would restore it: ",
                                               removed.message()));
    }
  }
  return absl::OkStatus();
}

size_t SessionManager::ReapIdle(absl::Time now) {
  std::vector<std::string> idle;
  {
    absl::MutexLock lock(&mu_);
    for (const auto& [id, session] : sessions_) {
      if (session->IdleSince(now, limits_.idle_timeout)) idle.push_back(id);
    }
  }
  size_t reaped = 0;
  for (const std::string& id : idle) {
    if (DeleteIfIdle(id, now).ok()) ++reaped;
  }
  return reaped;
}

void SessionManager::ReaperLoop() {
  const absl::Duration period =
      std::clamp(limits_.idle_timeout / 4, absl::Milliseconds(10), absl::Seconds(10));
  while (true) {
    {
      absl::MutexLock lock(&mu_);
      auto stop = [this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return shutdown_; };
      mu_.AwaitWithTimeout(absl::Condition(&stop), period);
      if (shutdown_) return;
    }
    ReapIdle(absl::Now());
  }
}

size_t SessionManager::HeldLocked(absl::string_view owner) const {
  if (owner.empty()) return sessions_.size() + unrestored_.size();
  size_t held = 0;
  for (const auto& [id, session] : sessions_) held += session->owner() == owner;
  for (const auto& [id, stored] : unrestored_) held += stored.owner == owner;
  return held;
}

std::string SessionManager::RestoredOfStoredLocked() const {
  return absl::StrCat(stored_sessions_ - unrestored_.size(), " of ", stored_sessions_);
}

absl::Status SessionManager::NotHeldLocked(absl::string_view id) const {
  if (unrestored_.count(std::string(id)) == 0) return UnknownSession(id);
  return absl::UnavailableError(absl::StrCat(
      "session ", QuotedSessionId(id), " is being restored after a restart of the server (",
      RestoredOfStoredLocked(), " sessions done); try again in a moment"));
}

void SessionManager::StartRestore(std::function<void(const std::string& id)> before_each) {
  if (store_ == nullptr) return;
  const absl::Time start = absl::Now();
  std::vector<std::string> problems;
  std::vector<StoredSessionFiles> stored = store_->List(&problems);
  absl::MutexLock lock(&mu_);
  if (shutdown_ || restorer_.joinable()) return;  // Stopped, or started already.
  restore_report_.problems = std::move(problems);
  restore_report_.took = absl::Now() - start;
  for (const StoredSessionFiles& files : stored) {
    unrestored_[files.stored.session_id()] = {files.stored.owner(), created_++};
  }
  stored_sessions_ = unrestored_.size();
  restoring_ = true;
  restorer_ = std::thread([this, stored = std::move(stored),
                           before_each = std::move(before_each)]() mutable {
    RestoreLoop(std::move(stored), std::move(before_each));
  });
}

void SessionManager::RestoreLoop(std::vector<StoredSessionFiles> stored,
                                 std::function<void(const std::string& id)> before_each) {
  const absl::Time start = absl::Now();
  for (const StoredSessionFiles& files : stored) {
    const std::string& id = files.stored.session_id();
    if (before_each) before_each(id);
    std::vector<std::string> problems;
    std::shared_ptr<Session> session =
        stop_restoring_.load() ? nullptr
                               : RestoreSession(files, *store_, limits_.max_points_per_session,
                                                pool_, encoder_, log_, metrics_, problems,
                                                &stop_restoring_);
    absl::MutexLock lock(&mu_);
    if (shutdown_) {
      // What Shutdown stopped stays on disk as it was, for the next start.
      if (session != nullptr) {
        session->Terminate(absl::UnavailableError("the server is shutting down"));
      }
      break;
    }
    uint64_t order = 0;
    if (const auto unrestored = unrestored_.find(id); unrestored != unrestored_.end()) {
      order = unrestored->second.order;
      unrestored_.erase(unrestored);
    } else {  // Not listed twice by the store; kept safe all the same.
      order = created_++;
    }
    for (std::string& problem : problems) restore_report_.problems.push_back(std::move(problem));
    if (session == nullptr) continue;
    sessions_.emplace(id, session);
    order_.emplace(order, id);
    ++restore_report_.sessions;
    restore_report_.points += session->points_received();
  }
  absl::MutexLock lock(&mu_);
  restore_report_.took += absl::Now() - start;
  unrestored_.clear();
  restoring_ = false;
}

RestoreReport SessionManager::WaitForRestore() const {
  absl::MutexLock lock(&mu_);
  auto done = [this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return !restoring_; };
  mu_.Await(absl::Condition(&done));
  return restore_report_;
}

void SessionManager::Shutdown(const absl::Status& status) {
  std::map<std::string, std::shared_ptr<Session>> sessions;
  {
    absl::MutexLock lock(&mu_);
    if (shutdown_) return;
    shutdown_ = true;
    sessions.swap(sessions_);
    order_.clear();
  }
  stop_restoring_ = true;
  if (restorer_.joinable()) restorer_.join();
  if (reaper_.joinable()) reaper_.join();
  for (auto& [id, session] : sessions) session->Terminate(status);
}

}  // namespace neuralmesh::server
