// Conversions between the neuralmesh.v1 messages and the domain types of core/ and server/.
// Every function that reads client input validates it and says what was wrong.
#ifndef NEURALMESH_SERVER_PROTO_CONVERSION_H_
#define NEURALMESH_SERVER_PROTO_CONVERSION_H_

#include <cstddef>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/analysis/mesh_report.h"
#include "core/io/draco_codec.h"
#include "core/point_cloud.h"
#include "core/triangle_mesh.h"
#include "neuralmesh/v1/reconstruction.pb.h"
#include "server/session_config.h"

namespace neuralmesh::server {

// Reads a configuration; unset fields take their defaults. INVALID_ARGUMENT for an unknown
// final_pass value. Range checks happen in ResolveSessionConfig.
absl::StatusOr<SessionConfig> SessionConfigFromProto(const v1::SessionConfig& proto);

// Every field set, defaults included.
v1::SessionConfig SessionConfigToProto(const SessionConfig& config);

v1::QuantizationBox QuantizationBoxToProto(const QuantizationBox& box);
v1::MeshReport MeshReportToProto(const MeshReport& report);

// Unpacks a batch (packed float32 arrays or a Draco point cloud).
// INVALID_ARGUMENT when no encoding is set, the batch is empty, an array's byte length is not
// a multiple of its element size or does not match the number of positions, or the Draco data
// is corrupt; RESOURCE_EXHAUSTED when it holds more than `max_batch_points` points.
// Non-finite values are left to GrowingPointCloud::Append, which rejects them.
absl::StatusOr<PointCloud> PointBatchFromProto(const v1::PointBatch& batch,
                                               size_t max_batch_points);

// A mesh packed as PackedMesh says (little-endian float32 positions, uint32 faces; the packing is
// proto/packing.h's PackMesh). Checks only the sizes: INVALID_ARGUMENT, naming `field`, when
// positions or faces are not whole elements or there are no positions; what the mesh is made
// of is checked where it is used (MakeStartMesh).
absl::StatusOr<TriangleMesh> TriangleMeshFromPacked(const v1::PackedMesh& packed,
                                                    absl::string_view field);

// The mesh of CreateSessionRequest.start_mesh: unpacked or Draco-decoded. INVALID_ARGUMENT,
// prefixed "start_mesh", when it holds no mesh or one that cannot be read.
absl::StatusOr<TriangleMesh> StartMeshFromProto(const v1::StartMesh& start);

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_PROTO_CONVERSION_H_
