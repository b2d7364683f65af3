// LZF, the compression of liblzf (Marc Lehmann) that PCL's binary_compressed PCD files use: a
// byte stream of literal runs (a control byte 0-31, then that many plus one bytes) and back
// references (a control byte whose top three bits hold the length minus two, 7 meaning that
// a second byte adds to it, and whose low five bits with the next byte hold the distance minus
// one, up to 8,192 bytes back).
#ifndef NEURALMESH_CORE_IO_INTERNAL_LZF_H_
#define NEURALMESH_CORE_IO_INTERNAL_LZF_H_

#include <string>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"

namespace neuralmesh::io_internal {

// Decompresses `in` into exactly out->size() bytes. Returns INVALID_ARGUMENT saying where
// and how for data that run past either end or give another size.
absl::Status LzfDecompress(absl::string_view in, std::string* out);

// Compresses `in` (greedily, each 3-byte sequence looked up in a table of its last
// occurrence): LzfDecompress gives `in` back. Never longer than in.size() + in.size() / 32 +
// 1 bytes. Deterministic.
std::string LzfCompress(absl::string_view in);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_LZF_H_
