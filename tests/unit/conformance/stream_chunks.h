// Taking one of our own streams apart into chunks and framing edited chunks again, for the tests
// that craft hostile streams (hostile_stream_test, declared_size_test).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <span>
#include <vector>

#include "bitstream/syntax.h"
#include "entropy/byte_io.h"

namespace dmc::testing {

struct Chunk {
  uint8_t type = 0;
  std::vector<uint8_t> payload;
};

// Splits a valid stream into its preamble and chunks (no checks: the input is our own encoding).
inline std::vector<Chunk> SplitChunks(const std::vector<uint8_t>& stream,
                                      std::vector<uint8_t>* preamble) {
  ByteReader reader(stream);
  std::span<const uint8_t> bytes;
  EXPECT_TRUE(reader.GetBytes(7, &bytes, "preamble").ok());
  preamble->assign(bytes.begin(), bytes.end());
  std::vector<Chunk> chunks;
  while (!reader.at_end()) {
    Chunk chunk;
    uint64_t size = 0;
    uint32_t checksum = 0;
    EXPECT_TRUE(reader.GetU8(&chunk.type, "type").ok());
    EXPECT_TRUE(reader.GetVarU(&size, "size").ok());
    EXPECT_TRUE(reader.GetBytes(size, &bytes, "payload").ok());
    EXPECT_TRUE(reader.GetU32(&checksum, "checksum").ok());
    chunk.payload.assign(bytes.begin(), bytes.end());
    chunks.push_back(std::move(chunk));
  }
  return chunks;
}

// Frames chunks again with correct checksums.
inline std::vector<uint8_t> JoinChunks(const std::vector<uint8_t>& preamble,
                                       const std::vector<Chunk>& chunks) {
  ByteWriter out;
  out.PutBytes(preamble);
  for (const Chunk& chunk : chunks) {
    out.PutU8(chunk.type);
    out.PutVarU(chunk.payload.size());
    out.PutBytes(chunk.payload);
    out.PutU32(format::ChunkChecksum(chunk.type, chunk.payload, preamble.at(5)));
  }
  return out.Take();
}

}  // namespace dmc::testing
