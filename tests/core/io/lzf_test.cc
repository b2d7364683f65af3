// LZF (core/io/internal/lzf.h), the compression of PCL's binary_compressed PCD files: what
// LzfCompress writes, LzfDecompress gives back, for data of every kind and size; runs and
// repeats compress, within the stated bound otherwise; damaged streams are refused.
#include "core/io/internal/lzf.h"

#include <string>

#include "core/random.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace neuralmesh::io_internal {
namespace {

using ::testing::HasSubstr;

std::string RoundTrip(const std::string& in) {
  const std::string compressed = LzfCompress(in);
  EXPECT_LE(compressed.size(), in.size() + in.size() / 32 + 1) << "the stated bound";
  std::string out(in.size(), '\0');
  const absl::Status status = LzfDecompress(compressed, &out);
  EXPECT_TRUE(status.ok()) << status;
  return out;
}

TEST(LzfTest, WhatIsCompressedDecompressesToItself) {
  Random rng(11);
  std::string noise(100000, '\0');
  for (char& c : noise) c = static_cast<char>(rng.NextIndex(256));
  std::string text;
  while (text.size() < 50000) text += "x y z 0.125 -3.5 12 255 128 0\n";
  // Repeats as far back as the format reaches (8,192 bytes), and beyond it.
  std::string far, beyond;
  for (int i = 0; i < 3; ++i) {
    far += noise.substr(0, 8000);
    beyond += noise.substr(0, 9000);
  }
  for (const std::string& in :
       {std::string(), std::string("a"), std::string("ab"), std::string("abc"),
        std::string(1000000, '\0'), noise, text, far, beyond,
        std::string(264 * 3 + 5, 'q')}) {
    EXPECT_EQ(RoundTrip(in), in) << in.size() << " bytes";
  }
  EXPECT_LT(LzfCompress(std::string(1000000, '\0')).size(), 20000u) << "a run compresses";
  EXPECT_LT(LzfCompress(text).size(), text.size() / 10) << "a repeated line compresses";
  EXPECT_LT(LzfCompress(far).size(), far.size() / 2) << "a repeat within 8 KB compresses";
}

TEST(LzfTest, DamagedStreamsAreRefused) {
  const std::string compressed = LzfCompress(std::string(5000, 'z'));
  std::string out(5000, '\0');
  EXPECT_THAT(std::string(LzfDecompress(compressed.substr(0, compressed.size() - 1), &out)
                              .message()),
              HasSubstr("corrupt"));
  std::string short_out(4000, '\0');
  EXPECT_THAT(std::string(LzfDecompress(compressed, &short_out).message()),
              HasSubstr("more bytes than the header states"));
  std::string long_out(6000, '\0');
  EXPECT_THAT(std::string(LzfDecompress(compressed, &long_out).message()),
              HasSubstr("the compressed points give 5000 bytes; the header states 6000"));
  std::string one(1, '\0');
  EXPECT_THAT(std::string(LzfDecompress(std::string("\x20\x05", 2), &one).message()),
              HasSubstr("a back reference points before the start"));
}

}  // namespace
}  // namespace neuralmesh::io_internal
