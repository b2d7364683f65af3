// The vertices of a binary PLY file as point records read where they lie (point_records.h):
// for sampling a scan's PLY file without reading it whole (core/sampling/off_core_sampler.h).
#ifndef NEURALMESH_CORE_IO_INTERNAL_PLY_VERTEX_RECORDS_H_
#define NEURALMESH_CORE_IO_INTERNAL_PLY_VERTEX_RECORDS_H_

#include <memory>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/internal/point_records.h"

namespace neuralmesh::io_internal {

// The 'vertex' element of the binary PLY file `data` (which must outlive the result), whose
// records all have one size: its x, y and z (and red, green and blue: StatedColor) as ParsePly
// reads them, records with a non-finite coordinate not kept (ParsePly refuses the whole file for
// one). No resolution or bounds are stated. Returns ParsePlyHeader's errors; INVALID_ARGUMENT, saying why, for an ASCII file (its
// lines have no fixed length), no 'vertex' element or no x, y or z in it, a list property in
// it or in an element before it (records whose size depends on their contents), and a body
// too short for the elements before it and the vertices.
absl::StatusOr<std::unique_ptr<PointRecords>> PlyVertexRecords(absl::string_view data);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_PLY_VERTEX_RECORDS_H_
