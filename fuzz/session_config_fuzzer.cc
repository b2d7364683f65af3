// The server's reading of a client's SessionConfig (server/proto_conversion.h,
// server/session_config.h), on any bytes that parse as a neuralmesh.v1.SessionConfig.
// Properties:
//  - SessionConfigFromProto and ResolveSessionConfig return OK or INVALID_ARGUMENT with a
//    message, and never crash;
//  - a resolved configuration keeps the promises of ResolveSessionConfig: valid learner and
//    Draco options, milestones strictly increasing from 4 and ending with the target, at most
//    256 of them;
//  - it survives SessionConfigToProto and back unchanged (milestones, target).
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_check.h"
#include "neuralmesh/v1/reconstruction.pb.h"
#include "server/proto_conversion.h"
#include "server/session_config.h"

namespace {

using neuralmesh::server::SessionConfig;

// The server's default --max_points_per_session.
constexpr size_t kMaxPointsPerSession = size_t{1} << 26;

void CheckFailure(const absl::Status& status) {
  FUZZ_CHECK(status.code() == absl::StatusCode::kInvalidArgument && !status.message().empty(),
             "rejected with %s", status.ToString().c_str());
}

void CheckResolved(const SessionConfig& config) {
  FUZZ_CHECK(config.learner.Validate().ok(), "resolved with invalid learner options");
  FUZZ_CHECK(config.draco.Validate().ok(), "resolved with invalid Draco options");
  const auto& milestones = config.lod_milestones;
  FUZZ_CHECK(!milestones.empty() && milestones.back() == config.target_vertices,
             "the milestones do not end with the target %zu", config.target_vertices);
  FUZZ_CHECK(milestones.size() <= neuralmesh::server::kMaxLodMilestones + 1,
             "%zu milestones", milestones.size());
  FUZZ_CHECK(milestones.front() >= neuralmesh::server::kMinTargetVertices,
             "a milestone of %zu vertices", milestones.front());
  for (size_t i = 1; i < milestones.size(); ++i) {
    FUZZ_CHECK(milestones[i - 1] < milestones[i], "milestones not strictly increasing");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  neuralmesh::v1::SessionConfig proto;
  if (!proto.ParseFromArray(data, static_cast<int>(size))) return 0;
  absl::StatusOr<SessionConfig> config = neuralmesh::server::SessionConfigFromProto(proto);
  if (!config.ok()) return CheckFailure(config.status()), 0;
  const absl::Status resolved =
      neuralmesh::server::ResolveSessionConfig(kMaxPointsPerSession, *config);
  if (!resolved.ok()) return CheckFailure(resolved), 0;
  CheckResolved(*config);

  absl::StatusOr<SessionConfig> again =
      neuralmesh::server::SessionConfigFromProto(neuralmesh::server::SessionConfigToProto(*config));
  FUZZ_CHECK(again.ok(), "a resolved config does not read back: %s",
             again.status().ToString().c_str());
  const absl::Status resolved_again =
      neuralmesh::server::ResolveSessionConfig(kMaxPointsPerSession, *again);
  FUZZ_CHECK(resolved_again.ok(), "a resolved config does not resolve again: %s",
             resolved_again.ToString().c_str());
  FUZZ_CHECK(again->lod_milestones == config->lod_milestones &&
                 again->target_vertices == config->target_vertices,
             "the milestones change through SessionConfigToProto");
  return 0;
}
