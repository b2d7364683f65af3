// Secrets that HTTP clients bring in "Authorization: Bearer SECRET" (RFC 6750): the viewer's key
// (`neuralmesh view --view_key_file`) and the metrics page's token (`neuralmesh-server
// --metrics_token_file`). Each is read from a file and compared in time that does not depend on
// where a guess goes wrong.
#ifndef NEURALMESH_HTTP_BEARER_TOKEN_H_
#define NEURALMESH_HTTP_BEARER_TOKEN_H_

#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "http/http_message.h"

namespace neuralmesh::http {

// A secret is at least this long.
inline constexpr size_t kMinSecretLength = 16;

// Whether `c` may stand in a secret: a letter, a digit or one of "-._~", so that a secret
// stands in a URL and a header as it is.
bool IsSecretCharacter(char c);

// The secret in `contents` (a file's): its text without surrounding whitespace, at least
// kMinSecretLength characters, each an IsSecretCharacter. INVALID_ARGUMENT naming it as
// `what` ("the viewer key") and saying what is wrong otherwise.
absl::StatusOr<std::string> ParseSecret(absl::string_view contents, absl::string_view what);

// Equal, in time that does not depend on where `a` and `b` first differ.
bool SameSecret(absl::string_view a, absl::string_view b);

// The credentials of the request's "Authorization: Bearer ..." header (the scheme's name in
// any case); empty without one.
absl::string_view BearerTokenOf(const HttpRequest& request);

// 401 with `message` and "WWW-Authenticate: Bearer realm=REALM".
HttpResponse BearerChallenge(absl::string_view realm, absl::string_view message);

}  // namespace neuralmesh::http

#endif  // NEURALMESH_HTTP_BEARER_TOKEN_H_
