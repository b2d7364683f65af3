#include "server/session_store.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/io/file_contents.h"
#include "core/status_macros.h"
#include "neuralmesh/storage/v1/learner_checkpoint.pb.h"
#include "proto/packing.h"
#include "server/proto_conversion.h"

namespace neuralmesh::server {
namespace {

constexpr uint32_t kFormatVersion = 1;
constexpr char kSessionsDirectory[] = "sessions";
constexpr char kLockFile[] = "LOCK";

absl::Status ErrorCodeStatus(const std::error_code& error, const std::string& what) {
  return absl::ErrnoToStatus(error.value(), what);
}

// fsync()s the file or directory at `path`.
absl::Status SyncPath(const std::string& path) {
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return absl::ErrnoToStatus(errno, absl::StrCat("cannot open '", path, "'"));
  const int result = fsync(fd);
  const int error = errno;
  close(fd);
  if (result != 0) return absl::ErrnoToStatus(error, absl::StrCat("cannot sync '", path, "'"));
  return absl::OkStatus();
}

// Whether `name` can be a session id the server made (server/session_manager.cc).
bool IsSessionId(const std::string& name) {
  return !name.empty() && name.size() <= 64 && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-';
  });
}

bool Ended(v1::SessionState state) {
  return state == v1::SESSION_STATE_FINISHED || state == v1::SESSION_STATE_CANCELLED ||
         state == v1::SESSION_STATE_FAILED;
}

// The checkpoint in `contents`, or what is wrong with it. The mesh itself is checked when
// learning goes on from it (Learner::CreateFrom).
absl::StatusOr<LearnerCheckpoint> ParseCheckpoint(const std::string& contents,
                                                  const std::string& id) {
  storage::v1::LearnerCheckpoint stored;
  if (!stored.ParseFromString(contents)) {
    return absl::DataLossError("it is not a learner checkpoint");
  }
  if (stored.format_version() != kFormatVersion) {
    return absl::FailedPreconditionError(
        absl::StrCat("it has format version ", stored.format_version(),
                     "; this server reads version ", kFormatVersion));
  }
  if (stored.session_id() != id) {
    return absl::DataLossError(absl::StrCat("it is of session \"", stored.session_id(), "\""));
  }
  absl::StatusOr<TriangleMesh> mesh = TriangleMeshFromPacked(stored.mesh(), "its mesh");
  if (!mesh.ok()) return absl::DataLossError(mesh.status().message());
  LearnerCheckpoint checkpoint;
  checkpoint.mesh = *std::move(mesh);
  checkpoint.learning = stored.learning();
  return checkpoint;
}

absl::StatusOr<StoredSessionFiles> ReadSessionDirectory(const std::string& directory) {
  StoredSessionFiles files;
  files.directory = directory;
  files.journal_path = absl::StrCat(directory, "/", kPointsJournalFile);
  NM_ASSIGN_OR_RETURN(const std::string state,
                      ReadFileContents(absl::StrCat(directory, "/", kStoredSessionFile)));
  if (!files.stored.ParseFromString(state)) {
    return absl::DataLossError(
        absl::StrCat("'", directory, "/", kStoredSessionFile, "' is not a stored session"));
  }
  if (files.stored.format_version() != kFormatVersion) {
    return absl::FailedPreconditionError(
        absl::StrCat("'", directory, "' has format version ", files.stored.format_version(),
                     "; this server reads version ", kFormatVersion));
  }
  const std::string id = std::filesystem::path(directory).filename().string();
  if (files.stored.session_id() != id) {
    return absl::DataLossError(
        absl::StrCat("'", directory, "' holds session \"", files.stored.session_id(), "\""));
  }
  if (absl::StatusOr<std::string> latest =
          ReadFileContents(absl::StrCat(directory, "/", kLatestMeshFile));
      latest.ok()) {
    v1::MeshUpdate update;
    if (update.ParseFromString(*latest)) files.latest = std::move(update);
  }
  const std::string checkpoint_path = absl::StrCat(directory, "/", kCheckpointFile);
  if (std::error_code missing; std::filesystem::exists(checkpoint_path, missing)) {
    absl::StatusOr<std::string> contents = ReadFileContents(checkpoint_path);
    absl::StatusOr<LearnerCheckpoint> checkpoint =
        contents.ok() ? ParseCheckpoint(*contents, id) : contents.status();
    if (checkpoint.ok()) {
      files.checkpoint = *std::move(checkpoint);
    } else {
      files.checkpoint_damage = std::string(checkpoint.status().message());
    }
  }
  return files;
}

}  // namespace

SessionRecord::SessionRecord(std::string directory, storage::v1::StoredSession stored,
                             std::unique_ptr<PointsJournal> journal, bool sync,
                             absl::Duration checkpoint_interval)
    : directory_(std::move(directory)),
      sync_(sync),
      checkpoint_interval_(checkpoint_interval),
      stored_(std::move(stored)),
      journal_(std::move(journal)) {}

absl::Status SessionRecord::AppendBatch(const PointCloud& batch) {
  absl::MutexLock lock(&mu_);
  if (removed_) return absl::OkStatus();
  return journal_->Append(batch);
}

absl::Status SessionRecord::SetState(v1::SessionState state, const std::string& error) {
  absl::MutexLock lock(&mu_);
  if (removed_) return absl::OkStatus();
  storage::v1::StoredSession changed = stored_;
  changed.set_state(state);
  changed.set_error(error);
  NM_RETURN_IF_ERROR(StoreLocked(std::move(changed), /*durable=*/true));
  // An ended session learns no more; a checkpoint left behind (the removal failing) is unused.
  if (Ended(state)) std::remove(absl::StrCat(directory_, "/", kCheckpointFile).c_str());
  return absl::OkStatus();
}

absl::Status SessionRecord::SetOwner(const std::string& owner) {
  absl::MutexLock lock(&mu_);
  if (removed_) return absl::OkStatus();
  storage::v1::StoredSession changed = stored_;
  changed.set_owner(owner);
  return StoreLocked(std::move(changed), /*durable=*/true);
}

absl::Status SessionRecord::SetPausedAt(uint64_t points) {
  absl::MutexLock lock(&mu_);
  if (removed_) return absl::OkStatus();
  storage::v1::StoredSession changed = stored_;
  changed.set_paused_at_points(points);
  return StoreLocked(std::move(changed), /*durable=*/false);
}

absl::Status SessionRecord::StoreLocked(storage::v1::StoredSession changed, bool durable) {
  NM_RETURN_IF_ERROR(ReplaceFile(kStoredSessionFile, changed, durable));
  stored_ = std::move(changed);
  return absl::OkStatus();
}

absl::Status SessionRecord::WriteLatestMesh(const v1::MeshUpdate& update, bool durable) {
  absl::MutexLock lock(&mu_);
  if (removed_) return absl::OkStatus();
  return ReplaceFile(kLatestMeshFile, update, durable);
}

bool SessionRecord::CheckpointDueLocked(CheckpointKind kind) const {
  if (removed_ || Ended(stored_.state())) return false;
  if (kind == CheckpointKind::kMilestone) return true;
  return checkpoint_interval_ > absl::ZeroDuration() &&
         absl::Now() - last_checkpoint_ >= checkpoint_interval_;
}

absl::Status SessionRecord::WriteCheckpoint(const TriangleMesh& mesh,
                                            const v1::LearningState& learning,
                                            CheckpointKind kind) {
  storage::v1::LearnerCheckpoint checkpoint;
  {
    absl::MutexLock lock(&mu_);
    if (!CheckpointDueLocked(kind)) return absl::OkStatus();
    checkpoint.set_session_id(stored_.session_id());
  }
  // Packed and written outside the lock, which batches take (36 MB at a million vertices).
  checkpoint.set_format_version(kFormatVersion);
  *checkpoint.mutable_mesh() = PackMesh(mesh);
  *checkpoint.mutable_learning() = learning;
  const absl::Status written = WriteTemporary(kCheckpointFile, checkpoint, /*durable=*/false);
  absl::MutexLock lock(&mu_);
  if (!CheckpointDueLocked(kind)) {  // Removed or ended meanwhile.
    std::remove(TemporaryPath(kCheckpointFile).c_str());
    return absl::OkStatus();
  }
  NM_RETURN_IF_ERROR(written);
  NM_RETURN_IF_ERROR(MoveTemporaryIntoPlace(kCheckpointFile, /*durable=*/false));
  last_checkpoint_ = absl::Now();
  return absl::OkStatus();
}

absl::Status SessionRecord::Remove() {
  absl::MutexLock lock(&mu_);
  if (removed_) return absl::OkStatus();
  removed_ = true;
  journal_.reset();
  std::error_code error;
  std::filesystem::remove_all(directory_, error);
  if (error) return ErrorCodeStatus(error, absl::StrCat("cannot remove '", directory_, "'"));
  return absl::OkStatus();
}

absl::Status SessionRecord::ReplaceFile(const std::string& name,
                                        const google::protobuf::Message& message, bool durable) {
  NM_RETURN_IF_ERROR(WriteTemporary(name, message, durable));
  return MoveTemporaryIntoPlace(name, durable);
}

absl::Status SessionRecord::WriteTemporary(const std::string& name,
                                           const google::protobuf::Message& message,
                                           bool durable) const {
  const std::string temporary = TemporaryPath(name);
  NM_RETURN_IF_ERROR(WriteFileContents(temporary, message.SerializeAsString()));
  if (durable && sync_) return SyncPath(temporary);
  return absl::OkStatus();
}

std::string SessionRecord::TemporaryPath(const std::string& name) const {
  return absl::StrCat(directory_, "/", name, ".new");
}

absl::Status SessionRecord::MoveTemporaryIntoPlace(const std::string& name, bool durable) {
  const std::string path = absl::StrCat(directory_, "/", name);
  const std::string temporary = TemporaryPath(name);
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const int error = errno;
    std::remove(temporary.c_str());
    return absl::ErrnoToStatus(error, absl::StrCat("cannot replace '", path, "'"));
  }
  if (durable && sync_) return SyncPath(directory_);
  return absl::OkStatus();
}

absl::StatusOr<std::unique_ptr<SessionStore>> SessionStore::Open(
    const std::string& directory, bool sync, absl::Duration checkpoint_interval) {
  if (directory.empty()) return absl::InvalidArgumentError("the state directory is empty");
  std::error_code error;
  const std::string sessions = absl::StrCat(directory, "/", kSessionsDirectory);
  std::filesystem::create_directories(sessions, error);
  if (error) {
    return ErrorCodeStatus(error,
                           absl::StrCat("cannot create the state directory '", directory, "'"));
  }
  // The points are the clients' data: readable by the server's user only.
  std::filesystem::permissions(sessions, std::filesystem::perms::owner_all,
                               std::filesystem::perm_options::replace, error);
  if (error) {
    return ErrorCodeStatus(error, absl::StrCat("cannot make '", sessions, "' private"));
  }
  const std::string lock_path = absl::StrCat(directory, "/", kLockFile);
  const int fd = open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  if (fd < 0) return absl::ErrnoToStatus(errno, absl::StrCat("cannot open '", lock_path, "'"));
  if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int lock_error = errno;
    close(fd);
    if (lock_error == EWOULDBLOCK) {
      return absl::FailedPreconditionError(absl::StrCat(
          "the state directory '", directory, "' is in use by another neuralmesh-server"));
    }
    return absl::ErrnoToStatus(lock_error, absl::StrCat("cannot lock '", lock_path, "'"));
  }
  return std::unique_ptr<SessionStore>(new SessionStore(directory, fd, sync, checkpoint_interval));
}

SessionStore::~SessionStore() { close(lock_fd_); }

std::vector<StoredSessionFiles> SessionStore::List(std::vector<std::string>* problems) const {
  std::vector<StoredSessionFiles> found;
  std::error_code error;
  const std::string sessions = absl::StrCat(directory_, "/", kSessionsDirectory);
  for (const auto& entry : std::filesystem::directory_iterator(sessions, error)) {
    const std::string name = entry.path().filename().string();
    if (!entry.is_directory() || !IsSessionId(name)) {
      problems->push_back(absl::StrCat("'", entry.path().string(), "' is not a session; left"));
      continue;
    }
    absl::StatusOr<StoredSessionFiles> files = ReadSessionDirectory(entry.path().string());
    if (!files.ok()) {
      problems->push_back(absl::StrCat(files.status().message(), "; left as it is"));
      continue;
    }
    found.push_back(*std::move(files));
  }
  if (error) {
    problems->push_back(absl::StrCat("cannot list '", sessions, "': ", error.message()));
  }
  std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) {
    if (a.stored.create_time_us() != b.stored.create_time_us()) {
      return a.stored.create_time_us() < b.stored.create_time_us();
    }
    return a.stored.session_id() < b.stored.session_id();
  });
  return found;
}

absl::StatusOr<std::unique_ptr<SessionRecord>> SessionStore::Create(
    const storage::v1::StoredSession& stored) {
  const std::string directory =
      absl::StrCat(directory_, "/", kSessionsDirectory, "/", stored.session_id());
  std::error_code error;
  if (!std::filesystem::create_directory(directory, error)) {
    return error ? ErrorCodeStatus(error, absl::StrCat("cannot create '", directory, "'"))
                 : absl::AlreadyExistsError(absl::StrCat("'", directory, "' exists already"));
  }
  storage::v1::StoredSession first = stored;
  first.set_format_version(kFormatVersion);
  const std::string state_path = absl::StrCat(directory, "/", kStoredSessionFile);
  absl::Status written = WriteFileContents(state_path, first.SerializeAsString());
  if (written.ok() && sync_) written = SyncPath(state_path);
  if (written.ok() && sync_) written = SyncPath(absl::StrCat(directory_, "/", kSessionsDirectory));
  absl::StatusOr<std::unique_ptr<PointsJournal>> journal =
      written.ok() ? PointsJournal::Open(absl::StrCat(directory, "/", kPointsJournalFile), 0, sync_)
                   : absl::StatusOr<std::unique_ptr<PointsJournal>>(written);
  if (!journal.ok()) {
    std::filesystem::remove_all(directory, error);
    return journal.status();
  }
  return std::make_unique<SessionRecord>(directory, std::move(first), *std::move(journal), sync_,
                                         checkpoint_interval_);
}

absl::StatusOr<std::unique_ptr<SessionRecord>> SessionStore::Reopen(const StoredSessionFiles& files,
                                                                    uint64_t journal_bytes) {
  NM_ASSIGN_OR_RETURN(std::unique_ptr<PointsJournal> journal,
                      PointsJournal::Open(files.journal_path, journal_bytes, sync_));
  return std::make_unique<SessionRecord>(files.directory, files.stored, std::move(journal), sync_,
                                         checkpoint_interval_);
}

}  // namespace neuralmesh::server
