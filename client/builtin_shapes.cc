#include "client/builtin_shapes.h"

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "core/status_macros.h"

namespace neuralmesh::client {
namespace {

struct Builtin {
  absl::string_view name;
  int reference_resolution;  // ImplicitSurface::ReferenceMesh's n: about 10^4 vertices.
};

constexpr Builtin kBuiltins[] = {{"sphere", 16}, {"torus", 16}, {"genus2", 5}};

absl::StatusOr<const Builtin*> FindBuiltin(absl::string_view input) {
  absl::string_view name = input;
  absl::ConsumePrefix(&name, kBuiltinPrefix);
  for (const Builtin& b : kBuiltins) {
    if (b.name == name) return &b;
  }
  return absl::InvalidArgumentError(absl::StrCat(
      "unknown built-in shape '", input, "'; use builtin:sphere, builtin:torus or builtin:genus2"));
}

}  // namespace

bool IsBuiltin(absl::string_view input) { return absl::StartsWith(input, kBuiltinPrefix); }

absl::StatusOr<std::unique_ptr<ImplicitSurface>> MakeBuiltinSurface(absl::string_view input) {
  NM_ASSIGN_OR_RETURN(const Builtin* builtin, FindBuiltin(input));
  const Vec3 origin(0, 0, 0);
  if (builtin->name == "sphere") return MakeSphere(origin, 1.0);
  if (builtin->name == "torus") return MakeTorus(origin, 1.0, 0.4);
  return MakeGenusTwo(origin, 1.0, 0.15);
}

absl::StatusOr<TriangleMesh> BuiltinReferenceMesh(absl::string_view input) {
  NM_ASSIGN_OR_RETURN(const Builtin* builtin, FindBuiltin(input));
  NM_ASSIGN_OR_RETURN(const std::unique_ptr<ImplicitSurface> surface, MakeBuiltinSurface(input));
  return surface->ReferenceMesh(builtin->reference_resolution);
}

}  // namespace neuralmesh::client
