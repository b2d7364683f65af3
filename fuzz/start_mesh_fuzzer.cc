// A client's start mesh (CreateSessionRequest.start_mesh), on any bytes that parse as a
// neuralmesh.v1.StartMesh: the server's reading of it (server/proto_conversion.h), its checks
// (CheckStartMesh, MakeStartMesh), and the learner that goes on from a mesh that passes them.
// Properties:
//  - a mesh is refused with INVALID_ARGUMENT and a message, or taken, and nothing crashes;
//  - a taken mesh is one the learner takes (Learner::CreateFrom), and after up to 2,000 Basic
//    Steps on a sphere the mesh is still a valid manifold with finite positions.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "core/learning/learner.h"
#include "core/mesh_validation.h"
#include "core/sampling/implicit_surfaces.h"
#include "fuzz/fuzz_check.h"
#include "neuralmesh/v1/reconstruction.pb.h"
#include "server/proto_conversion.h"
#include "server/session_manager.h"

namespace {

void CheckRefused(const absl::Status& status) {
  FUZZ_CHECK(status.code() == absl::StatusCode::kInvalidArgument && !status.message().empty(),
             "refused with %s", status.ToString().c_str());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  neuralmesh::v1::StartMesh proto;
  if (!proto.ParseFromArray(data, static_cast<int>(size))) return 0;
  absl::StatusOr<neuralmesh::TriangleMesh> start = neuralmesh::server::StartMeshFromProto(proto);
  if (!start.ok()) return CheckRefused(start.status()), 0;
  if (start->positions.size() > 2000) return 0;  // Larger meshes only take longer.
  neuralmesh::server::SessionConfig config;
  config.target_vertices = start->positions.size() + 20;
  const absl::Status checked = neuralmesh::server::CheckStartMesh(*start, config);
  if (!checked.ok()) return CheckRefused(checked), 0;

  static const std::unique_ptr<neuralmesh::ImplicitSurface> sphere =
      neuralmesh::MakeSphere(neuralmesh::Vec3(0, 0, 0), 1.0).value();
  absl::StatusOr<std::unique_ptr<neuralmesh::Learner>> learner =
      neuralmesh::Learner::CreateFrom(config.learner, sphere.get(), *start);
  FUZZ_CHECK(learner.ok(), "a start mesh that passed the checks was refused: %s",
             learner.status().ToString().c_str());
  neuralmesh::StopCriteria stop;
  stop.target_vertices = config.target_vertices;
  stop.max_basic_steps = 2000;
  absl::StatusOr<neuralmesh::StopReason> reason = (*learner)->Run(stop);
  FUZZ_CHECK(reason.ok(), "learning failed: %s", reason.status().ToString().c_str());
  const neuralmesh::Mesh& mesh = (*learner)->mesh();
  const absl::Status valid = neuralmesh::ValidateMesh(mesh);
  FUZZ_CHECK(valid.ok(), "the mesh is no longer valid: %s", valid.ToString().c_str());
  for (auto v : mesh.vertices()) {
    const neuralmesh::Vec3& p = mesh.point(v);
    FUZZ_CHECK(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]),
               "vertex %d is not finite", v.idx());
  }
  return 0;
}
