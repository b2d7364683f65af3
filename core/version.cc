#include "core/version.h"

#include <OpenMesh/Core/System/config.h>

#include "absl/strings/str_cat.h"
#include "draco/core/draco_version.h"

#ifndef NEURALMESH_VERSION
#error "NEURALMESH_VERSION is set by core/CMakeLists.txt"
#endif

namespace neuralmesh {

const char* NeuralmeshVersion() { return NEURALMESH_VERSION; }

std::string VersionLine(absl::string_view program, absl::string_view more) {
  return absl::StrCat(program, " ", NeuralmeshVersion(), " (Draco ", draco::kDracoVersion,
                      ", OpenMesh ", OM_GET_VER, ".", OM_GET_MAJ, ".", OM_GET_MIN,
                      more.empty() ? "" : ", ", more, ")");
}

}  // namespace neuralmesh
