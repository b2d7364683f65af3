// Where positions put (0, 0, 0) in the coordinates of the data they came from: georeferenced
// data are held relative to a nearby origin so that floats keep their resolution
// (core/io/internal/position_collector.h). Zero for most data.
#ifndef NEURALMESH_CORE_ORIGIN_H_
#define NEURALMESH_CORE_ORIGIN_H_

#include <array>

namespace neuralmesh {

using Origin = std::array<double, 3>;

// The origin of positions that are the data's own coordinates.
inline constexpr Origin kNoOrigin = {0, 0, 0};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_ORIGIN_H_
