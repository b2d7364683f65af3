// The state directory of neuralmesh-server --state_dir: each session's identity, state, points
// and latest mesh on disk, so that sessions outlive a restart of the server.
//
// Layout:
//   DIR/LOCK                      flock()ed by the one server that uses DIR
//   DIR/sessions/ID/session.binpb neuralmesh.storage.v1.StoredSession, replaced whole
//   DIR/sessions/ID/points.journal every batch the session took, in order (points_journal.h)
//   DIR/sessions/ID/latest.binpb  the latest published neuralmesh.v1.MeshUpdate, replaced whole
//   DIR/sessions/ID/checkpoint.binpb  the learner's mesh at the latest milestone, or at a later
//                                 refresh (every checkpoint_interval), exactly
//                                 (neuralmesh.storage.v1.LearnerCheckpoint), replaced whole
//
// What is durable: a batch is acknowledged only after its record is written (and, with `sync`,
// on the disk); a state change a client asks for (finish, cancel) is written before it
// answers. Meshes are written after they are published and are not synced: a restored session
// that lacks one relearns it. Of the learner's state only the mesh of the checkpoint is kept
// (not its signal counters or octree): a restored session learns on from that mesh, or, without
// one, again from the initial mesh (session.h). So a restart costs the learning since the
// latest milestone, or at most about checkpoint_interval of it.
#ifndef NEURALMESH_SERVER_SESSION_STORE_H_
#define NEURALMESH_SERVER_SESSION_STORE_H_

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "core/point_cloud.h"
#include "core/triangle_mesh.h"
#include "neuralmesh/storage/v1/stored_session.pb.h"
#include "neuralmesh/v1/reconstruction.pb.h"
#include "server/points_journal.h"

namespace neuralmesh::server {

// How often a refresh of a learning session is kept as its checkpoint, at most.
inline constexpr absl::Duration kDefaultCheckpointInterval = absl::Seconds(30);

// What a checkpoint is taken from: every milestone is kept, a refresh only when
// checkpoint_interval has passed since the last checkpoint.
enum class CheckpointKind { kMilestone, kRefresh };

// The files of one session, open for writing. Thread-safe.
class SessionRecord {
 public:
  SessionRecord(std::string directory, storage::v1::StoredSession stored,
                std::unique_ptr<PointsJournal> journal, bool sync,
                absl::Duration checkpoint_interval = kDefaultCheckpointInterval);

  SessionRecord(const SessionRecord&) = delete;
  SessionRecord& operator=(const SessionRecord&) = delete;

  // Appends a batch to the journal (PointsJournal::Append). OK and nothing written once
  // removed.
  absl::Status AppendBatch(const PointCloud& batch) ABSL_LOCKS_EXCLUDED(mu_);
  // Records a new state and its reason (the error of a cancelled or failed session). An ended
  // state (finished, cancelled, failed) removes the learner checkpoint.
  absl::Status SetState(v1::SessionState state, const std::string& error) ABSL_LOCKS_EXCLUDED(mu_);
  // Records a new owner (TransferSession), synced like a state.
  absl::Status SetOwner(const std::string& owner) ABSL_LOCKS_EXCLUDED(mu_);
  // Records that learning paused for lack of growth with `points` points taken
  // (StoredSession.paused_at_points). Not synced: a pause lost to a crash is found again.
  absl::Status SetPausedAt(uint64_t points) ABSL_LOCKS_EXCLUDED(mu_);
  // Replaces the stored latest mesh; with `durable` (the final mesh) synced like a state.
  absl::Status WriteLatestMesh(const v1::MeshUpdate& update, bool durable) ABSL_LOCKS_EXCLUDED(mu_);
  // Replaces the stored learner checkpoint: `mesh` as the learner had it, and the session's
  // learning counters then. Not synced. OK and nothing written once the state is an ended
  // one, and for a refresh that comes before checkpoint_interval has passed since the last
  // checkpoint (or at all, with an interval of zero). The file is written without holding the
  // lock that AppendBatch takes; one thread at a time may call it.
  absl::Status WriteCheckpoint(const TriangleMesh& mesh, const v1::LearningState& learning,
                               CheckpointKind kind = CheckpointKind::kMilestone)
      ABSL_LOCKS_EXCLUDED(mu_);
  // Deletes the session's directory; every later call does nothing. The errno's code when the
  // directory could not be removed (a restart would then restore the session).
  absl::Status Remove() ABSL_LOCKS_EXCLUDED(mu_);

  const std::string& directory() const { return directory_; }

 private:
  // Writes `message` to `name` in the directory through a temporary file and a rename.
  // Writes `changed` as the session's file (ReplaceFile) and keeps it as stored_.
  absl::Status StoreLocked(storage::v1::StoredSession changed, bool durable)
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  absl::Status ReplaceFile(const std::string& name, const google::protobuf::Message& message,
                           bool durable) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // The two halves of ReplaceFile: the temporary file of `name` written (which needs no lock
  // when one thread at a time writes `name`), and renamed over `name`.
  absl::Status WriteTemporary(const std::string& name, const google::protobuf::Message& message,
                              bool durable) const;
  absl::Status MoveTemporaryIntoPlace(const std::string& name, bool durable)
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // Where the temporary file of `name` is written.
  std::string TemporaryPath(const std::string& name) const;

  // Whether a checkpoint of `kind` is to be written now.
  bool CheckpointDueLocked(CheckpointKind kind) const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);

  const std::string directory_;
  const bool sync_;
  const absl::Duration checkpoint_interval_;
  absl::Mutex mu_;
  storage::v1::StoredSession stored_ ABSL_GUARDED_BY(mu_);
  absl::Time last_checkpoint_ ABSL_GUARDED_BY(mu_) = absl::InfinitePast();
  std::unique_ptr<PointsJournal> journal_ ABSL_GUARDED_BY(mu_);
  bool removed_ ABSL_GUARDED_BY(mu_) = false;
};

// The learner's mesh at a session's latest checkpoint, and the session's counters then.
struct LearnerCheckpoint {
  TriangleMesh mesh;
  v1::LearningState learning;
};

// A session found in the state directory.
struct StoredSessionFiles {
  std::string directory;
  storage::v1::StoredSession stored;
  std::string journal_path;
  // The latest mesh, when its file was there and readable.
  std::optional<v1::MeshUpdate> latest;
  // The learner checkpoint, when its file was there and readable; else, when it was there,
  // what was wrong with it.
  std::optional<LearnerCheckpoint> checkpoint;
  std::string checkpoint_damage;
};

class SessionStore {
 public:
  // Opens (creating) the state directory `directory`, makes its sessions directory private to
  // the server's user (mode 0700) and locks it against other servers: FAILED_PRECONDITION when
  // another process holds it, the errno's code otherwise. `sync`:
  // batches and state changes reach the disk before they are acknowledged (fdatasync).
  // `checkpoint_interval`: the records' (SessionRecord::WriteCheckpoint).
  static absl::StatusOr<std::unique_ptr<SessionStore>> Open(
      const std::string& directory, bool sync,
      absl::Duration checkpoint_interval = kDefaultCheckpointInterval);
  ~SessionStore();

  SessionStore(const SessionStore&) = delete;
  SessionStore& operator=(const SessionStore&) = delete;

  // The sessions in the directory, oldest first. A session directory that cannot be read is
  // left as it is and described in `problems`.
  std::vector<StoredSessionFiles> List(std::vector<std::string>* problems) const;

  // Creates the files of a new session (its state file first) and opens them for writing.
  absl::StatusOr<std::unique_ptr<SessionRecord>> Create(const storage::v1::StoredSession& stored);

  // Opens the files of a listed session for writing, its journal cut to `journal_bytes`
  // (ReadPointsJournal's valid_bytes).
  absl::StatusOr<std::unique_ptr<SessionRecord>> Reopen(const StoredSessionFiles& files,
                                                        uint64_t journal_bytes);

  const std::string& directory() const { return directory_; }
  bool sync() const { return sync_; }

 private:
  SessionStore(std::string directory, int lock_fd, bool sync, absl::Duration checkpoint_interval)
      : directory_(std::move(directory)),
        lock_fd_(lock_fd),
        sync_(sync),
        checkpoint_interval_(checkpoint_interval) {}

  const std::string directory_;
  const int lock_fd_;
  const bool sync_;
  const absl::Duration checkpoint_interval_;
};

// The file names inside a session's directory.
inline constexpr char kStoredSessionFile[] = "session.binpb";
inline constexpr char kPointsJournalFile[] = "points.journal";
inline constexpr char kLatestMeshFile[] = "latest.binpb";
inline constexpr char kCheckpointFile[] = "checkpoint.binpb";

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_SESSION_STORE_H_
