// Core's point clouds and meshes in the packed forms of the neuralmesh.v1 API (PackedPoints,
// PackedMesh: little-endian float32 coordinates and uint32 vertex indices), as the client sends
// them and the server stores them. The unpacking, with its checks, is the server's
// (server/proto_conversion.h).
#ifndef NEURALMESH_PROTO_PACKING_H_
#define NEURALMESH_PROTO_PACKING_H_

#include <cstddef>

#include "core/point_cloud.h"
#include "core/triangle_mesh.h"
#include "neuralmesh/v1/reconstruction.pb.h"

namespace neuralmesh {

// Points [begin, end) of `cloud`: positions, and weights, normals and colours when the cloud
// has them.
v1::PackedPoints PackPoints(const PointCloud& cloud, size_t begin, size_t end);
// Appends points [begin, end) of `cloud` to `packed`, as PackPoints packs them.
void AppendPackedPoints(const PointCloud& cloud, size_t begin, size_t end,
                        v1::PackedPoints* packed);

// Points [begin, end) of `cloud` as a batch that says where it starts in the upload
// (first_point = begin), so that a batch sent again after a lost connection is not taken twice.
v1::PointBatch PackPointBatch(const PointCloud& cloud, size_t begin, size_t end);

// `mesh`, exactly.
v1::PackedMesh PackMesh(const TriangleMesh& mesh);

}  // namespace neuralmesh

#endif  // NEURALMESH_PROTO_PACKING_H_
