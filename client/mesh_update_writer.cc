#include "client/mesh_update_writer.h"

#include <filesystem>
#include <system_error>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/io/draco_codec.h"
#include "core/io/file_contents.h"
#include "core/io/mesh_io.h"
#include "core/status_macros.h"

namespace neuralmesh::client {
namespace {

std::string KindName(v1::UpdateKind kind) {
  switch (kind) {
    case v1::UPDATE_KIND_MILESTONE:
      return "lod";
    case v1::UPDATE_KIND_REFRESH:
      return "refresh";
    case v1::UPDATE_KIND_FINAL:
      return "final";
    default:
      return "update";
  }
}

}  // namespace

LodFigures FiguresOf(const v1::MeshUpdate& update) {
  LodFigures f;
  f.kind = KindName(update.kind());
  f.vertices = update.vertex_count();
  f.faces = update.face_count();
  f.valence6_percent = update.report().valence6_share();
  f.genus = update.report().genus();
  f.boundaries = update.report().boundary_loops();
  f.basic_steps = update.learning().basic_steps();
  f.elapsed = absl::Seconds(update.learning().learning_seconds());
  return f;
}

MeshUpdateWriter::MeshUpdateWriter(MeshUpdateWriterOptions options, std::ostream& out)
    : options_(std::move(options)), out_(out) {}

absl::Status MeshUpdateWriter::Write(const v1::MeshUpdate& update) {
  LodFigures figures = FiguresOf(update);
  const bool is_final = update.kind() == v1::UPDATE_KIND_FINAL;
  if (is_final || update.kind() == v1::UPDATE_KIND_MILESTONE) {
    std::error_code error;
    std::filesystem::create_directories(options_.out_dir, error);
    if (error) {
      return absl::PermissionDeniedError(
          absl::StrCat("cannot create --out-dir ", options_.out_dir, ": ", error.message()));
    }
    const std::string name =
        is_final ? options_.stem : absl::StrCat(options_.stem, "_lod", update.vertex_count());
    const std::filesystem::path base = std::filesystem::path(options_.out_dir) / name;
    figures.path = base.string() + ".drc";
    NM_RETURN_IF_ERROR(WriteFileContents(figures.path, update.draco_mesh()));
    if (!options_.also.empty()) {
      absl::StatusOr<TriangleMesh> mesh = DecodeMesh(update.draco_mesh());
      if (!mesh.ok()) {
        return absl::InvalidArgumentError(
            absl::StrCat("update ", update.sequence(), ": ", mesh.status().message()));
      }
      for (const std::string& extension : options_.also) {
        NM_RETURN_IF_ERROR(WriteMesh(*mesh, base.string() + extension));
      }
    }
    saved_.push_back(figures);
  }
  if (!header_printed_) {
    PrintLodHeader(out_);
    header_printed_ = true;
  }
  PrintLodRow(figures, out_);
  final_received_ = final_received_ || is_final;
  return absl::OkStatus();
}

}  // namespace neuralmesh::client
