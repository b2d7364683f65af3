// The cube a session's meshes are quantized against (Draco positions), fixed by the first data
// and grown when later data falls outside it, so that every update of a session decodes in one
// frame (Session, reconstruction.proto's MeshUpdate.quantization_box).
#ifndef NEURALMESH_SERVER_QUANTIZATION_CUBE_H_
#define NEURALMESH_SERVER_QUANTIZATION_CUBE_H_

#include "absl/status/statusor.h"
#include "core/bounding_box.h"
#include "core/io/draco_codec.h"

namespace neuralmesh::server {

// The first cube around the bounds a client declared (SessionConfig.bounds), and around the
// first batch when it declared none: room for the data still to come.
inline constexpr double kDeclaredBoundsEnlargement = 1.1;
inline constexpr double kFirstBatchEnlargement = 2.0;

// Whether `box` contains `bounds`.
bool CubeContains(const QuantizationBox& box, const BoundingBox& bounds);

// The bounding cube of `bounds` scaled by `enlarge` about its centre (a degenerate box gets edge
// 1), widened to the nearest cube Draco keeps exactly (DracoExactBox). INVALID_ARGUMENT when
// Draco cannot quantize against that cube at `bits` bits (CheckQuantizationBox): coordinates
// near the limits of a float.
absl::StatusOr<QuantizationBox> QuantizationCube(const BoundingBox& bounds, double enlarge,
                                                 int bits);

// `box` grown 2x about its centre until it contains `bounds`, then widened as above.
// INVALID_ARGUMENT as above, when no cube Draco can use contains `bounds`.
absl::StatusOr<QuantizationBox> GrowQuantizationCube(QuantizationBox box, const BoundingBox& bounds,
                                                     int bits);

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_QUANTIZATION_CUBE_H_
