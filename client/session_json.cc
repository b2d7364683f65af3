#include "client/session_json.h"

#include "absl/strings/ascii.h"
#include "absl/strings/string_view.h"
#include "absl/strings/strip.h"

namespace neuralmesh::client {

namespace {

std::string ShortEnumName(absl::string_view name, absl::string_view prefix) {
  absl::ConsumePrefix(&name, prefix);
  return absl::AsciiStrToLower(name);
}

}  // namespace

std::string SessionStateName(neuralmesh::v1::SessionState state) {
  return ShortEnumName(neuralmesh::v1::SessionState_Name(state), "SESSION_STATE_");
}

std::string UpdateKindName(neuralmesh::v1::UpdateKind kind) {
  return ShortEnumName(neuralmesh::v1::UpdateKind_Name(kind), "UPDATE_KIND_");
}

void WriteSessionJson(const neuralmesh::v1::Session& s, JsonWriter& json) {
  json.BeginObject();
  json.Key("session_id").String(s.session_id());
  json.Key("name").String(s.name());
  json.Key("owner").String(s.owner());
  json.Key("state").String(SessionStateName(s.state()));
  json.Key("points_received").Uint(s.learning().points_received());
  json.Key("points_taken").Uint(s.points_taken());
  json.Key("points_removed_as_outliers").Uint(s.learning().points_removed_as_outliers());
  json.Key("outliers_held").Uint(s.learning().outliers_held());
  json.Key("outliers_accepted_later").Uint(s.learning().outliers_accepted_later());
  json.Key("vertices").Uint(s.vertex_count());
  json.Key("faces").Uint(s.face_count());
  json.Key("target_vertices").Uint(s.config().target_vertices());
  // Where the session's coordinates' zero lies in the data's (SessionConfig.origin).
  json.Key("origin").BeginArray();
  json.Double(s.config().origin().x()).Double(s.config().origin().y());
  json.Double(s.config().origin().z()).EndArray();
  json.Key("basic_steps").Uint(s.learning().basic_steps());
  // Learning waits for more points to grow the mesh (LearningState.stalled).
  json.Key("stalled").Bool(s.learning().stalled());
  json.Key("latest_sequence").Uint(s.latest_sequence());
  json.Key("watchers").Uint(s.watchers());
  json.Key("error").String(s.error());
  json.EndObject();
}

}  // namespace neuralmesh::client
