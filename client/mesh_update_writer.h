// Saves and prints the meshes a server publishes for one session (neuralmesh watch and
// neuralmesh reconstruct --server).
#ifndef NEURALMESH_CLIENT_MESH_UPDATE_WRITER_H_
#define NEURALMESH_CLIENT_MESH_UPDATE_WRITER_H_

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "client/lod_table.h"
#include "neuralmesh/v1/reconstruction.pb.h"

namespace neuralmesh::client {

struct MeshUpdateWriterOptions {
  std::string out_dir;  // Created when missing.
  std::string stem;     // File name stem: <stem>_lod<N>.drc per milestone, <stem>.drc final.
  // Extensions (".ply", ".glb", any of kMeshExtensions) each saved mesh is also written in,
  // decoded, beside the .drc.
  std::vector<std::string> also;
};

// The figures of one update, as printed in the LOD table.
LodFigures FiguresOf(const v1::MeshUpdate& update);

class MeshUpdateWriter {
 public:
  // Rows go to `out` (the header before the first one).
  MeshUpdateWriter(MeshUpdateWriterOptions options, std::ostream& out);

  // Saves `update` when it is a milestone or the final mesh (refreshes are only printed),
  // then prints its row. Returns the error of creating the directory or writing a file, or
  // INVALID_ARGUMENT when a mesh that must be written in another format does not decode.
  absl::Status Write(const v1::MeshUpdate& update);

  bool final_received() const { return final_received_; }
  // The rows of the saved updates, in arrival order.
  const std::vector<LodFigures>& saved() const { return saved_; }

 private:
  MeshUpdateWriterOptions options_;
  std::ostream& out_;
  bool header_printed_ = false;
  bool final_received_ = false;
  std::vector<LodFigures> saved_;
};

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_MESH_UPDATE_WRITER_H_
