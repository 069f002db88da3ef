// Container errors name the chunk type by its kChunkTypeNames entry (hyphens spelled as spaces),
// or "unknown (N)" for a type no row holds.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "bitstream/format.h"
#include "dmc/decoder.h"

namespace dmc {
namespace {

using ::testing::HasSubstr;

// Magic, version, reserved byte, then one chunk header declaring more bytes than follow.
std::vector<uint8_t> StreamWithChunkOf(uint8_t type) {
  std::vector<uint8_t> stream(format::kMagic.begin(), format::kMagic.end());
  stream.insert(stream.end(), {static_cast<uint8_t>(format::kVersionMajor),
                               static_cast<uint8_t>(format::kVersionMinor), 0, type, 100});
  return stream;
}

std::string OpenError(uint8_t type) {
  Decoder decoder;
  const Status status = decoder.Open(StreamWithChunkOf(type));
  EXPECT_EQ(status.code(), ErrorCode::kTruncatedStream);
  return status.message();
}

TEST(ChunkNames, ErrorsNameTheChunkTypeFromTheWireTable) {
  EXPECT_THAT(OpenError(1), HasSubstr("chunk 0 (sequence header) declares 100 bytes"));
  EXPECT_THAT(OpenError(3), HasSubstr("chunk 0 (segment header) declares"));
  EXPECT_THAT(OpenError(6), HasSubstr("chunk 0 (operator) declares"));
  EXPECT_THAT(OpenError(15), HasSubstr("chunk 0 (end) declares"));
  EXPECT_THAT(OpenError(9), HasSubstr("chunk 0 (scene) declares"));
  EXPECT_THAT(OpenError(10), HasSubstr("chunk 0 (unknown (10)) declares"));
  EXPECT_THAT(OpenError(0), HasSubstr("chunk 0 (unknown (0)) declares"));
}

}  // namespace
}  // namespace dmc
