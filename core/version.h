// The version of neuralmesh (the CMake project's) and of the geometry libraries it was built
// with, for `neuralmesh --version`, `neuralmesh-server --version` and the server's metrics.
#ifndef NEURALMESH_CORE_VERSION_H_
#define NEURALMESH_CORE_VERSION_H_

#include <string>

#include "absl/strings/string_view.h"

namespace neuralmesh {

// "0.1.0".
const char* NeuralmeshVersion();

// "neuralmesh 0.1.0 (Draco 1.5.5, OpenMesh 9.0.0, gRPC 1.51.1)" for `program` "neuralmesh" and
// `more` "gRPC 1.51.1": the versions of the headers this build was compiled against, then
// `more` (the libraries core does not know).
std::string VersionLine(absl::string_view program, absl::string_view more);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_VERSION_H_
