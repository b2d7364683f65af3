// What `neuralmesh view` serves over HTTP: the viewer's page and scripts, and a small API over
// one neuralmesh-server's sessions that a browser can read:
//
//   GET /                              the viewer (static/index.html)
//   GET /static/NAME                   its scripts and styles (client/web/static/)
//   GET /vendor/three/PATH             three.js and its Draco decoder (client/web/node_modules)
//   GET /api/sessions                  JSON array of every session (ListSessions)
//   GET /api/sessions/ID               JSON of one session (GetSession)
//   GET /api/sessions/ID/mesh?after=N  the first published mesh with a sequence above N
//                                      (default 0), as Draco bytes, waiting for it up to the
//                                      poll timeout (a long poll)
//   GET /api/sessions/ID/download?format=F
//                                      the session's latest mesh as a file to save: F is glb
//                                      (the default), gltf, ply, obj, off, stl or drc (the
//                                      server's Draco bytes as they are; the others decoded,
//                                      with their colours)
//
// The mesh answer is 200 with the Draco-encoded mesh as the body (application/x-draco, exactly
// the bytes of MeshUpdate.draco_mesh) and its figures in X-Neuralmesh-* headers (Sequence,
// Kind, Vertices, Faces, Lod-Milestone, State, Points-Received, Basic-Steps, Genus,
// Boundaries, Snapshot-Time-Us: when the server took the mesh, microseconds since the epoch); 204
// when no newer mesh came within the poll timeout (poll again); 410 when the session's stream is
// over and the mesh with sequence N was its last (final, or the session was cancelled or failed;
// the body says which); 404 for an unknown session; 400 for a malformed `after`; 502 when the
// server cannot be reached. Errors have a JSON body
// {"error": "..."}.
//
// A download is 200 with Content-Disposition: attachment; filename="NAME-SEQUENCE.F" (the
// session's name, or its id when it has none); 400 for an unknown format; 404 for an unknown
// session; 409 for one that has published no mesh yet; 502 as above.
#ifndef NEURALMESH_CLIENT_WEB_VIEWER_SERVICE_H_
#define NEURALMESH_CLIENT_WEB_VIEWER_SERVICE_H_

#include <map>
#include <memory>
#include <string>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "client/reconstruction_client.h"
#include "client/web/mesh_relay.h"
#include "http/http_message.h"

namespace neuralmesh::client::web {

struct ViewerOptions {
  // The folder holding static/ and node_modules/three (client/web in the source tree).
  std::string web_root;
  // How long a mesh request waits for a newer mesh before answering 204.
  absl::Duration poll_timeout = absl::Seconds(20);
  // A session's watch is dropped when no browser has asked for its meshes for this long.
  absl::Duration relay_idle_timeout = absl::Seconds(60);
  // Empty: every request is answered. Else every request must bring this key (viewer_key.h):
  // one with the key in its query is sent on without it, keeping the key in a cookie, and one
  // without the key gets 401. ReplaceKey changes it.
  std::string key;
  // Whether browsers reach the viewer over HTTPS: the key's cookie is then Secure.
  bool https = false;
};

// OK when `web_root` holds the viewer's page and three.js; otherwise NOT_FOUND naming the
// missing file and how to install it.
absl::Status CheckWebRoot(const std::string& web_root);

class ViewerService {
 public:
  // Serves the sessions of the server that `client` is connected to.
  ViewerService(std::unique_ptr<ReconstructionClient> client, ViewerOptions options);
  // Stop().
  ~ViewerService();

  // Answers one request; thread-safe, and mesh requests block up to the poll timeout.
  http::HttpResponse Handle(const http::HttpRequest& request);

  // Ends the watches no browser has asked about for relay_idle_timeout (each holds a stream on
  // the server). The owner calls it now and then (RunView: every 5 s).
  void DropIdleRelays();

  // Ends every watch and wakes every waiting mesh request; later requests for meshes get 503.
  void Stop();

  // The key that requests from now on must bring (a key file read again on SIGHUP); cookies
  // of the old key no longer let a browser in. Empty lets every request in.
  void ReplaceKey(std::string key);

 private:
  // The answer to a browser whose request failed at the server with `status`, as an HTTP status
  // that says what it means: UNAVAILABLE from a server that answered it (the channel is
  // connected: the server is restoring its sessions after a restart, or shutting down) is 503
  // with Retry-After; UNAVAILABLE from a server out of reach is 502 (Bad Gateway).
  http::HttpResponse ServerErrorResponse(const absl::Status& status) const;
  http::HttpResponse ServeFile(const std::string& file) const;
  http::HttpResponse ListSessions();
  http::HttpResponse GetSession(const std::string& session_id);
  http::HttpResponse GetMesh(const std::string& session_id, const http::HttpRequest& request);
  http::HttpResponse Download(const std::string& session_id, const http::HttpRequest& request);
  // The relay of `session_id`, made when missing or when its watch lost the connection.
  std::shared_ptr<MeshRelay> RelayFor(const std::string& session_id);

  const std::unique_ptr<ReconstructionClient> client_;
  const ViewerOptions options_;

  absl::Mutex mu_;
  std::string key_ ABSL_GUARDED_BY(mu_);  // ViewerOptions::key, then each ReplaceKey.
  std::map<std::string, std::shared_ptr<MeshRelay>> relays_ ABSL_GUARDED_BY(mu_);
  bool stopped_ ABSL_GUARDED_BY(mu_) = false;
};

}  // namespace neuralmesh::client::web

#endif  // NEURALMESH_CLIENT_WEB_VIEWER_SERVICE_H_
