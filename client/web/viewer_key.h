// The key that `neuralmesh view --view_key_file FILE` asks of browsers, so that a viewer bound
// to an address others can reach shows the sessions only to those given its URL. The browser
// opens the URL with the key once (http://HOST:PORT/?key=KEY); the viewer answers with a
// cookie that carries the key and sends the browser on to the same page without it, and every
// later request (the page, its scripts, the API) brings the cookie. Other clients of the API
// may send "Authorization: Bearer KEY" instead. Over plain HTTP the key crosses the network in
// the clear, so it keeps out those who do not know the URL, not those who can read the
// traffic; over HTTPS (--view_tls_cert_file) it keeps out both.
#ifndef NEURALMESH_CLIENT_WEB_VIEWER_KEY_H_
#define NEURALMESH_CLIENT_WEB_VIEWER_KEY_H_

#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "http/http_message.h"

namespace neuralmesh::client::web {

// The name of the cookie that carries `key`: "neuralmesh_view_key_" and 16 hex digits of a
// hash of the key. Browsers keep cookies by host, not by port, so viewers with other keys on
// the same host (other ports, or the same port behind other mappings) each keep their own.
std::string ViewerKeyCookieName(absl::string_view key);

// The key in `contents` (a key file): its text without surrounding whitespace, at least 16
// characters, each a letter, a digit or one of "-._~" (so that it stands in a URL as it is).
// INVALID_ARGUMENT saying what is wrong otherwise.
absl::StatusOr<std::string> ParseViewerKey(absl::string_view contents);

enum class ViewerKeyCheck {
  kGranted,         // The request carries the key (cookie or Authorization header).
  kGrantedFromUrl,  // The key is in the query (`key`): answer with ViewerKeyRedirect.
  kRefused,         // No key, or a wrong one.
};

// What `request` brings of `key` (compared in time independent of where they differ).
ViewerKeyCheck CheckViewerKey(const http::HttpRequest& request, absl::string_view key);

// The answer to a request with the key in its query: 303 to the same path and query without
// `key`, setting the cookie (HttpOnly, SameSite=Strict, Path=/; with `https`, Secure too, so
// that the browser never sends it in the clear).
http::HttpResponse ViewerKeyRedirect(const http::HttpRequest& request, absl::string_view key,
                                     bool https = false);

}  // namespace neuralmesh::client::web

#endif  // NEURALMESH_CLIENT_WEB_VIEWER_KEY_H_
