// neuralmesh: Neural Meshes surface reconstruction (Ivrissimtzis, Jeong, Seidel) on the
// command line, locally or through a neuralmesh-server. This file holds the flags and the
// dispatch only; the commands live in the neuralmesh_client library.
#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/time/time.h"
#include "client/command_line.h"
#include "client/inputs.h"
#include "client/local_commands.h"
#include "client/lod_plan.h"
#include "client/progress_bar.h"
#include "client/remote_commands.h"
#include "client/session_commands.h"
#include "client/web/run_view.h"
#include "client/web/viewer_key.h"
#include "core/analysis/color_source.h"
#include "core/analysis/statistical_outliers.h"
#include "core/io/draco_codec.h"
#include "core/io/file_contents.h"
#include "core/io/las_cleaning.h"
#include "core/io/point_selection.h"
#include "core/learning/learner_options.h"
#include "core/status_macros.h"
#include "core/version.h"

namespace {
const neuralmesh::LearnerOptions kLearnerDefaults;
const neuralmesh::DracoOptions kDracoDefaults;
}  // namespace

// Output and size.
ABSL_FLAG(std::string, output, "",
          "Local reconstruct: the mesh to write; the extension picks the format (.ply .obj .off "
          ".stl .drc .glb .gltf). LOD files go beside it as <stem>_lod<N><ext>. get: where the "
          "session's mesh goes. convert: the file written (a mesh's format, or a point cloud's: "
          ".ply .xyz .txt .pts .ptx .las .laz .pcd .e57 .drc .glb .gltf).");
ABSL_FLAG(uint64_t, vertices, 0,
          "Vertex count of the final mesh (met exactly). Required for a local reconstruct; with "
          "--server, 0 means one vertex per 2 points, at most 10000.");
ABSL_FLAG(std::string, lod, "",
          "Comma-separated vertex counts below --vertices at which a level of detail is "
          "written, e.g. 1000,2000. With --server, empty means the server's 1-2-5 series.");

// Learner parameters: defaults and ranges from core/learning/learner_options.h.
ABSL_FLAG(uint64_t, seed, kLearnerDefaults.seed,
          "Seed of every random choice: the learner, the points drawn from builtin:NAME for "
          "upload, eval's surface samples. Equal seeds give identical output.");
ABSL_FLAG(double, alpha_w, kLearnerDefaults.alpha_w,
          "alpha_w (Eq. 1): how far the winner moves toward the sample, in (0, 1].");
ABSL_FLAG(double, alpha_l, kLearnerDefaults.alpha_l,
          "alpha_L (Section 2.1): tangential Laplacian smoothing rate, in [0, 1].");
ABSL_FLAG(int32_t, c_l, kLearnerDefaults.c_l,
          "C_L (Section 2.1): smoothing iterations per Basic Step, >= 0.");
ABSL_FLAG(int32_t, c_vs, kLearnerDefaults.c_vs,
          "C_vs (Section 2.2): Basic Steps between two vertex splits, >= 1.");
ABSL_FLAG(double, c_ec, kLearnerDefaults.c_ec,
          "C_ec (Section 2.2): the half-edge collapse step runs every C_ec * v Basic Steps, > 0 "
          "(v counted as at least C_vs, not in the paper).");
ABSL_FLAG(uint64_t, early_phase_vertices, kLearnerDefaults.early_phase_vertices,
          "The paper's early phase (Section 4, its David model): until the mesh first has this "
          "many vertices, Steps 2 and 3 run with --early_c_vs and --early_c_ec. 0: none; the "
          "paper's David setting is 10000.");
ABSL_FLAG(int32_t, early_c_vs, kLearnerDefaults.early_c_vs,
          "C_vs of the early phase (--early_phase_vertices), >= 1.");
ABSL_FLAG(double, early_c_ec, kLearnerDefaults.early_c_ec,
          "C_ec of the early phase (--early_phase_vertices), > 0.");
ABSL_FLAG(double, alpha_sc, kLearnerDefaults.alpha_sc,
          "alpha_sc (Section 2.2, Eq. 4): signal counter decay, in (0, 1).");
ABSL_FLAG(double, alpha_r, kLearnerDefaults.alpha_r,
          "alpha_r (Eq. 2): remove triangles larger than alpha_r E(Area).");
ABSL_FLAG(double, alpha_m, kLearnerDefaults.alpha_m,
          "alpha_m (Eq. 3): merge boundaries closer than alpha_m sqrt(E(Area)).");
ABSL_FLAG(bool, remove_triangles, kLearnerDefaults.remove_triangles,
          "Step 4 (Section 2.3): triangle removal on or off (--noremove_triangles).");
ABSL_FLAG(bool, merge_boundaries, kLearnerDefaults.merge_boundaries,
          "Step 5 (Section 2.3): boundary merging on or off (--nomerge_boundaries).");
ABSL_FLAG(int32_t, splits_per_step, kLearnerDefaults.splits_per_step,
          "Vertex splits per call of Step 2 (Section 3.3), >= 1.");
ABSL_FLAG(bool, close_small_holes, kLearnerDefaults.close_small_holes,
          "Step 5: refill holes, and zip slits and cracks in longer borders, where the filling "
          "passes Step 4's area test and bridges no more than Step 5 would "
          "(--noclose_small_holes).");
ABSL_FLAG(int32_t, max_closed_hole_vertices, kLearnerDefaults.max_closed_hole_vertices,
          "The largest boundary loop, in vertices, that close_small_holes refills, >= 3.");
ABSL_FLAG(bool, merge_only_settled_boundaries, kLearnerDefaults.merge_only_settled_boundaries,
          "Step 5 skips loops that Step 4 cut into in the same call "
          "(--nomerge_only_settled_boundaries).");
ABSL_FLAG(bool, split_largest_cell_near_most_active,
          kLearnerDefaults.split_largest_cell_near_most_active,
          "Step 2 splits the largest cell (F_v, Eq. 5-6) of the most active vertex's 1-ring; "
          "--nosplit_largest_cell_near_most_active splits the most active vertex itself.");
ABSL_FLAG(int32_t, sewn_strip_grace_calls, kLearnerDefaults.sewn_strip_grace_calls,
          "Calls of Step 4 that spare the faces around a strip Step 5 has just sewn, in "
          "[0, 1000]; 0 is the paper's rule.");
ABSL_FLAG(int32_t, min_merged_loop_vertices, kLearnerDefaults.min_merged_loop_vertices,
          "Step 5 merges only boundary loops of at least this many vertices, in [3, 1000]; 3 "
          "is the paper's rule.");
ABSL_FLAG(bool, cut_inactive_faces, kLearnerDefaults.cut_inactive_faces,
          "After Step 4: cut out faces over no data that Steps 3 and 4 cannot remove, a "
          "bridge between two holes and the faces of a border vertex Step 3 could not "
          "collapse (--nocut_inactive_faces).");
ABSL_FLAG(std::string, initial_mesh,
          std::string(neuralmesh::InitialMeshName(kLearnerDefaults.initial_mesh)),
          "The mesh learning starts from: tetrahedron (the paper's; closed surfaces and open "
          "ones that curve round) or disc (a flat disc in the data's best-fit plane whose "
          "border is never refilled: open, nearly flat sheets such as one range scan, a "
          "terrain or a facade).");

ABSL_FLAG(std::string, start_mesh, "",
          "Learn on from this mesh (.ply .obj .off .stl .drc .glb .gltf, for example an earlier "
          "OUTPUT or "
          "final mesh) instead of --initial_mesh, refining it with INPUT's points to "
          "--vertices, which must exceed its vertex count. It must be an orientable manifold "
          "triangle mesh, with or without borders, every vertex on a face and no face of zero "
          "area. --initial_mesh disc still keeps its longest border open. With --server the "
          "mesh is sent exactly (CreateSessionRequest.start_mesh); not with --resume.");

ABSL_FLAG(bool, off_core, false,
          "Read the one INPUT, an uncompressed LAS, binary PLY or binary PCD file (or with "
          "--server a LAZ file), where it lies, mapped into memory, instead of reading it "
          "whole: learning (or the upload) starts at once whatever the file's size, and memory "
          "holds the mesh, not the points (the paper's off-core learning of 28 million points, "
          "Section 4.1). Locally, records are sampled where they lie (uniform sampling; colours "
          "are not painted). With --server, the records are uploaded in an order spread over "
          "the whole file from the first batch on (blocks of 256 records along a golden-ratio "
          "stride), so the first meshes outline the whole scan; a LAZ file is decoded a chunk "
          "at a time, eight chunks spread over the file at once, never whole. Colours go from "
          "LAS and LAZ, not from PLY or PCD. --resume reads the records before the session's "
          "points again. No --remove_outliers in the client (--outliers_on_server is fine).");

ABSL_FLAG(std::string, pcd_data, "binary",
          "How convert stores the points of a .pcd OUTPUT (its DATA line): binary (point "
          "records), binary_compressed (field by field, LZF-compressed, as PCL keeps maps) or "
          "ascii.");

// Input clean-up.
ABSL_FLAG(std::string, las_classes, "",
          "The ASPRS classes whose points are read from LAS files, as numbers and ranges "
          "(2 ground, 6 building: '2,6'; '1-6,9'), or 'all'. Unset: every class but noise (7, "
          "low point; 18, high noise). Withheld points are never read.");
ABSL_FLAG(bool, remove_outliers, false,
          "Remove a point cloud's statistical outliers before learning, upload or convert: "
          "points whose "
          "mean distance to their --outlier_neighbours nearest points exceeds the mean of "
          "that distance by more than --outlier_std_ratio standard deviations (as PCL and "
          "Open3D define them). Not in the paper.");
ABSL_FLAG(int32_t, outlier_neighbours, neuralmesh::OutlierOptions{}.neighbours,
          "With --remove_outliers: the neighbours each point's mean distance is taken over, "
          "in [1, 256].");
ABSL_FLAG(double, outlier_std_ratio, neuralmesh::OutlierOptions{}.std_ratio,
          "With --remove_outliers: how many standard deviations above the mean distance "
          "make an outlier, > 0.");
ABSL_FLAG(int32_t, outlier_passes, neuralmesh::OutlierOptions{}.passes,
          "With --remove_outliers: passes over the cloud, in [1, 16], each judging the points "
          "the one before kept (a few far strays widen the deviation enough to hide milder "
          "ones from the first). The server's filter (--outliers_on_server) makes one.");
ABSL_FLAG(bool, outliers_as_noise, false,
          "With --remove_outliers, converting .las/.laz files to .las/.laz: keep the outliers' "
          "records, classified as noise (ASPRS class 7, low point; the readers leave such "
          "points out), instead of removing them, as PDAL's outlier filter marks them.");
ABSL_FLAG(bool, outliers_on_server, false,
          "With --remove_outliers and --server: the session removes the outliers as the batches "
          "arrive (SessionConfig.outlier_removal), as for a client that streams a scan, instead "
          "of this command filtering the whole file before upload.");

// Colours.
ABSL_FLAG(bool, colors, true,
          "When INPUT's points (or, with --sampling area|curvature, its mesh's vertices) carry "
          "colours, give every mesh written a colour per vertex: the inverse-distance weighted "
          "mean of its --color_neighbours nearest points' colours (for a mesh INPUT, the colour "
          "of its nearest surface point). STL files keep none. With --server the colours are "
          "uploaded and the session paints its meshes so (--nocolors: uploaded without). Not "
          "in the paper.");
ABSL_FLAG(int32_t, color_neighbours, neuralmesh::PointColorOptions{}.neighbours,
          "With --colors: how many of the nearest points a vertex's colour blends, in [1, 64] "
          "(1: the nearest point's colour); with --server the session's "
          "(SessionConfig.color_neighbours).");

// Local learning.
ABSL_FLAG(std::string, sampling, "uniform",
          "How INPUT is sampled: uniform or weighted (a point cloud; weighted uses its "
          "per-point weights), area or curvature (a triangle mesh: remeshing, Section 4.1).");
ABSL_FLAG(absl::Duration, time_budget, absl::InfiniteDuration(),
          "Stop learning after this long (e.g. 30s, 2m) and write the mesh learned so far.");
ABSL_FLAG(uint64_t, max_steps, 0,
          "Stop learning after this many Basic Steps and write the mesh so far; 0: no limit.");
ABSL_FLAG(int32_t, quantization_bits, kDracoDefaults.position_quantization_bits,
          "Draco position quantization bits (1..24) for .drc meshes and --gltf_draco.");
ABSL_FLAG(int32_t, encode_speed, kDracoDefaults.encode_speed,
          "Draco encoder speed, 0 (smallest) .. 10 (fastest), for .drc meshes and --gltf_draco.");
ABSL_FLAG(bool, gltf_draco, false,
          "Compress .glb and .gltf outputs with Draco (KHR_draco_mesh_compression; positions "
          "quantized by --quantization_bits). Off: plain glTF, which every glTF reader takes.");
ABSL_FLAG(bool, progress, false, "Draw progress bars on stderr even when it is not a terminal.");

// Server.
ABSL_FLAG(std::string, server, "",
          "HOST:PORT of a neuralmesh-server; with reconstruct, learn there instead of locally.");
ABSL_FLAG(std::string, out_dir, "",
          "Directory for the meshes a server publishes: <stem>_lod<N>.drc per milestone and "
          "<stem>.drc for the final mesh.");
ABSL_FLAG(uint64_t, batch_size, 10000, "Points per uploaded batch.");
ABSL_FLAG(uint64_t, points, 100000,
          "Points sampled from a builtin:NAME input before it is uploaded.");
ABSL_FLAG(bool, ply, false, "Also write each mesh received from the server as .ply.");
ABSL_FLAG(bool, glb, false, "Also write each mesh received from the server as .glb (glTF).");
ABSL_FLAG(std::string, resume, "",
          "reconstruct --server: the id of a session whose upload lost its connection; the "
          "upload goes on from the points the session has taken (run with the same INPUT and "
          "input flags; the session keeps its configuration).");
ABSL_FLAG(absl::Duration, reconnect_for, neuralmesh::client::ReconnectOptions().give_up_after,
          "reconstruct --server and watch: how long to keep trying when the connection to the "
          "server is lost, counted from the last batch taken or mesh received (the upload goes "
          "on from the points the session has taken, the watch from its last mesh); 0: give up "
          "at once (reconstruct then prints the --resume command). sessions: how long to wait "
          "for a server that is out of reach or still restoring its sessions after a restart.");
ABSL_FLAG(bool, final, false,
          "get: the final mesh of a finished session instead of the latest mesh.");
ABSL_FLAG(std::string, to, "",
          "transfer: the client that is to own the session (a client name of the server's "
          "tokens file, or a client certificate's common name).");
ABSL_FLAG(absl::Duration, wait, absl::ZeroDuration(),
          "get: wait up to this long for the mesh to exist (a first mesh, or with --final the "
          "final one); 0: it must exist now.");
ABSL_FLAG(absl::Duration, connect_timeout, absl::Seconds(5),
          "How long to wait for the server to accept the connection.");
ABSL_FLAG(int, max_message_bytes, neuralmesh::client::ClientOptions().max_message_bytes,
          "The largest message taken from the server (a mesh of about 2 bytes a vertex): as "
          "neuralmesh-server's --max_message_bytes.");
ABSL_FLAG(bool, tls, false,
          "Connect over TLS, checking the server's certificate against the system's CAs (or "
          "--tls_ca_file's).");
ABSL_FLAG(std::string, tls_ca_file, "",
          "PEM file with the CAs that sign the server's certificate, instead of the system's; "
          "implies --tls.");
ABSL_FLAG(std::string, tls_cert_file, "",
          "PEM file with this client's certificate, for servers that require one (mutual "
          "TLS); implies --tls and needs --tls_key_file.");
ABSL_FLAG(std::string, tls_key_file, "", "PEM file with the private key of --tls_cert_file.");
ABSL_FLAG(std::string, tls_server_name, "",
          "The name the server's certificate must carry when it is not the host of --server "
          "(through an SSH tunnel or a port forward to 127.0.0.1); implies --tls.");
ABSL_FLAG(std::string, access_token_file, "",
          "File holding the access token the server asks for (sent as 'authorization: Bearer "
          "TOKEN' with every call); needs TLS. Keep it readable by its owner only.");

// Viewer.
ABSL_FLAG(std::string, listen, neuralmesh::client::web::ViewOptions().listen,
          "view: HOST:PORT where browsers connect (port 0: any free port). Bind 0.0.0.0 only "
          "on a trusted network: the viewer shows every session of the server.");
ABSL_FLAG(std::string, web_root, "",
          "view: the folder with the viewer's static/ and node_modules/three; empty: the "
          "client/web folder of the source tree it was built from.");
ABSL_FLAG(std::string, view_key_file, "",
          "view: a file holding a key (16 or more letters, digits or -._~) that every browser "
          "must bring: it opens http://HOST:PORT/?key=KEY once (printed at start) and keeps "
          "the key in a cookie; other clients send 'Authorization: Bearer KEY'. Over plain "
          "HTTP it keeps out who does not know the URL, not who can read the traffic (see "
          "--view_tls_cert_file). SIGHUP reads the file again (the old key's cookies stop "
          "working). Empty: anyone who reaches --listen is let in.");
ABSL_FLAG(std::string, view_tls_cert_file, "",
          "view: PEM file with the viewer's certificate (then any intermediates): browsers "
          "connect over HTTPS (https://HOST:PORT/), and the key's cookie is sent over HTTPS "
          "only. Needs --view_tls_key_file. SIGHUP reads it and the key again (a renewed "
          "certificate, for the connections that follow).");
ABSL_FLAG(std::string, view_tls_key_file, "",
          "view: PEM file with the private key of --view_tls_cert_file.");

// Reports.
ABSL_FLAG(bool, json, false, "Print JSON instead of text.");
ABSL_FLAG(std::string, reference, "", "eval: the reference surface, a mesh file or builtin:NAME.");
ABSL_FLAG(uint64_t, samples, 0,
          "eval: area-uniform samples per surface; 0: the default of "
          "core/analysis/geometric_error.h (200000).");

namespace {

using neuralmesh::client::ParsedArgs;
using neuralmesh::client::Subcommand;

absl::Status ExpectPositional(const ParsedArgs& args, size_t n, const std::string& names) {
  if (args.positional.size() == n) return absl::OkStatus();
  if (args.positional.size() < n) return absl::InvalidArgumentError("missing " + names);
  return absl::InvalidArgumentError(
      absl::StrCat("unexpected argument '", args.positional[n], "' (expected ", names, ")"));
}

absl::StatusOr<neuralmesh::LearnerOptions> LearnerFromFlags() {
  neuralmesh::LearnerOptions o;
  NM_ASSIGN_OR_RETURN(o.initial_mesh,
                      neuralmesh::ParseInitialMesh(absl::GetFlag(FLAGS_initial_mesh)));
  o.alpha_w = absl::GetFlag(FLAGS_alpha_w);
  o.alpha_l = absl::GetFlag(FLAGS_alpha_l);
  o.c_l = absl::GetFlag(FLAGS_c_l);
  o.c_vs = absl::GetFlag(FLAGS_c_vs);
  o.c_ec = absl::GetFlag(FLAGS_c_ec);
  o.early_phase_vertices = absl::GetFlag(FLAGS_early_phase_vertices);
  o.early_c_vs = absl::GetFlag(FLAGS_early_c_vs);
  o.early_c_ec = absl::GetFlag(FLAGS_early_c_ec);
  o.alpha_sc = absl::GetFlag(FLAGS_alpha_sc);
  o.remove_triangles = absl::GetFlag(FLAGS_remove_triangles);
  o.alpha_r = absl::GetFlag(FLAGS_alpha_r);
  o.merge_boundaries = absl::GetFlag(FLAGS_merge_boundaries);
  o.alpha_m = absl::GetFlag(FLAGS_alpha_m);
  o.splits_per_step = absl::GetFlag(FLAGS_splits_per_step);
  o.close_small_holes = absl::GetFlag(FLAGS_close_small_holes);
  o.max_closed_hole_vertices = absl::GetFlag(FLAGS_max_closed_hole_vertices);
  o.merge_only_settled_boundaries = absl::GetFlag(FLAGS_merge_only_settled_boundaries);
  o.split_largest_cell_near_most_active = absl::GetFlag(FLAGS_split_largest_cell_near_most_active);
  o.sewn_strip_grace_calls = absl::GetFlag(FLAGS_sewn_strip_grace_calls);
  o.min_merged_loop_vertices = absl::GetFlag(FLAGS_min_merged_loop_vertices);
  o.cut_inactive_faces = absl::GetFlag(FLAGS_cut_inactive_faces);
  o.seed = absl::GetFlag(FLAGS_seed);
  return o;
}

// Unset without --remove_outliers; checked here so that a bad value is named by its flag.
// Unset without --las_classes; refused when no input is a LAS file, where it would select
// nothing.
absl::StatusOr<neuralmesh::PointSelection> SelectionFromFlags(
    const std::vector<std::string>& inputs) {
  neuralmesh::PointSelection selection;
  const std::string classes = absl::GetFlag(FLAGS_las_classes);
  if (classes.empty()) return selection;
  absl::StatusOr<neuralmesh::LasClasses> parsed = neuralmesh::ParseLasClasses(classes);
  if (!parsed.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("--las_classes: ", parsed.status().message()));
  }
  // Standard input ('-') may be a LAS stream; it says so when it is text.
  if (std::none_of(inputs.begin(), inputs.end(), [](const std::string& input) {
        return input == "-" || neuralmesh::IsLasPath(input);
      })) {
    return absl::InvalidArgumentError(
        "--las_classes selects the points of LAS files by class; no INPUT is a .las or .laz "
        "file, nor standard input ('-')");
  }
  selection.las_classes = *parsed;
  return selection;
}

absl::StatusOr<std::optional<neuralmesh::OutlierOptions>> OutliersFromFlags() {
  if (!absl::GetFlag(FLAGS_remove_outliers)) return std::nullopt;
  neuralmesh::OutlierOptions o;
  o.neighbours = absl::GetFlag(FLAGS_outlier_neighbours);
  o.std_ratio = absl::GetFlag(FLAGS_outlier_std_ratio);
  if (o.neighbours < 1 || o.neighbours > 256) {
    return absl::InvalidArgumentError(
        absl::StrCat("--outlier_neighbours is ", o.neighbours, "; it must be in [1, 256]"));
  }
  if (!(o.std_ratio > 0) || !std::isfinite(o.std_ratio)) {
    return absl::InvalidArgumentError(
        absl::StrCat("--outlier_std_ratio is ", o.std_ratio, "; it must be finite and > 0"));
  }
  o.passes = absl::GetFlag(FLAGS_outlier_passes);
  if (o.passes < 1 || o.passes > 16) {
    return absl::InvalidArgumentError(
        absl::StrCat("--outlier_passes is ", o.passes, "; it must be in [1, 16]"));
  }
  return o;
}

// Unset with --nocolors; checked here so that a bad value is named by its flag.
absl::StatusOr<std::optional<neuralmesh::PointColorOptions>> ColorsFromFlags() {
  if (!absl::GetFlag(FLAGS_colors)) return std::nullopt;
  neuralmesh::PointColorOptions o;
  o.neighbours = absl::GetFlag(FLAGS_color_neighbours);
  if (!o.Validate().ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--color_neighbours is ", o.neighbours, "; it must be in [1, 64]"));
  }
  return o;
}

// Checked here so that a bad value is named by its flag, not by DracoOptions' field.
absl::StatusOr<neuralmesh::DracoOptions> DracoFromFlags() {
  neuralmesh::DracoOptions o;
  o.position_quantization_bits = absl::GetFlag(FLAGS_quantization_bits);
  o.encode_speed = absl::GetFlag(FLAGS_encode_speed);
  auto check = [](const char* flag, int value, int min, int max) {
    if (value >= min && value <= max) return absl::OkStatus();
    return absl::InvalidArgumentError(
        absl::StrCat("--", flag, " is ", value, "; it must be in [", min, ", ", max, "]"));
  };
  NM_RETURN_IF_ERROR(check("quantization_bits", o.position_quantization_bits, 1,
                           neuralmesh::kMaxQuantizationBits));
  NM_RETURN_IF_ERROR(check("encode_speed", o.encode_speed, 0, neuralmesh::kMaxDracoSpeed));
  return o;
}

// The formats meshes received are also written in: --ply, --glb.
std::vector<std::string> AlsoWriteFromFlags() {
  std::vector<std::string> also;
  if (absl::GetFlag(FLAGS_ply)) also.push_back(".ply");
  if (absl::GetFlag(FLAGS_glb)) also.push_back(".glb");
  return also;
}

// How meshes are written: the Draco flags, and --gltf_draco.
absl::StatusOr<neuralmesh::MeshWriteOptions> MeshWritingFromFlags() {
  neuralmesh::MeshWriteOptions o;
  NM_ASSIGN_OR_RETURN(o.draco, DracoFromFlags());
  o.gltf_draco = absl::GetFlag(FLAGS_gltf_draco);
  return o;
}

constexpr const char* kConnectionFlags[] = {"connect_timeout",   "tls",
                                            "tls_ca_file",       "tls_cert_file",
                                            "tls_key_file",      "tls_server_name",
                                            "access_token_file", "max_message_bytes"};

// How to reach the server: --connect_timeout, TLS and the access token.
absl::StatusOr<neuralmesh::client::ClientOptions> ConnectionFromFlags() {
  neuralmesh::client::ClientOptions o;
  o.connect_timeout = absl::GetFlag(FLAGS_connect_timeout);
  o.max_message_bytes = absl::GetFlag(FLAGS_max_message_bytes);
  if (o.max_message_bytes < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("--max_message_bytes must be at least 1, not ", o.max_message_bytes));
  }
  neuralmesh::client::ClientSecurity& security = o.security;
  struct FileFlag {
    const char* flag;
    std::string path;
    std::string* contents;
  };
  const FileFlag files[] = {
      {"tls_ca_file", absl::GetFlag(FLAGS_tls_ca_file), &security.tls.root_certificates},
      {"tls_cert_file", absl::GetFlag(FLAGS_tls_cert_file), &security.tls.certificate_chain},
      {"tls_key_file", absl::GetFlag(FLAGS_tls_key_file), &security.tls.private_key},
      {"access_token_file", absl::GetFlag(FLAGS_access_token_file), &security.access_token}};
  for (const FileFlag& file : files) {
    NM_ASSIGN_OR_RETURN(*file.contents, neuralmesh::ReadFileNamedByFlag(file.flag, file.path));
  }
  security.access_token = std::string(absl::StripAsciiWhitespace(security.access_token));
  security.tls.server_name = absl::GetFlag(FLAGS_tls_server_name);
  security.tls.enabled = absl::GetFlag(FLAGS_tls) || !security.tls.root_certificates.empty() ||
                         !security.tls.certificate_chain.empty() ||
                         !security.tls.server_name.empty();
  if (!security.access_token.empty() && !security.tls.enabled) {
    return absl::InvalidArgumentError(
        "--access_token_file needs TLS (--tls or --tls_ca_file): the token must not cross the "
        "network in the clear");
  }
  return o;
}

// `value` of the duration flag --`name` when finite and not negative.
absl::StatusOr<absl::Duration> FiniteDurationFlag(const char* name, absl::Duration value) {
  if (value < absl::ZeroDuration() || value == absl::InfiniteDuration()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--", name, " must be a finite duration >= 0 (e.g. 60s, 5m), not ",
                     absl::FormatDuration(value)));
  }
  return value;
}

absl::StatusOr<absl::Duration> ReconnectForFromFlags() {
  return FiniteDurationFlag("reconnect_for", absl::GetFlag(FLAGS_reconnect_for));
}

// The flags of a command that connects to a server, and `flags`.
std::vector<std::string> WithConnectionFlags(std::vector<std::string> flags) {
  for (const char* f : kConnectionFlags) flags.push_back(f);
  return flags;
}

// Flags that only one of the two kinds of reconstruct accepts.
absl::Status RejectFlags(const ParsedArgs& args, const std::vector<std::string>& flags,
                         const std::string& why) {
  for (const std::string& f : flags) {
    if (args.Has(f)) return absl::InvalidArgumentError(absl::StrCat("--", f, " ", why));
  }
  return absl::OkStatus();
}

absl::Status Reconstruct(const ParsedArgs& args) {
  if (args.positional.empty()) return absl::InvalidArgumentError("missing INPUT");
  NM_ASSIGN_OR_RETURN(const std::vector<size_t> lods,
                      neuralmesh::client::ParseLodList(absl::GetFlag(FLAGS_lod)));
  const bool progress = neuralmesh::client::ShowProgressOnStderr(absl::GetFlag(FLAGS_progress));
  if (args.Has("server")) {
    NM_RETURN_IF_ERROR(RejectFlags(
        args, {"output", "sampling", "time_budget", "max_steps", "gltf_draco"},
        "applies to a local reconstruct only (the server picks its own budget; use --out-dir)"));
    neuralmesh::client::RemoteReconstructOptions o;
    o.inputs = args.positional;
    o.server = absl::GetFlag(FLAGS_server);
    o.out_dir = absl::GetFlag(FLAGS_out_dir);
    o.vertices = absl::GetFlag(FLAGS_vertices);
    o.lods = lods;
    NM_ASSIGN_OR_RETURN(o.learner, LearnerFromFlags());
    NM_ASSIGN_OR_RETURN(o.outliers, OutliersFromFlags());
    NM_ASSIGN_OR_RETURN(o.selection, SelectionFromFlags(o.inputs));
    o.outliers_on_server = absl::GetFlag(FLAGS_outliers_on_server);
    o.off_core = absl::GetFlag(FLAGS_off_core);
    NM_ASSIGN_OR_RETURN(o.colors, ColorsFromFlags());
    if (o.outliers_on_server && !o.outliers.has_value()) {
      return absl::InvalidArgumentError("--outliers_on_server needs --remove_outliers");
    }
    if (o.outliers_on_server && o.outliers->passes > 1) {
      return absl::InvalidArgumentError(
          "--outlier_passes: the server's filter makes one pass (--outliers_on_server)");
    }
    NM_ASSIGN_OR_RETURN(o.draco, DracoFromFlags());
    o.batch_size = absl::GetFlag(FLAGS_batch_size);
    o.builtin_points = absl::GetFlag(FLAGS_points);
    o.also = AlsoWriteFromFlags();
    o.progress = progress;
    o.resume_session = absl::GetFlag(FLAGS_resume);
    o.start_mesh = absl::GetFlag(FLAGS_start_mesh);
    NM_ASSIGN_OR_RETURN(o.reconnect_for, ReconnectForFromFlags());
    NM_ASSIGN_OR_RETURN(o.connection, ConnectionFromFlags());
    return neuralmesh::client::RunRemoteReconstruct(o, std::cout, std::cerr);
  }
  NM_RETURN_IF_ERROR(
      RejectFlags(args,
                  WithConnectionFlags({"out-dir", "batch-size", "points", "ply", "glb",
                                       "outliers_on_server", "resume", "reconnect_for"}),
                  "needs --server (a local reconstruct writes -o OUTPUT)"));
  if (std::find(args.positional.begin(), args.positional.end(), "-") != args.positional.end()) {
    return absl::InvalidArgumentError(
        "INPUT '-' streams points from standard input to a server: it needs --server");
  }
  if (!args.Has("vertices")) return absl::InvalidArgumentError("--vertices N is required");
  neuralmesh::client::LocalReconstructOptions o;
  o.inputs = args.positional;
  o.output = absl::GetFlag(FLAGS_output);
  o.vertices = absl::GetFlag(FLAGS_vertices);
  o.lods = lods;
  NM_ASSIGN_OR_RETURN(o.learner, LearnerFromFlags());
  NM_ASSIGN_OR_RETURN(o.outliers, OutliersFromFlags());
  NM_ASSIGN_OR_RETURN(o.selection, SelectionFromFlags(o.inputs));
  NM_ASSIGN_OR_RETURN(o.sampling,
                      neuralmesh::client::ParseSamplingMode(absl::GetFlag(FLAGS_sampling)));
  o.start_mesh = absl::GetFlag(FLAGS_start_mesh);
  o.off_core = absl::GetFlag(FLAGS_off_core);
  NM_ASSIGN_OR_RETURN(o.colors, ColorsFromFlags());
  o.time_budget = absl::GetFlag(FLAGS_time_budget);
  o.max_steps = absl::GetFlag(FLAGS_max_steps);
  NM_ASSIGN_OR_RETURN(o.writing, MeshWritingFromFlags());
  o.progress = progress;
  return neuralmesh::client::RunLocalReconstruct(o, std::cout, std::cerr);
}

absl::Status Stats(const ParsedArgs& args) {
  NM_RETURN_IF_ERROR(ExpectPositional(args, 1, "MESH"));
  return neuralmesh::client::RunStats(args.positional[0], absl::GetFlag(FLAGS_json), std::cout);
}

absl::Status Convert(const ParsedArgs& args) {
  if (args.positional.empty()) return absl::InvalidArgumentError("missing INPUT");
  neuralmesh::client::ConvertOptions o;
  o.inputs = args.positional;
  o.output = absl::GetFlag(FLAGS_output);
  NM_ASSIGN_OR_RETURN(o.writing, MeshWritingFromFlags());
  NM_ASSIGN_OR_RETURN(o.outliers, OutliersFromFlags());
  NM_ASSIGN_OR_RETURN(o.selection, SelectionFromFlags(o.inputs));
  o.outliers_as_noise = absl::GetFlag(FLAGS_outliers_as_noise);
  const std::string pcd_data = absl::GetFlag(FLAGS_pcd_data);
  if (pcd_data == "binary_compressed") {
    o.pcd_data = neuralmesh::PcdData::kBinaryCompressed;
  } else if (pcd_data == "ascii") {
    o.pcd_data = neuralmesh::PcdData::kAscii;
  } else if (pcd_data != "binary") {
    return absl::InvalidArgumentError(absl::StrCat(
        "--pcd_data is '", pcd_data, "'; it must be binary, binary_compressed or ascii"));
  }
  if (args.Has("pcd_data") && !absl::EndsWithIgnoreCase(o.output, ".pcd")) {
    return absl::InvalidArgumentError("--pcd_data applies to a .pcd OUTPUT");
  }
  if (o.outliers_as_noise && !o.outliers.has_value()) {
    return absl::InvalidArgumentError("--outliers_as_noise needs --remove_outliers");
  }
  return neuralmesh::client::RunConvert(o, std::cout);
}

absl::Status Eval(const ParsedArgs& args) {
  NM_RETURN_IF_ERROR(ExpectPositional(args, 1, "MESH"));
  if (!args.Has("reference")) return absl::InvalidArgumentError("--reference REF is required");
  neuralmesh::client::EvalOptions o;
  o.mesh = args.positional[0];
  o.reference = absl::GetFlag(FLAGS_reference);
  o.samples = absl::GetFlag(FLAGS_samples);
  o.seed = absl::GetFlag(FLAGS_seed);
  o.json = absl::GetFlag(FLAGS_json);
  NM_ASSIGN_OR_RETURN(o.selection, SelectionFromFlags({o.reference}));
  return neuralmesh::client::RunEval(o, std::cout);
}

absl::Status Watch(const ParsedArgs& args) {
  NM_RETURN_IF_ERROR(ExpectPositional(args, 1, "SESSION"));
  neuralmesh::client::WatchOptions o;
  o.session_id = args.positional[0];
  o.server = absl::GetFlag(FLAGS_server);
  o.out_dir = absl::GetFlag(FLAGS_out_dir);
  o.also = AlsoWriteFromFlags();
  NM_ASSIGN_OR_RETURN(o.reconnect_for, ReconnectForFromFlags());
  NM_ASSIGN_OR_RETURN(o.connection, ConnectionFromFlags());
  return neuralmesh::client::RunWatch(o, std::cout, std::cerr);
}

absl::Status Sessions(const ParsedArgs& args) {
  NM_RETURN_IF_ERROR(ExpectPositional(args, 0, "no arguments"));
  neuralmesh::client::SessionsOptions o;
  o.server = absl::GetFlag(FLAGS_server);
  o.json = absl::GetFlag(FLAGS_json);
  NM_ASSIGN_OR_RETURN(o.connection, ConnectionFromFlags());
  NM_ASSIGN_OR_RETURN(o.reconnect_for, ReconnectForFromFlags());
  return neuralmesh::client::RunSessions(o, std::cout, std::cerr);
}

absl::Status OnSession(neuralmesh::client::SessionAction action, const ParsedArgs& args) {
  NM_RETURN_IF_ERROR(ExpectPositional(args, 1, "SESSION"));
  neuralmesh::client::SessionActionOptions o;
  o.session_id = args.positional[0];
  o.server = absl::GetFlag(FLAGS_server);
  o.new_owner = absl::GetFlag(FLAGS_to);
  NM_ASSIGN_OR_RETURN(o.connection, ConnectionFromFlags());
  return neuralmesh::client::RunSessionAction(action, o, std::cout);
}

// `neuralmesh NAME SESSION --server HOST:PORT`, which asks the server for `action`; `flags`
// beyond --server and the connection's.
Subcommand SessionActionCommand(const std::string& name, std::string summary,
                                std::string description, neuralmesh::client::SessionAction action,
                                const std::string& usage_flags = "",
                                std::vector<std::string> flags = {}) {
  flags.insert(flags.begin(), "server");
  return {name,
          absl::StrCat(name, " SESSION ", usage_flags, usage_flags.empty() ? "" : " ",
                       "--server HOST:PORT"),
          std::move(summary),
          std::move(description),
          WithConnectionFlags(std::move(flags)),
          [action](const ParsedArgs& args) { return OnSession(action, args); }};
}

absl::Status Get(const ParsedArgs& args) {
  NM_RETURN_IF_ERROR(ExpectPositional(args, 1, "SESSION"));
  neuralmesh::client::GetMeshOptions o;
  o.session_id = args.positional[0];
  o.server = absl::GetFlag(FLAGS_server);
  o.output = absl::GetFlag(FLAGS_output);
  o.final = absl::GetFlag(FLAGS_final);
  NM_ASSIGN_OR_RETURN(o.writing, MeshWritingFromFlags());
  NM_ASSIGN_OR_RETURN(o.wait, FiniteDurationFlag("wait", absl::GetFlag(FLAGS_wait)));
  NM_ASSIGN_OR_RETURN(o.connection, ConnectionFromFlags());
  return neuralmesh::client::RunGetMesh(o, std::cout);
}

absl::Status View(const ParsedArgs& args) {
  NM_RETURN_IF_ERROR(ExpectPositional(args, 0, "no arguments"));
  neuralmesh::client::web::ViewOptions o;
  o.server = absl::GetFlag(FLAGS_server);
  o.listen = absl::GetFlag(FLAGS_listen);
  o.web_root = absl::GetFlag(FLAGS_web_root);
  NM_ASSIGN_OR_RETURN(o.connection, ConnectionFromFlags());
  if (const std::string key_file = absl::GetFlag(FLAGS_view_key_file); !key_file.empty()) {
    const auto read_key = [key_file]() -> absl::StatusOr<std::string> {
      absl::StatusOr<std::string> contents =
          neuralmesh::ReadFileNamedByFlag("view_key_file", key_file);
      if (contents.ok()) contents = neuralmesh::client::web::ParseViewerKey(*contents);
      if (!contents.ok()) {
        return absl::Status(contents.status().code(),
                            absl::StrCat("--view_key_file: ", contents.status().message()));
      }
      return contents;
    };
    NM_ASSIGN_OR_RETURN(o.key, read_key());
    o.reread_key = read_key;
  }
  using TlsPem = neuralmesh::client::web::ViewOptions::TlsPem;
  const auto read_tls = []() -> absl::StatusOr<TlsPem> {
    TlsPem pem;
    NM_ASSIGN_OR_RETURN(pem.certificate_chain,
                        neuralmesh::ReadFileNamedByFlag("view_tls_cert_file",
                                                        absl::GetFlag(FLAGS_view_tls_cert_file)));
    NM_ASSIGN_OR_RETURN(pem.private_key,
                        neuralmesh::ReadFileNamedByFlag("view_tls_key_file",
                                                        absl::GetFlag(FLAGS_view_tls_key_file)));
    return pem;
  };
  NM_ASSIGN_OR_RETURN(TlsPem pem, read_tls());
  o.tls_certificate_chain = std::move(pem.certificate_chain);
  o.tls_private_key = std::move(pem.private_key);
  o.reread_tls = read_tls;
  return neuralmesh::client::web::RunView(o, std::cout, std::cerr);
}

std::vector<Subcommand> Commands() {
  // clang-format off
  const std::vector<std::string> reconstruct = {
      "output", "vertices", "lod", "seed", "alpha_w", "alpha_l", "c_l", "c_vs", "c_ec",
      "early_phase_vertices", "early_c_vs", "early_c_ec", "alpha_sc", "alpha_r", "alpha_m",
      "remove_triangles", "merge_boundaries", "splits_per_step", "close_small_holes",
      "max_closed_hole_vertices", "merge_only_settled_boundaries",
      "split_largest_cell_near_most_active", "sewn_strip_grace_calls", "min_merged_loop_vertices",
      "cut_inactive_faces", "initial_mesh", "start_mesh", "off_core", "las_classes",
      "remove_outliers", "outlier_neighbours", "outlier_std_ratio", "outlier_passes", "outliers_on_server", "colors", "color_neighbours", "sampling",
      "time_budget", "max_steps", "quantization_bits", "encode_speed", "gltf_draco", "progress",
      "server", "out-dir", "batch-size", "points", "ply", "glb", "resume", "reconnect_for"};
  // clang-format on
  return {
      {"reconstruct",
       "reconstruct INPUT... -o OUTPUT --vertices N [flags]\n"
       "       neuralmesh reconstruct INPUT... --server HOST:PORT --out-dir DIR [--vertices N] "
       "[--batch-size K] [--ply] [--glb] [--resume SESSION] [--reconnect_for D]",
       "Learns a mesh of a point cloud, a mesh or a built-in surface, locally or on a server.",
       "Learns a mesh of INPUT: a point cloud (.ply .xyz .txt .pts .ptx .las .laz .pcd .e57\n"
       ".obj .off .drc .glb .gltf), a triangle mesh with --sampling area|curvature, or\n"
       "builtin:sphere|torus|genus2. Several point cloud files (the scans of one site, a file\n"
       "per station or tile) are learned as one, each where its coordinates put it.\n"
       "Locally it writes OUTPUT and one OUTPUT_lod<N> file per --lod; with --server it\n"
       "uploads the points and saves each mesh the server publishes into --out-dir. Prints\n"
       "the figures of every level. With --server, INPUT '-' streams points from standard\n"
       "input as they arrive (\"x y z\" per line, split as in XYZ files, '#' and '//'\n"
       "comments skipped, further columns ignored unless a header comment names them,\n"
       "\"# x y z r g b\"; or a LAS or LAZ file's records, with their colours, of the\n"
       "--las_classes chosen: LAZ a chunk at a time), a batch whenever --batch-size points\n"
       "came or 100 ms passed; the session finishes at the end of the stream (files named\n"
       "stdin*).",
       WithConnectionFlags(reconstruct), Reconstruct},
      {"stats",
       "stats MESH|POINTS [--json]",
       "Prints the mesh report of a mesh, or what a point cloud file holds.",
       "Prints the mesh report of MESH (a mesh file or builtin:NAME): counts, valences, genus,\n"
       "boundaries, manifoldness. For POINTS, a point cloud file (.xyz .txt .pts .ptx .las\n"
       ".laz .pcd .e57, or a mesh format without faces): the points read and left out, where\n"
       "they lie and what they carry; for LAS and LAZ also the version, point format,\n"
       "records, scale, offset, coordinate system, GPS time, classes and, for LAZ, the\n"
       "compression.",
       {"json"},
       Stats},
      {"convert",
       "convert INPUT... -o OUTPUT [--gltf_draco] [--remove_outliers [--outliers_as_noise]]\n"
       "        [--las_classes C] [--pcd_data D] [--quantization_bits B] [--encode_speed S]",
       "Writes a mesh or a point cloud in another format.",
       "Writes INPUT to OUTPUT in the format of its extension, colours included where the\n"
       "format holds them. A mesh (a file with faces, or builtin:NAME, its dense reference\n"
       "tessellation) goes to .ply .obj .off .stl .drc .glb .gltf; points (.xyz .txt .pts\n"
       ".ptx .las .laz .pcd .e57, a file without faces, or anything written to .xyz .txt\n"
       ".pts .ptx .las .laz .pcd .e57) go to .ply .xyz .txt .pts .ptx .las .laz .pcd .e57\n"
       ".drc .glb .gltf with their normals and weights (LAS, PTX: positions and colours\n"
       "only; E57: no weights), after --remove_outliers if given. Several point cloud files\n"
       "are written as one. One LAS file (.las, or .laz compressed by LASzip) written to .las\n"
       "or .laz with nothing to remove or select is copied whole, every record and the\n"
       "header. LAS files written to LAS otherwise keep their records whole (classes,\n"
       "intensities, times, extra bytes) and the offset and variable-length records (the\n"
       "coordinate system) of the first file of the highest LAS version; tiles are joined so\n"
       "when they share the coordinate system and extra bytes and hold no waveforms, those\n"
       "of other point formats in the format that holds every field of theirs.\n"
       "--outliers_as_noise classifies the outliers as noise instead of removing them.",
       {"output", "gltf_draco", "pcd_data", "las_classes", "remove_outliers", "outlier_neighbours",
        "outlier_std_ratio", "outlier_passes", "outliers_as_noise", "quantization_bits",
        "encode_speed"},
       Convert},
      {"eval",
       "eval MESH --reference REF [--json] [--samples N]",
       "Prints the geometric error of a mesh against a reference surface.",
       "Prints the geometric error (Chamfer, Hausdorff, normal consistency) of MESH against\n"
       "REF, a mesh file or builtin:NAME (its dense reference tessellation), or against the\n"
       "points of a scan (a point cloud file, or one without faces): each point's distance to\n"
       "MESH, and MESH's distance to the nearest point.",
       {"reference", "json", "samples", "seed", "las_classes"},
       Eval},
      {"watch",
       "watch SESSION --server HOST:PORT --out-dir DIR [--ply] [--glb] [--reconnect_for D]",
       "Watches a server session until it ends, saving every milestone and the final mesh.", "",
       WithConnectionFlags({"server", "out-dir", "ply", "glb", "reconnect_for"}), Watch},
      {"sessions", "sessions --server HOST:PORT [--json] [--reconnect_for D]",
       "Lists the sessions of a server.",
       "Lists the sessions of a server; a server restoring its sessions after a restart is\n"
       "asked again until it is done (at most --reconnect_for).",
       WithConnectionFlags({"server", "json", "reconnect_for"}), Sessions},
      {"get", "get SESSION --server HOST:PORT -o OUTPUT [--final] [--wait D]",
       "Saves a session's latest or final mesh.",
       "Saves the latest mesh of a server session (with --final its final mesh) to OUTPUT:\n"
       ".drc keeps the server's Draco bytes as they are; .ply .obj .off .stl .glb .gltf are\n"
       "decoded (and re-encoded with --gltf_draco).\n"
       "Prints its figures.",
       WithConnectionFlags({"server", "output", "final", "wait", "quantization_bits",
                            "encode_speed", "gltf_draco"}),
       Get},
      SessionActionCommand(
          "finish", "Tells a server session that all its points have arrived.",
          "The session learns on to its target vertex count and publishes the final mesh\n"
          "(`watch` or `get --final --wait D` fetch it).",
          neuralmesh::client::SessionAction::kFinish),
      SessionActionCommand("cancel", "Stops a server session's learning; its latest mesh stays.",
                           "", neuralmesh::client::SessionAction::kCancel),
      SessionActionCommand("delete", "Removes a server session, its meshes and its files.", "",
                           neuralmesh::client::SessionAction::kDelete),
      SessionActionCommand(
          "transfer", "Hands a server session to another client.",
          "The client named by --to owns the session from now on: its user token (or client\n"
          "certificate) may use it as its creator could, and the previous owner's no longer\n"
          "can. An admin may hand over any session, a user only its own.",
          neuralmesh::client::SessionAction::kTransfer, "--to CLIENT", {"to"}),
      {"view",
       "view --server HOST:PORT [--listen HOST:PORT] [--view_key_file FILE]\n"
       "     [--view_tls_cert_file FILE --view_tls_key_file FILE]",
       "Serves a live 3D viewer of the server's sessions to web browsers.",
       "Serves a web page (http://HOST:PORT/ of --listen) that lists the sessions of the\n"
       "server and shows the chosen one's mesh as it learns: each published mesh is fetched\n"
       "Draco-encoded, decoded in the browser and drawn with three.js, coarse to fine, until\n"
       "the final mesh. It opens on the newest session still learning;\n"
       "http://HOST:PORT/?session=ID goes straight to a session. With --view_tls_cert_file\n"
       "and --view_tls_key_file it serves https:// instead (SIGHUP reads them again). Runs\n"
       "until Ctrl-C.",
       WithConnectionFlags({"server", "listen", "web_root", "view_key_file", "view_tls_cert_file",
                            "view_tls_key_file"}),
       View},
  };
}

}  // namespace

int main(int argc, char** argv) {
  const std::string version =
      neuralmesh::VersionLine("neuralmesh", absl::StrCat("gRPC ", grpc::Version()));
  return neuralmesh::client::RunCommandLine(argc, argv, Commands(), version, std::cout, std::cerr);
}
