#include "server/session_restore.h"

#include <filesystem>
#include <optional>
#include <system_error>
#include <utility>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "server/points_journal.h"
#include "server/proto_conversion.h"

namespace neuralmesh::server {
namespace {

struct Replay {
  uint64_t batches = 0;        // Taken again.
  uint64_t journal_bytes = 0;  // Of whole records, torn or damaged ones after them cut off.
  absl::Status status;         // Of the first batch that could not be taken again.
};

// Takes the journal's batches again into `session`. After one that no longer fits (a lower
// point limit), the rest are only read, to find where the whole records end. A missing journal
// is an empty one (a crash right after the session was created).
absl::StatusOr<Replay> ReplayJournal(const std::string& path, Session& session,
                                     std::vector<std::string>& problems,
                                     const std::atomic<bool>* stop) {
  Replay replay;
  std::error_code error;
  if (!std::filesystem::exists(path, error)) return replay;
  absl::StatusOr<JournalReadResult> read = ReadPointsJournal(path, [&](const PointCloud& batch) {
    if (stop != nullptr && stop->load(std::memory_order_relaxed)) {
      return absl::CancelledError("the server is shutting down");
    }
    if (!replay.status.ok()) return absl::OkStatus();
    if (absl::Status taken = session.ReplayBatch(batch); !taken.ok()) {
      replay.status = absl::Status(
          taken.code(),
          absl::StrCat("batch ", replay.batches + 1, " of its journal: ", taken.message()));
    } else {
      ++replay.batches;
    }
    return absl::OkStatus();
  });
  if (!read.ok()) return read.status();
  replay.journal_bytes = read->valid_bytes;
  if (!read->damage.empty()) {
    problems.push_back(absl::StrCat("session ", session.id(), ": its journal ends in ",
                                    read->damage, "; cut off there"));
  }
  return replay;
}

std::string StateName(v1::SessionState state) {
  return absl::AsciiStrToLower(absl::StripPrefix(v1::SessionState_Name(state), "SESSION_STATE_"));
}

}  // namespace

std::shared_ptr<Session> RestoreSession(const StoredSessionFiles& files, SessionStore& store,
                                        size_t max_points_per_session, WorkerPool* pool,
                                        Executor* encoder, std::shared_ptr<EventLog> log,
                                        ServerMetrics* metrics, std::vector<std::string>& problems,
                                        const std::atomic<bool>* stop) {
  const storage::v1::StoredSession& stored = files.stored;
  const std::string& id = stored.session_id();
  auto unrestored = [&](const absl::Status& status) {
    problems.push_back(
        absl::StrCat("session ", id, " stays on disk unrestored: ", status.message()));
    return nullptr;
  };
  absl::StatusOr<SessionConfig> config = SessionConfigFromProto(stored.config());
  if (!config.ok()) return unrestored(config.status());
  if (absl::Status valid = ResolveSessionConfig(max_points_per_session, *config); !valid.ok()) {
    return unrestored(valid);
  }
  auto session = std::make_shared<Session>(
      id, stored.name(), *std::move(config), max_points_per_session, pool, encoder, log,
      stored.owner(), absl::FromUnixMicros(stored.create_time_us()));
  absl::StatusOr<Replay> replay = ReplayJournal(files.journal_path, *session, problems, stop);
  if (!replay.ok()) return unrestored(replay.status());

  v1::SessionState state = stored.state();
  std::string error = stored.error();
  std::shared_ptr<v1::MeshUpdate> latest;
  if (files.latest.has_value() && files.latest->session_id() == id) {
    latest = std::make_shared<v1::MeshUpdate>(*files.latest);
  }
  // Finished, but the final mesh did not reach the disk: it is learned again.
  if (state == v1::SESSION_STATE_FINISHED &&
      (latest == nullptr || latest->kind() != v1::UPDATE_KIND_FINAL)) {
    state = v1::SESSION_STATE_FINISHING;
  }
  if (!replay->status.ok()) {
    state = v1::SESSION_STATE_FAILED;
    error = absl::StrCat("restoring it after a restart failed at ", replay->status.message());
    problems.push_back(absl::StrCat(
        "session ", id, " is restored as failed (its files stay as they are): ", error));
  }
  absl::StatusOr<std::unique_ptr<SessionRecord>> record =
      store.Reopen(files, replay->journal_bytes);
  if (!record.ok()) return unrestored(record.status());
  std::string latest_note = latest == nullptr ? std::string()
                                              : absl::StrCat(", mesh ", latest->sequence(), " of ",
                                                             latest->vertex_count(), " vertices");
  if (!files.checkpoint_damage.empty()) {
    problems.push_back(absl::StrCat("session ", id, ": its learner checkpoint cannot be used (",
                                    files.checkpoint_damage,
                                    "); it learns again from the initial mesh"));
  }
  std::optional<LearnerCheckpoint> checkpoint = files.checkpoint;
  if (checkpoint.has_value() &&
      (state == v1::SESSION_STATE_COLLECTING || state == v1::SESSION_STATE_FINISHING)) {
    absl::StrAppend(&latest_note, ", learner checkpoint of ", checkpoint->mesh.positions.size(),
                    " vertices");
  }
  if (state == v1::SESSION_STATE_COLLECTING && stored.paused_at_points() > 0 &&
      session->points_received() <= stored.paused_at_points()) {
    absl::StrAppend(&latest_note, ", paused for lack of growth until more than ",
                    stored.paused_at_points(), " points come");
  }
  session->AttachMetrics(metrics);  // After the replay: its batches are not new work.
  session->FinishRestore(state, error, stored.paused_at_points(), std::move(latest),
                         std::move(checkpoint), *std::move(record));
  if (log != nullptr) {
    log->Record(
        id, absl::StrCat("restored after a restart: ", session->points_received(), " points in ",
                         replay->batches, " batches, ", StateName(session->state()), latest_note));
  }
  return session;
}

}  // namespace neuralmesh::server
