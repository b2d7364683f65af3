#include "client/web/viewer_service.h"

#include <algorithm>
#include <filesystem>
#include <iterator>
#include <system_error>
#include <utility>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "absl/time/clock.h"
#include "client/session_json.h"
#include "core/analysis/json_writer.h"
#include "client/web/viewer_key.h"
#include "core/io/draco_codec.h"
#include "core/io/file_contents.h"
#include "core/io/mesh_io.h"

namespace neuralmesh::client::web {

using ::neuralmesh::http::HttpRequest;
using ::neuralmesh::http::HttpResponse;
using ::neuralmesh::http::JsonResponse;

namespace {

// At most this many sessions are watched at once for browsers.
constexpr size_t kMaxRelays = 256;

// The files CheckWebRoot requires: the page, its script, and three.js with its Draco decoder.
const char* const kRequiredFiles[] = {
    "static/index.html",
    "static/viewer.js",
    "node_modules/three/build/three.module.js",
    "node_modules/three/examples/jsm/loaders/DRACOLoader.js",
    "node_modules/three/examples/jsm/libs/draco/draco_decoder.wasm",
};

HttpResponse ErrorResponse(int status, absl::string_view message) {
  JsonWriter json;
  json.BeginObject().Key("error").String(message).EndObject();
  return JsonResponse(status, json.text());
}

// The HTTP status that tells a browser what a failed call to the server means.
int HttpStatusOf(const absl::Status& status) {
  switch (status.code()) {
    case absl::StatusCode::kNotFound:
      return 404;
    case absl::StatusCode::kInvalidArgument:
      return 400;
    case absl::StatusCode::kFailedPrecondition:  // E.g. a session without a mesh yet.
      return 409;
    case absl::StatusCode::kCancelled:
    case absl::StatusCode::kAborted:
      return 410;
    case absl::StatusCode::kDeadlineExceeded:
      return 504;
    case absl::StatusCode::kResourceExhausted:
      return 503;
    default:
      return 502;
  }
}

std::string ContentTypeOf(absl::string_view file) {
  if (absl::EndsWith(file, ".html")) return "text/html; charset=utf-8";
  if (absl::EndsWith(file, ".js")) return "text/javascript; charset=utf-8";
  if (absl::EndsWith(file, ".css")) return "text/css; charset=utf-8";
  if (absl::EndsWith(file, ".wasm")) return "application/wasm";
  if (absl::EndsWith(file, ".json")) return "application/json";
  return "application/octet-stream";
}

// Letters, digits, '.', '_' and '-': the characters of the file names served and saved.
bool IsFileNameCharacter(char c) {
  return absl::ascii_isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-';
}

// Whether `path` is a relative path of plain names: IsFileNameCharacter's, no name starting
// with a dot (so no "..", no hidden files), no empty names.
bool IsPlainRelativePath(absl::string_view path) {
  if (path.empty()) return false;
  for (absl::string_view name : absl::StrSplit(path, '/')) {
    if (name.empty() || name[0] == '.') return false;
    if (!std::all_of(name.begin(), name.end(), IsFileNameCharacter)) return false;
  }
  return true;
}

// The formats a download may take, by the extension it is saved with, and their media types.
constexpr std::pair<const char*, const char*> kDownloadFormats[] = {
    {"glb", "model/gltf-binary"}, {"gltf", "model/gltf+json"},
    {"ply", "application/octet-stream"}, {"obj", "text/plain; charset=utf-8"},
    {"off", "text/plain; charset=utf-8"}, {"stl", "model/stl"},
    {"drc", "application/x-draco"}};

// `name` with every character but IsFileNameCharacter's replaced by '_', for a file name.
std::string FileNameOf(absl::string_view name) {
  std::string out(name);
  for (char& c : out) {
    if (!IsFileNameCharacter(c)) c = '_';
  }
  return out;
}

HttpResponse MeshResponse(const v1::MeshUpdate& update) {
  HttpResponse response;
  response.content_type = "application/x-draco";
  response.body = update.draco_mesh();
  auto add = [&response](absl::string_view name, const auto& value) {
    response.headers.emplace_back(absl::StrCat("X-Neuralmesh-", name), absl::StrCat(value));
  };
  add("Sequence", update.sequence());
  add("Kind", UpdateKindName(update.kind()));
  add("Vertices", update.vertex_count());
  add("Faces", update.face_count());
  add("Lod-Milestone", update.lod_milestone());
  add("State", SessionStateName(update.state()));
  add("Points-Received", update.learning().points_received());
  add("Basic-Steps", update.learning().basic_steps());
  add("Genus", update.report().genus());
  add("Boundaries", update.report().boundary_loops());
  add("Snapshot-Time-Us", update.snapshot_time_us());
  return response;
}

}  // namespace

absl::Status CheckWebRoot(const std::string& web_root) {
  for (const char* file : kRequiredFiles) {
    const std::filesystem::path path = std::filesystem::path(web_root) / file;
    std::error_code error;
    if (!std::filesystem::is_regular_file(path, error)) {
      return absl::NotFoundError(absl::StrCat(
          "the viewer's file ", path.string(),
          " is missing: run scripts/install-deps.sh (it "
          "installs three.js with `npm ci` in client/web), or point --web_root at a folder "
          "that has static/ and node_modules/three"));
    }
  }
  return absl::OkStatus();
}

ViewerService::ViewerService(std::unique_ptr<ReconstructionClient> client, ViewerOptions options)
    : client_(std::move(client)), options_(std::move(options)), key_(options_.key) {}

void ViewerService::ReplaceKey(std::string key) {
  absl::MutexLock lock(&mu_);
  key_ = std::move(key);
}

ViewerService::~ViewerService() { Stop(); }

void ViewerService::Stop() {
  std::map<std::string, std::shared_ptr<MeshRelay>> relays;
  {
    absl::MutexLock lock(&mu_);
    stopped_ = true;
    relays.swap(relays_);
  }
  for (auto& [id, relay] : relays) relay->Stop();
}

HttpResponse ViewerService::Handle(const HttpRequest& request) {
  std::string key;
  {
    absl::MutexLock lock(&mu_);
    key = key_;
  }
  if (!key.empty()) {
    switch (CheckViewerKey(request, key)) {
      case ViewerKeyCheck::kGranted:
        break;
      case ViewerKeyCheck::kGrantedFromUrl:
        return ViewerKeyRedirect(request, key, options_.https);
      case ViewerKeyCheck::kRefused:
        return ErrorResponse(401,
                             "this viewer needs its key: open the URL with ?key= that "
                             "neuralmesh view printed");
    }
  }
  absl::string_view path = request.path;
  if (path == "/" || path == "/index.html") return ServeFile("static/index.html");
  if (absl::ConsumePrefix(&path, "/static/")) {
    if (!IsPlainRelativePath(path) || absl::StrContains(path, '/')) {
      return ErrorResponse(404, absl::StrCat("no such file: ", request.path));
    }
    return ServeFile(absl::StrCat("static/", path));
  }
  if (absl::ConsumePrefix(&path, "/vendor/three/")) {
    if (!IsPlainRelativePath(path) ||
        !(absl::StartsWith(path, "build/") || absl::StartsWith(path, "examples/jsm/"))) {
      return ErrorResponse(404, absl::StrCat("no such file: ", request.path));
    }
    return ServeFile(absl::StrCat("node_modules/three/", path));
  }
  if (path == "/api/sessions") return ListSessions();
  if (absl::ConsumePrefix(&path, "/api/sessions/")) {
    const std::vector<absl::string_view> parts = absl::StrSplit(path, '/');
    if (parts.size() == 1 && !parts[0].empty()) return GetSession(std::string(parts[0]));
    if (parts.size() == 2 && !parts[0].empty() && parts[1] == "mesh") {
      return GetMesh(std::string(parts[0]), request);
    }
    if (parts.size() == 2 && !parts[0].empty() && parts[1] == "download") {
      return Download(std::string(parts[0]), request);
    }
  }
  return ErrorResponse(404, absl::StrCat("no such page: ", request.path));
}

HttpResponse ViewerService::ServerErrorResponse(const absl::Status& status) const {
  const bool server_answered =
      absl::IsUnavailable(status) &&
      client_->channel()->GetState(/*try_to_connect=*/false) == GRPC_CHANNEL_READY;
  if (!server_answered) return ErrorResponse(HttpStatusOf(status), status.message());
  HttpResponse response = ErrorResponse(503, status.message());
  response.headers.emplace_back("Retry-After", "1");
  return response;
}

HttpResponse ViewerService::ServeFile(const std::string& file) const {
  absl::StatusOr<std::string> contents =
      ReadFileContents((std::filesystem::path(options_.web_root) / file).string());
  if (!contents.ok()) return ErrorResponse(404, absl::StrCat("no such file: ", file));
  HttpResponse response;
  response.content_type = ContentTypeOf(file);
  response.body = *std::move(contents);
  return response;
}

HttpResponse ViewerService::ListSessions() {
  absl::StatusOr<std::vector<v1::Session>> sessions = client_->ListSessions();
  if (!sessions.ok()) {
    return ServerErrorResponse(sessions.status());
  }
  JsonWriter json;
  json.BeginArray();
  for (const v1::Session& session : *sessions) WriteSessionJson(session, json);
  json.EndArray();
  return JsonResponse(200, json.text());
}

HttpResponse ViewerService::GetSession(const std::string& session_id) {
  absl::StatusOr<v1::Session> session = client_->GetSession(session_id);
  if (!session.ok()) {
    return ServerErrorResponse(session.status());
  }
  JsonWriter json;
  WriteSessionJson(*session, json);
  return JsonResponse(200, json.text());
}

void ViewerService::DropIdleRelays() {
  std::vector<std::shared_ptr<MeshRelay>> idle;
  {
    absl::MutexLock lock(&mu_);
    const absl::Time now = absl::Now();
    for (auto it = relays_.begin(); it != relays_.end();) {
      if (now - it->second->last_used() > options_.relay_idle_timeout) {
        idle.push_back(std::move(it->second));
        it = relays_.erase(it);
      } else {
        ++it;
      }
    }
  }
  for (auto& relay : idle) relay->Stop();
}

std::shared_ptr<MeshRelay> ViewerService::RelayFor(const std::string& session_id) {
  std::shared_ptr<MeshRelay> lost;
  std::shared_ptr<MeshRelay> relay;
  {
    absl::MutexLock lock(&mu_);
    if (stopped_) return nullptr;
    auto found = relays_.find(session_id);
    if (found != relays_.end()) {
      // A watch cut off by a lost connection is tried again; other ends are the session's.
      const MeshRelay::State state = found->second->Peek();
      if (!(state.ended && absl::IsUnavailable(state.end_status))) relay = found->second;
      if (relay == nullptr) {
        lost = std::move(found->second);
        relays_.erase(found);
      }
    }
    if (relay == nullptr && relays_.size() < kMaxRelays) {
      try {
        relay = std::make_shared<MeshRelay>(client_->channel(), client_->options(), session_id);
        relays_[session_id] = relay;
      } catch (const std::system_error&) {
        // No thread for the watch: the request gets 503, as when the viewer is full.
      }
    }
  }
  if (lost != nullptr) lost->Stop();
  return relay;
}

HttpResponse ViewerService::GetMesh(const std::string& session_id, const HttpRequest& request) {
  uint64_t after = 0;
  if (auto it = request.query.find("after");
      it != request.query.end() && !absl::SimpleAtoi(it->second, &after)) {
    return ErrorResponse(
        400, absl::StrCat("after=", it->second, " is not a sequence number (a whole number >= 0)"));
  }
  bool watched = false;
  {
    absl::MutexLock lock(&mu_);
    if (stopped_) return ErrorResponse(503, "the viewer is shutting down");
    watched = relays_.count(session_id) != 0;
  }
  if (!watched) {
    // Only sessions that exist get a watch: an unknown id costs one call, not a stream.
    absl::StatusOr<v1::Session> session = client_->GetSession(session_id);
    if (!session.ok()) {
      return ServerErrorResponse(session.status());
    }
  }
  std::shared_ptr<MeshRelay> relay = RelayFor(session_id);
  if (relay == nullptr) {
    return ErrorResponse(503, absl::StrCat("the viewer watches at most ", kMaxRelays,
                                           " sessions at once, is out of threads, or is "
                                           "shutting down"));
  }
  const MeshRelay::State state = relay->WaitForNewer(after, options_.poll_timeout);
  if (state.latest != nullptr && state.latest->sequence() > after) {
    return MeshResponse(*state.latest);
  }
  {
    absl::MutexLock lock(&mu_);
    if (stopped_) return ErrorResponse(503, "the viewer is shutting down");
  }
  if (!state.ended) {
    HttpResponse response;
    response.status = 204;
    return response;
  }
  if (state.end_status.ok()) {
    return ErrorResponse(
        410, absl::StrCat("session ", session_id, " has ended: its last mesh was sequence ",
                          state.latest == nullptr ? 0 : state.latest->sequence()));
  }
  return ServerErrorResponse(state.end_status);
}

HttpResponse ViewerService::Download(const std::string& session_id, const HttpRequest& request) {
  std::string format = "glb";
  if (auto it = request.query.find("format"); it != request.query.end()) format = it->second;
  const auto* known = std::find_if(std::begin(kDownloadFormats), std::end(kDownloadFormats),
                                   [&format](const auto& f) { return format == f.first; });
  if (known == std::end(kDownloadFormats)) {
    const auto extension = [](std::string* out, const auto& f) { out->append(f.first); };
    return ErrorResponse(400, absl::StrCat("format=", format, " is not one of ",
                                           absl::StrJoin(kDownloadFormats, ", ", extension)));
  }
  absl::StatusOr<v1::Session> session = client_->GetSession(session_id);
  if (!session.ok()) return ServerErrorResponse(session.status());
  absl::StatusOr<v1::MeshUpdate> update = client_->GetMesh(
      session_id, v1::MESH_VERSION_LATEST, /*wait=*/false, client_->options().call_timeout);
  if (!update.ok()) return ServerErrorResponse(update.status());
  HttpResponse response;
  response.content_type = known->second;
  const std::string file = absl::StrCat(
      FileNameOf(session->name().empty() ? session_id : session->name()), "-", update->sequence(),
      ".", format);
  response.headers.emplace_back("Content-Disposition",
                                absl::StrCat("attachment; filename=\"", file, "\""));
  if (format == "drc") {
    response.body = update->draco_mesh();
    return response;
  }
  absl::StatusOr<TriangleMesh> mesh = DecodeMesh(update->draco_mesh());
  if (!mesh.ok()) {
    return ErrorResponse(502, absl::StrCat("mesh ", update->sequence(), " of session ",
                                           session_id, " does not decode: ",
                                           mesh.status().message()));
  }
  absl::StatusOr<std::string> bytes = FormatMesh(*mesh, file);
  if (!bytes.ok()) return ErrorResponse(500, bytes.status().message());
  response.body = *std::move(bytes);
  return response;
}

}  // namespace neuralmesh::client::web
