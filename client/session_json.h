// A session as the client shows it: the short names of its state and update kinds, and its
// JSON form, shared by `neuralmesh sessions` and the live viewer.
#ifndef NEURALMESH_CLIENT_SESSION_JSON_H_
#define NEURALMESH_CLIENT_SESSION_JSON_H_

#include <string>

#include "core/analysis/json_writer.h"
#include "neuralmesh/v1/reconstruction.pb.h"

namespace neuralmesh::client {

// "learning", "finished", ...: the enum name without SESSION_STATE_, lower-cased.
std::string SessionStateName(neuralmesh::v1::SessionState state);

// "milestone", "refresh", "final": the enum name without UPDATE_KIND_, lower-cased.
std::string UpdateKindName(neuralmesh::v1::UpdateKind kind);

// Writes `session` as one JSON object: id, name, state, point and outlier counts, mesh size,
// target, Basic Steps, latest update sequence, watchers and error.
void WriteSessionJson(const neuralmesh::v1::Session& session, JsonWriter& json);

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_SESSION_JSON_H_
