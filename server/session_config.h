// The configuration of one reconstruction session, in domain types (the proto's
// neuralmesh.v1.SessionConfig with every default resolved).
#ifndef NEURALMESH_SERVER_SESSION_CONFIG_H_
#define NEURALMESH_SERVER_SESSION_CONFIG_H_

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/time/time.h"
#include "core/analysis/color_source.h"
#include "core/analysis/statistical_outliers.h"
#include "core/bounding_box.h"
#include "core/io/draco_codec.h"
#include "core/learning/learner_options.h"
#include "core/origin.h"

namespace neuralmesh::server {

// What happens to the incrementally learned mesh at finish (neuralmesh.v1.FinalPass).
enum class FinalPass {
  kAuto,      // Relearn when the arrival order was spatially biased (see NeedsRelearn).
  kRelearn,   // Always relearn from scratch on the complete point set.
  kContinue,  // Always continue the incremental mesh.
};

inline constexpr size_t kMinTargetVertices = 4;  // The initial tetrahedron.
// The mesh numbers its elements with 32-bit ints, six half-edges per vertex.
inline constexpr size_t kMaxTargetVertices = size_t{1} << 28;
inline constexpr size_t kMaxLodMilestones = 256;
inline constexpr absl::Duration kDefaultRefreshInterval = absl::Milliseconds(250);
inline constexpr absl::Duration kMinRefreshInterval = absl::Milliseconds(10);
inline constexpr double kDefaultPointsPerVertex = 2.0;
// The smallest milestone of the default series. The stream's budget is 8 bytes per vertex at
// 11-bit quantization, and Draco spends about 70 bytes on any mesh (header, connectivity and
// attribute headers, the quantization box, entropy-coder tables) before its vertices. Even
// with the shortest of the encodings core/io/draco_codec.h tries, learned meshes of 10
// vertices took at least 110 bytes (11.0 per vertex) and of 20 vertices up to 164 (8.2, in
// the tighter box that SessionConfig.bounds gives), while at 50 vertices they stayed below 5.7
// per vertex (20 tori and 20 spheres each). So the series starts at 50.
inline constexpr size_t kFirstDefaultMilestone = 50;

// How the client orders its upload, in its own words: kept, never interpreted.
struct UploadOrder {
  static constexpr size_t kMaxNameBytes = 256;
  std::string name;
  uint64_t items = 0;
  uint64_t fingerprint = 0;  // Of the first points sent; 0: not told.
};

struct SessionConfig {
  LearnerOptions learner;      // The paper's parameters.
  size_t target_vertices = 0;  // The final vertex count, >= 4.
  // Publication milestones, strictly increasing, ending with target_vertices once resolved.
  // Empty before ResolveSessionConfig: the 1-2-5 series from 50 (DefaultLodMilestones).
  std::vector<size_t> lod_milestones;
  // Wall time between two republications while learning; zero disables them.
  absl::Duration refresh_interval = kDefaultRefreshInterval;
  // Draco settings; quantization_box is chosen by the session, never by the client.
  DracoOptions draco;
  // Points received per allowed vertex (> 0): vertices <= floor(points / points_per_vertex).
  double points_per_vertex = kDefaultPointsPerVertex;
  // Where the data lies, if the client knows; seeds the quantization box.
  std::optional<BoundingBox> bounds;
  FinalPass final_pass = FinalPass::kAuto;
  // Drop each batch's statistical outliers before accepting it; unset: accept every point.
  std::optional<OutlierOptions> outlier_removal;
  // How published meshes are painted when the points carry colours.
  PointColorOptions colors;
  // Where the points' (0, 0, 0) lies in the data's coordinates; carried by every published
  // mesh (TriangleMesh::origin).
  Origin origin = kNoOrigin;
  // The client's upload order (v1::UploadOrder), kept for a client that resumes the upload.
  std::optional<UploadOrder> upload_order;
};

// The 1-2-5 series from kFirstDefaultMilestone, 50, 100, 200, 500, 1000, ... below `target`,
// then `target` itself (the only milestone of a target up to 50).
std::vector<size_t> DefaultLodMilestones(size_t target);

// Validates `config` and fills in the milestones (the default series when empty, the target
// appended when missing). INVALID_ARGUMENT naming the first offending field: a target below 4,
// above kMaxTargetVertices or unreachable within `max_points_per_session` points, milestones not
// strictly increasing, below 4, above the target or more than 256 of them, a refresh interval
// between 0 and 10 ms, points_per_vertex not finite and positive, bounds not finite or inverted,
// an origin not finite, an upload order's name longer than UploadOrder::kMaxNameBytes,
// and whatever LearnerOptions::Validate, DracoOptions::Validate, OutlierOptions::Validate and
// PointColorOptions::Validate reject.
absl::Status ResolveSessionConfig(size_t max_points_per_session, SessionConfig& config);

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_SESSION_CONFIG_H_
