// The version of neuralmesh (the CMake project's) and of the geometry libraries it was built
// with, for `neuralmesh --version`, `neuralmesh-server --version` and the server's metrics.
#ifndef NEURALMESH_CORE_VERSION_H_
#define NEURALMESH_CORE_VERSION_H_

#include <string>

namespace neuralmesh {

// "0.1.0".
const char* NeuralmeshVersion();

// "Draco 1.5.5, OpenMesh 9.0.0": the versions of the headers this build was compiled against.
std::string GeometryLibraryVersions();

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_VERSION_H_
