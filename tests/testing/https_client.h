// For tests of HTTPS servers (the live viewer, the server's metrics page): a raw HTTP/1.1 client
// over TLS that checks the server's certificate as a browser would, against a given CA and for a
// given host name or address.
#ifndef NEURALMESH_TESTS_TESTING_HTTPS_CLIENT_H_
#define NEURALMESH_TESTS_TESTING_HTTPS_CLIENT_H_

#include <string>

#include "tests/testing/http_client.h"

namespace neuralmesh::testing {

struct HttpsTarget {
  int port = 0;                    // On 127.0.0.1.
  std::string ca;                  // PEM: the CA the server's certificate must chain to.
  std::string host = "127.0.0.1";  // The name or address it must be for (and SNI for a name).
  // PEM: a client certificate and its key to present when the server asks. Empty: none.
  std::string client_chain, client_key;
};

// Sends `request` as is over TLS and reads until the server closes. A failed connection or
// handshake gives status 0, and then `error` (when given) says why in OpenSSL's words.
HttpReply SendRawHttps(const HttpsTarget& target, const std::string& request,
                       std::string* error = nullptr);

// GET `path` with a Host header and, when `bearer` is set, "Authorization: Bearer BEARER".
HttpReply HttpsGet(const HttpsTarget& target, const std::string& path,
                   const std::string& bearer = "", std::string* error = nullptr);

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_TESTING_HTTPS_CLIENT_H_
