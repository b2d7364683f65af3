// The built-in inputs builtin:sphere, builtin:torus and builtin:genus2: implicit surfaces
// (core/sampling/implicit_surfaces.h) that need no data file, for demos and tests.
#ifndef NEURALMESH_CLIENT_BUILTIN_SHAPES_H_
#define NEURALMESH_CLIENT_BUILTIN_SHAPES_H_

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/sampling/implicit_surfaces.h"
#include "core/triangle_mesh.h"

namespace neuralmesh::client {

inline constexpr absl::string_view kBuiltinPrefix = "builtin:";

// Whether `input` names a built-in shape (starts with "builtin:").
bool IsBuiltin(absl::string_view input);

// The surface of builtin:NAME: sphere (unit radius at the origin), torus (R = 1, r = 0.4
// around the z axis) or genus2 (the lemniscate tube, scale 1, thickness 0.1).
// INVALID_ARGUMENT naming the known shapes for any other name.
absl::StatusOr<std::unique_ptr<ImplicitSurface>> MakeBuiltinSurface(absl::string_view input);

// The dense reference tessellation of builtin:NAME used by `neuralmesh eval` and `stats`
// (about 10^4 vertices).
absl::StatusOr<TriangleMesh> BuiltinReferenceMesh(absl::string_view input);

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_BUILTIN_SHAPES_H_
