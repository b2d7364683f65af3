#include "core/io/internal/lzf.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

#include "absl/strings/str_cat.h"

namespace neuralmesh::io_internal {
namespace {

constexpr size_t kMaxLiteralRun = 32;
constexpr size_t kMaxDistance = 1 << 13;
constexpr size_t kMaxMatch = 2 + 7 + 255;
constexpr int kHashBits = 14;

uint32_t HashOfThree(const char* p) {
  const uint32_t v = static_cast<uint32_t>(static_cast<uint8_t>(p[0])) << 16 |
                     static_cast<uint32_t>(static_cast<uint8_t>(p[1])) << 8 |
                     static_cast<uint8_t>(p[2]);
  return (v * 2654435761u) >> (32 - kHashBits);
}

}  // namespace

absl::Status LzfDecompress(absl::string_view in, std::string* out) {
  size_t ip = 0, op = 0;
  const size_t out_size = out->size();
  const auto corrupt = [&](absl::string_view what) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the compressed points are corrupt at byte ", ip, " of ", in.size(), ": ", what));
  };
  while (ip < in.size()) {
    const unsigned ctrl = static_cast<uint8_t>(in[ip++]);
    if (ctrl < 32) {  // A literal run of ctrl + 1 bytes.
      const size_t length = ctrl + 1;
      if (length > in.size() - ip) return corrupt("a literal run reaches past the end");
      if (length > out_size - op) return corrupt("more bytes than the header states");
      std::memcpy(out->data() + op, in.data() + ip, length);
      ip += length;
      op += length;
      continue;
    }
    size_t length = ctrl >> 5;  // A back reference of length + 2 bytes.
    if (ip >= in.size()) return corrupt("a back reference is cut off");
    if (length == 7) {
      length += static_cast<uint8_t>(in[ip++]);
      if (ip >= in.size()) return corrupt("a back reference is cut off");
    }
    const size_t distance = ((ctrl & 0x1F) << 8) + static_cast<uint8_t>(in[ip++]) + 1;
    length += 2;
    if (distance > op) return corrupt("a back reference points before the start");
    if (length > out_size - op) return corrupt("more bytes than the header states");
    for (size_t k = 0; k < length; ++k, ++op) (*out)[op] = (*out)[op - distance];
  }
  if (op != out_size) {
    return absl::InvalidArgumentError(absl::StrCat("the compressed points give ", op,
                                                   " bytes; the header states ", out_size));
  }
  return absl::OkStatus();
}

std::string LzfCompress(absl::string_view in) {
  std::string out;
  out.reserve(in.size() + in.size() / kMaxLiteralRun + 1);
  // The literal run being written: its control byte's place and its length so far.
  size_t run_start = 0, run = 0;
  const auto add_literal = [&](char byte) {
    if (run == 0) {
      run_start = out.size();
      out.push_back('\0');
    }
    out.push_back(byte);
    if (++run == kMaxLiteralRun) {
      out[run_start] = static_cast<char>(run - 1);
      run = 0;
    }
  };
  const auto end_run = [&] {
    if (run > 0) out[run_start] = static_cast<char>(run - 1);
    run = 0;
  };
  // Where each hashed 3-byte sequence was seen last, plus one (0: never).
  std::vector<uint32_t> last_seen(size_t{1} << kHashBits, 0);
  size_t ip = 0;
  while (ip + 3 <= in.size()) {
    const uint32_t hash = HashOfThree(in.data() + ip);
    const size_t candidate = last_seen[hash];
    last_seen[hash] = static_cast<uint32_t>(ip + 1);
    if (candidate == 0 || ip - (candidate - 1) > kMaxDistance ||
        std::memcmp(in.data() + candidate - 1, in.data() + ip, 3) != 0) {
      add_literal(in[ip++]);
      continue;
    }
    const size_t ref = candidate - 1;
    const size_t longest = std::min(kMaxMatch, in.size() - ip);
    size_t length = 3;
    while (length < longest && in[ref + length] == in[ip + length]) ++length;
    end_run();
    const size_t distance = ip - ref - 1;
    const size_t encoded = length - 2;
    if (encoded < 7) {
      out.push_back(static_cast<char>(encoded << 5 | distance >> 8));
    } else {
      out.push_back(static_cast<char>(7 << 5 | distance >> 8));
      out.push_back(static_cast<char>(encoded - 7));
    }
    out.push_back(static_cast<char>(distance & 0xFF));
    ip += length;
  }
  while (ip < in.size()) add_literal(in[ip++]);
  end_run();
  return out;
}

}  // namespace neuralmesh::io_internal
