// Draco compression of triangle meshes and point clouds behind one typed wrapper: callers never
// see Draco's types or its string-keyed options.
//
// Meshes are encoded with Edgebreaker (small ones several ways, keeping the shortest stream:
// see DracoOptions::shrink_small_meshes), point clouds with the kd-tree coder (the sequential
// coder at encode_speed 10, which keeps the point order). Positions are quantized
// uniformly: with b bits, a coordinate decodes to within range / (2^b - 1) / 2 of its input,
// where range is the edge of the quantization cube (the largest side of the bounding box, or
// QuantizationBox::range).
//
// Draco may reorder vertices and faces. Edgebreaker keeps only vertices that some face uses,
// drops degenerate faces (a repeated vertex index), and splits non-manifold vertices (and
// vertices where orientation is inconsistent) into copies at the same position.
//
// A mesh's or cloud's non-zero origin (TriangleMesh::origin, PointCloud::origin) is stored as
// the geometry metadata entry "origin", three doubles, and decoded back; decoders that ignore
// metadata see the positions relative to it.
#ifndef NEURALMESH_CORE_IO_DRACO_CODEC_H_
#define NEURALMESH_CORE_IO_DRACO_CODEC_H_

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/mesh.h"
#include "core/point_cloud.h"
#include "core/triangle_mesh.h"

namespace neuralmesh {

// An axis-aligned cube [origin, origin + range]^3 that positions are quantized against.
struct QuantizationBox {
  Vec3f origin{0.0f, 0.0f, 0.0f};  // The cube's minimum corner.
  float range = 0;                 // Edge length; must be finite and positive.
};

// The most quantization bits any attribute may ask for. Draco accepts up to 30, but its
// entropy coder sizes a table by the largest symbol, so an encoding costs time and memory in
// proportion to 2^bits whatever the geometry's size (measured with Draco 1.5.5 on a 25-vertex
// mesh without prediction: 17 MB and 1-6 ms at 20 bits, 149 MB and 0.1 s at 24, 2 GB and 2 s
// at 28); at 30 bits its mesh encoder crashes. More than 24 bits, a float's significand, add
// no precision to float positions.
inline constexpr int kMaxQuantizationBits = 24;
// Draco's speed settings run from 0 (smallest output) to this (fastest).
inline constexpr int kMaxDracoSpeed = 10;

struct DracoOptions {
  int position_quantization_bits = 11;  // 1..kMaxQuantizationBits.
  int normal_quantization_bits = 10;    // 2..kMaxQuantizationBits; point-cloud normals.
  int weight_quantization_bits = 16;    // 1..kMaxQuantizationBits; point weights, against
                                        // their own min..max.
  int encode_speed = 5;                 // 0 (smallest output) .. kMaxDracoSpeed (fastest).
  int decode_speed = 5;                 // 0 .. kMaxDracoSpeed.
  // Meshes under 64 vertices are also encoded at speeds 0 and 10, and the shortest stream is
  // kept. Draco's fixed cost (about 70 bytes) dominates such meshes, and which settings save
  // most varies from mesh to mesh (a few bytes at 10-30 vertices); each try takes about 0.1 ms. Every variant decodes to the same mesh,
  // with any Draco 1.5 decoder. False: exactly the speeds above.
  bool shrink_small_meshes = true;
  // When set, positions are quantized against this fixed cube instead of each geometry's own
  // bounding box, so successive meshes of one session share one grid (no jitter, no cracks):
  // the same input position always decodes to bit-identical floats. Draco uses the cube as it
  // reads it, rounded to six decimals (see DracoExactBox). Every position must lie inside that
  // cube, give or take a quarter grid step for float rounding; encoding returns
  // INVALID_ARGUMENT otherwise (nothing is clamped).
  std::optional<QuantizationBox> quantization_box;

  // Returns INVALID_ARGUMENT naming the first field that is out of range.
  absl::Status Validate() const;
};

// The smallest box containing `box` that Draco keeps exactly. Draco's encoder receives a fixed
// box as text with six decimals (std::to_string), so a box of origin 1e-7 and edge 3e-9 reaches
// it as origin 0 and edge 0, and any other box moves by up to 5e-7. The returned box's origin
// and edge are millionths (floats above 8 or so: themselves); for data spanning less than about
// 1e-3 the grid gets coarser than asked. Callers that announce their grid use it.
QuantizationBox DracoExactBox(const QuantizationBox& box);

// OK when Draco can quantize positions against `box` (as it reads the box) at `bits` bits per
// coordinate: finite, positive, and neither too small for a step nor reaching past the largest
// float; else INVALID_ARGUMENT saying which.
absl::Status CheckQuantizationBox(const QuantizationBox& box, int bits);

// The box Draco quantizes against when given `box`: its origin and edge rounded to six
// decimals (a box of origin 1e-7 and edge 3e-9 becomes origin 0 and edge 0). DracoExactBox's
// boxes come back unchanged.
QuantizationBox BoxAsDracoReadsIt(const QuantizationBox& box);

// Encodes `mesh` (positions, faces, and colours as a COLOR attribute of three normalized bytes,
// coded losslessly) with Edgebreaker; see shrink_small_meshes for meshes under 64 vertices.
// Returns INVALID_ARGUMENT when `options` is invalid, the mesh has no vertices or no
// non-degenerate faces, a face index is out of range, a coordinate is not finite, a position
// lies outside `options.quantization_box` (as Draco reads it), the colours are not one per
// vertex, or the grid cannot be quantized in float (an edge too small for its step, or
// spanning nearly the whole float range); INTERNAL if Draco fails for another reason.
absl::StatusOr<std::string> EncodeMesh(const TriangleMesh& mesh, const DracoOptions& options);

// How EncodeMeshForGltf stores colours and which attributes a decoder of glTF's
// KHR_draco_mesh_compression finds them in (the extension names attributes by unique id).
inline constexpr int kGltfDracoPositionId = 0;
inline constexpr int kGltfDracoColorId = 1;

// Encodes `mesh` as EncodeMesh does, for a glTF primitive: POSITION has unique id
// kGltfDracoPositionId and colours, when present, are linear light (glTF's COLOR_0) in a COLOR
// attribute of three normalized 16-bit integers with unique id kGltfDracoColorId. Returns what
// EncodeMesh returns.
absl::StatusOr<std::string> EncodeMeshForGltf(const TriangleMesh& mesh,
                                              const DracoOptions& options);

// Decodes the Draco mesh of a glTF primitive (KHR_draco_mesh_compression) as glTF's accessors
// count it: one vertex per Draco point (vertices at one position are not merged), positions from
// the attribute with unique id `position_id`, and colours, when `color_id` is not negative,
// from that attribute, read as linear light and converted to sRGB channels. Returns
// INVALID_ARGUMENT as DecodeMesh does, and when an attribute with either id is missing, has
// fewer than three components or is not numeric.
absl::StatusOr<TriangleMesh> DecodeGltfDracoMesh(std::string_view bytes, int position_id,
                                                 int color_id);

// Encodes the positions of `cloud`, its normals, its weights (as a generic one-component
// attribute) and its colours (COLOR, three bytes) when present.
// Returns INVALID_ARGUMENT as EncodeMesh does, also when the cloud is empty or fails
// ValidatePointCloud, or its weights' spread cannot be quantized; INTERNAL if Draco fails for
// another reason.
absl::StatusOr<std::string> EncodePointCloud(const PointCloud& cloud, const DracoOptions& options);

// Decodes a Draco mesh: one position per distinct position value, the triangles, and colours
// when there is a COLOR attribute of three or four components (bytes as they are, other
// integers as levels of their type, floats and normalized integers as fractions; alpha is
// dropped).
// Returns INVALID_ARGUMENT when `bytes` is not a valid Draco mesh (corrupt, truncated, a point
// cloud, no numeric position attribute, non-finite positions, counts of vertices or faces far
// beyond what its size can hold: more than 2^20 and 256 per byte, or a bitstream version older
// than what current Draco encoders write: 2.2 for meshes, 2.3 for point clouds), and when its
// metadata entry "origin" is not three finite numbers.
absl::StatusOr<TriangleMesh> DecodeMesh(std::string_view bytes);

// Decodes a Draco point cloud, or the points of a Draco mesh; restores normals (the NORMAL
// attribute), weights (the first one-component GENERIC attribute) and colours (COLOR, as
// DecodeMesh reads them) when present.
// Returns INVALID_ARGUMENT when `bytes` is not valid Draco data (as for DecodeMesh), has no
// numeric positions, or decodes to a cloud that fails ValidatePointCloud; RESOURCE_EXHAUSTED,
// before anything is decoded, when it declares more than `max_points` points (for a mesh:
// vertices, or faces beyond twice that), so that a caller with a limit never allocates for
// more (points that compress well declare millions in a few bytes).
absl::StatusOr<PointCloud> DecodePointCloud(
    std::string_view bytes, uint64_t max_points = std::numeric_limits<uint64_t>::max());

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_DRACO_CODEC_H_
