#include "client/lod_table.h"

#include "absl/strings/str_format.h"

namespace neuralmesh::client {

void PrintLodHeader(std::ostream& out) {
  out << absl::StrFormat("%-9s %9s %9s %7s %5s %10s %12s %9s  %s\n", "kind", "vertices", "faces",
                         "val6", "genus", "boundaries", "basic_steps", "elapsed", "file");
}

void PrintLodRow(const LodFigures& f, std::ostream& out) {
  out << absl::StrFormat("%-9s %9d %9d %6.1f%% %5d %10d %12d %8.2fs  %s\n", f.kind, f.vertices,
                         f.faces, f.valence6_percent, f.genus, f.boundaries, f.basic_steps,
                         absl::ToDoubleSeconds(f.elapsed), f.path.empty() ? "-" : f.path)
      << std::flush;
}

}  // namespace neuralmesh::client
