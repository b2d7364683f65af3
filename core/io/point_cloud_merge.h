// Several point clouds as one: the scans of a site in separate files (a PTX or LAS file per
// station or tile) learned as one surface.
#ifndef NEURALMESH_CORE_IO_POINT_CLOUD_MERGE_H_
#define NEURALMESH_CORE_IO_POINT_CLOUD_MERGE_H_

#include <vector>

#include "core/point_cloud.h"

namespace neuralmesh {

// The points of `clouds` one cloud after another, each where its own origin puts it. When
// every cloud has the same origin, the positions are kept as they are; otherwise they are
// taken relative to an origin chosen for all of them, as a reader chooses one
// (internal/position_collector.h). Normals, weights and colours are kept where every cloud has
// them, and dropped otherwise.
PointCloud MergePointClouds(std::vector<PointCloud> clouds);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_POINT_CLOUD_MERGE_H_
