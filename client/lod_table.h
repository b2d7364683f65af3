// The figures printed for each level of detail, locally and from a server, as a table.
#ifndef NEURALMESH_CLIENT_LOD_TABLE_H_
#define NEURALMESH_CLIENT_LOD_TABLE_H_

#include <cstdint>
#include <ostream>
#include <string>

#include "absl/time/time.h"

namespace neuralmesh::client {

struct LodFigures {
  std::string kind;  // "lod", "final", or a server update's kind.
  uint64_t vertices = 0;
  uint64_t faces = 0;
  double valence6_percent = 0;  // Interior vertices of valence 6, in percent (Section 3.4).
  int64_t genus = 0;
  uint64_t boundaries = 0;   // Boundary loops.
  uint64_t basic_steps = 0;  // Cumulative Basic Steps of the learner.
  absl::Duration elapsed;    // Learning time so far.
  std::string path;          // Where the level was written; empty when not written.
};

// The column titles, then one row per level, aligned with each other.
void PrintLodHeader(std::ostream& out);
void PrintLodRow(const LodFigures& figures, std::ostream& out);

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_LOD_TABLE_H_
