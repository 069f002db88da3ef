// Decoding never allocates more than a bound derived from the stream's declared sizes (issue 6;
// decoder.h's contract, spec §12.1): for every truncation and every single-byte flip (with and
// without repaired checksums) of a small valid stream, the peak of live heap bytes during
// Decode() stays within
//
//   kBoundFactor · (12·V·F + 12·T + stream bytes) + kBoundSlack
//
// where V, T and F are the vertex, triangle and frame counts the damaged stream's own sequence
// header declares (0 when it does not parse). 12·V·F + 12·T is the size of the decoded sequence
// (float32 positions, int32 triangles); the decoder's working set (topology, coefficients, the
// normal equations and their factor) is a small multiple of it, and the slack covers fixed costs
// (thread pool, solver workspaces) that do not grow with the stream.
//
// The peak is measured by interposing the C allocator (malloc and friends) in this test binary:
// operator new, Eigen, CHOLMOD and TBB all allocate through it, so every heap byte is seen. Under
// AddressSanitizer (tools/sanitize.sh) the sanitizer owns the allocator and the tests skip.
#include <gtest/gtest.h>
#include <malloc.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "dmc/synth.h"
#include "dmc/wire_ids.h"
#include "entropy/byte_io.h"
#include "fuzz/fuzz_support.h"
#include "test_support.h"

namespace {

// Live heap bytes (usable sizes, so allocator rounding counts) and their high-water mark.
std::atomic<int64_t> live_bytes{0};
std::atomic<int64_t> peak_bytes{0};

[[maybe_unused]] void CountAllocation(void* pointer) {
  if (pointer == nullptr) return;
  const auto size = static_cast<int64_t>(malloc_usable_size(pointer));
  const int64_t now = live_bytes.fetch_add(size) + size;
  int64_t peak = peak_bytes.load(std::memory_order_relaxed);
  while (now > peak && !peak_bytes.compare_exchange_weak(peak, now)) {
  }
}

[[maybe_unused]] void CountRelease(void* pointer) {
  if (pointer != nullptr) live_bytes.fetch_sub(static_cast<int64_t>(malloc_usable_size(pointer)));
}

}  // namespace

#if !DMC_SANITIZER_OWNS_ALLOCATOR
// glibc's own entry points, which the replacements below forward to.
extern "C" {
void* __libc_malloc(size_t size);
void __libc_free(void* pointer);
void* __libc_calloc(size_t count, size_t size);
void* __libc_realloc(void* pointer, size_t size);
void* __libc_memalign(size_t alignment, size_t size);

void* malloc(size_t size) noexcept {
  void* pointer = __libc_malloc(size);
  CountAllocation(pointer);
  return pointer;
}

void free(void* pointer) noexcept {
  CountRelease(pointer);
  __libc_free(pointer);
}

void* calloc(size_t count, size_t size) noexcept {
  void* pointer = __libc_calloc(count, size);
  CountAllocation(pointer);
  return pointer;
}

void* realloc(void* pointer, size_t size) noexcept {
  const int64_t old_size =
      pointer != nullptr ? static_cast<int64_t>(malloc_usable_size(pointer)) : 0;
  void* moved = __libc_realloc(pointer, size);
  if (moved == nullptr && size != 0) return nullptr;  // the old block is untouched
  live_bytes.fetch_sub(old_size);
  CountAllocation(moved);
  return moved;
}

void* memalign(size_t alignment, size_t size) noexcept {
  void* pointer = __libc_memalign(alignment, size);
  CountAllocation(pointer);
  return pointer;
}

void* aligned_alloc(size_t alignment, size_t size) noexcept { return memalign(alignment, size); }

int posix_memalign(void** out, size_t alignment, size_t size) noexcept {
  if (alignment % sizeof(void*) != 0 || (alignment & (alignment - 1)) != 0) return EINVAL;
  void* pointer = memalign(alignment, size);
  if (pointer == nullptr && size != 0) return ENOMEM;
  *out = pointer;
  return 0;
}
}  // extern "C"
#endif

namespace dmc {
namespace {

// The bound's constants. The small stream below decodes with a peak of about 170 KB for 6 KB of
// output: the solver's workspaces and the topology dominate a mesh this small, so the slack
// carries the bound there, while the factor is what a stream declaring a large mesh may use.
// Damaged variants peak within a few percent of the valid stream.
constexpr int64_t kBoundFactor = 16;
constexpr int64_t kBoundSlack = int64_t{1} << 20;

int64_t DeclaredOutputBytes(std::span<const uint8_t> stream) {
  const std::optional<format::SequenceHeader> header = fuzz::DeclaredSequenceHeader(stream);
  if (!header) return 0;
  return 12 * static_cast<int64_t>(header->vertex_count) * header->frame_count +
         12 * static_cast<int64_t>(header->triangle_count);
}

int64_t BoundFor(std::span<const uint8_t> stream) {
  return kBoundFactor * (DeclaredOutputBytes(stream) + static_cast<int64_t>(stream.size())) +
         kBoundSlack;
}

struct DecodeCost {
  int64_t peak_bytes = 0;  // above the live bytes before the call
  ErrorCode code = ErrorCode::kOk;
};

// Decodes the stream and reports the peak of heap bytes allocated while doing so (the result's
// own storage included).
DecodeCost MeasureDecode(std::span<const uint8_t> stream, const DecoderOptions& options = {}) {
  const int64_t before = live_bytes.load();
  peak_bytes.store(before);
  DecodeCost cost;
  cost.code = Decode(stream, options).status().code();
  cost.peak_bytes = peak_bytes.load() - before;
  return cost;
}

std::vector<uint8_t> EncodeSynthetic(const char* generator, int resolution, int frames,
                                     const char* operator_name, int segment_frames = 0) {
  SynthOptions synth;
  synth.resolution = resolution;
  synth.frames = frames;
  const StatusOr<MeshSequence> sequence = Synthesize(generator, synth);
  EXPECT_TRUE(sequence.ok()) << sequence.status().ToString();
  if (!sequence.ok()) return {};
  EncoderOptions options;
  options.measure = false;
  options.operator_name = operator_name;
  options.segment_frames = segment_frames;
  const StatusOr<std::vector<uint8_t>> stream = Encode(*sequence, options);
  EXPECT_TRUE(stream.ok()) << stream.status().ToString();
  return stream.ok() ? *stream : std::vector<uint8_t>();
}

// A small valid one-segment DDL stream (twist, ~100 vertices, 3 frames): DDL reaches the most
// payload decoders (weights, their prediction, the operator rebuild).
const std::vector<uint8_t>& SmallStream() {
  static const std::vector<uint8_t> stream = EncodeSynthetic("twist", 100, 3, "ddl");
  return stream;
}

class AllocationBound : public ::testing::Test {
 protected:
  void SetUp() override {
    if (DMC_SANITIZER_OWNS_ALLOCATOR) {
      GTEST_SKIP() << "a sanitizer replaces the allocator; heap peaks are measured unsanitized";
    }
    ASSERT_FALSE(SmallStream().empty());
    // One decode first, so that one-time costs (the thread pool, lazily built tables) fall
    // outside the measured cases.
    ASSERT_TRUE(Decode(SmallStream()).ok());
  }

  // Decodes a damaged variant and checks its peak against the bound; returns the peak.
  int64_t ExpectWithinBound(std::span<const uint8_t> stream, const char* what, size_t where) {
    const DecodeCost cost = MeasureDecode(stream);
    const int64_t bound = BoundFor(stream);
    EXPECT_LE(cost.peak_bytes, bound)
        << what << " " << where << ": peak " << cost.peak_bytes << " bytes, declared output "
        << DeclaredOutputBytes(stream) << " bytes, code " << ErrorCodeName(cost.code);
    return cost.peak_bytes;
  }
};

TEST_F(AllocationBound, TrackingSeesTheDecodedOutput) {
  // The measurement itself: decoding the valid stream must show at least the decoded sequence's
  // own storage (12 bytes per vertex and frame, 12 per triangle), and stay within the bound.
  const std::vector<uint8_t>& stream = SmallStream();
  const DecodeCost cost = MeasureDecode(stream);
  ASSERT_EQ(cost.code, ErrorCode::kOk);
  const int64_t output = DeclaredOutputBytes(stream);
  ASSERT_GT(output, 0);
  EXPECT_GE(cost.peak_bytes, output);
  EXPECT_LE(cost.peak_bytes, BoundFor(stream));
  std::printf("valid stream: %zu bytes, declared output %lld bytes, decode peak %lld bytes\n",
              stream.size(), static_cast<long long>(output),
              static_cast<long long>(cost.peak_bytes));
}

TEST_F(AllocationBound, EveryTruncationStaysWithinTheBound) {
  const std::vector<uint8_t>& stream = SmallStream();
  int64_t worst = 0;
  for (size_t length = 0; length < stream.size(); ++length) {
    worst = std::max(worst, ExpectWithinBound(std::span<const uint8_t>(stream.data(), length),
                                              "truncated to", length));
  }
  std::printf("truncations: worst peak %lld bytes\n", static_cast<long long>(worst));
}

TEST_F(AllocationBound, EveryByteFlipStaysWithinTheBound) {
  // Each byte flipped two ways, with the damaged checksum left (the container rejects it) and
  // repaired (the flip reaches the headers, connectivity, payload decoders and the solver).
  const std::vector<uint8_t>& stream = SmallStream();
  int64_t worst_raw = 0, worst_repaired = 0;
  for (size_t i = 0; i < stream.size(); ++i) {
    for (const uint8_t mask : {uint8_t{0x01}, uint8_t{0xFF}}) {
      std::vector<uint8_t> damaged = stream;
      damaged[i] ^= mask;
      worst_raw = std::max(worst_raw, ExpectWithinBound(damaged, "byte flipped", i));
      const std::vector<uint8_t> repaired = fuzz::RepairChecksums(damaged);
      if (repaired != damaged) {
        worst_repaired =
            std::max(worst_repaired, ExpectWithinBound(repaired, "byte flipped (repaired)", i));
      }
    }
  }
  std::printf("byte flips: worst peak %lld bytes (raw), %lld bytes (repaired checksums)\n",
              static_cast<long long>(worst_raw), static_cast<long long>(worst_repaired));
}

TEST_F(AllocationBound, StreamRejectedInItsPayloadsDoesNotAllocateItsOutput) {
  // A stream whose residual payload is damaged is rejected before its frames are synthesised.
  // The decoder needs its topology, the segment's syntax elements and (factored while the
  // residuals decode) the normal matrix's factor to get there: a working set that grows with
  // the vertex count alone, far less than the declared output of a long segment (480 frames:
  // 5760 bytes per vertex of positions), so allocating the output before the payloads are
  // validated shows up as a peak above half of it.
  const std::vector<uint8_t> stream = EncodeSynthetic("twist", 1000, 480, "tutte", 480);
  ASSERT_FALSE(stream.empty());
  ASSERT_EQ(ReadStreamInfo(stream)->segments.size(), 1u);
  std::optional<size_t> residuals;  // offset of the residual payload's first byte
  ByteReader reader(stream);
  std::span<const uint8_t> bytes;
  ASSERT_TRUE(reader.GetBytes(7, &bytes, "preamble").ok());
  while (!reader.at_end()) {
    uint8_t type = 0;
    uint64_t size = 0;
    uint32_t checksum = 0;
    ASSERT_TRUE(reader.GetU8(&type, "type").ok());
    ASSERT_TRUE(reader.GetVarU(&size, "size").ok());
    if (type == static_cast<uint8_t>(ChunkType::kResiduals)) residuals = reader.position();
    ASSERT_TRUE(reader.GetBytes(size, &bytes, "payload").ok());
    ASSERT_TRUE(reader.GetU32(&checksum, "checksum").ok());
  }
  ASSERT_TRUE(residuals.has_value());
  std::vector<uint8_t> damaged = stream;
  damaged[*residuals] ^= 0xFF;  // a range-coded payload must start with a zero byte (spec §5)
  damaged = fuzz::RepairChecksums(damaged);

  const DecodeCost cost = MeasureDecode(damaged);
  ASSERT_NE(cost.code, ErrorCode::kOk);
  const int64_t output = DeclaredOutputBytes(damaged);
  std::printf("rejected stream: declared output %lld bytes, decode peak %lld bytes\n",
              static_cast<long long>(output), static_cast<long long>(cost.peak_bytes));
  // The decoder allocates a segment's output only once its payloads have decoded and solved.
  EXPECT_LT(cost.peak_bytes, output / 2);
}

TEST_F(AllocationBound, StreamsDeclaringHugeMeshesAreRefusedInLittleMemory) {
  // The generated vectors that declare 2^26 vertices (or 2^25 anchors) in a few hundred bytes
  // are refused from their headers and payload sizes (spec §8.7), with no caller limit, and by
  // the default limit (4 GiB) when their output exceeds it: either way within a few megabytes,
  // nowhere near the gigabytes their declared sizes would take.
  constexpr int64_t kMaxPeak = int64_t{64} << 20;
  DecoderOptions none;
  none.max_output_bytes = 0;
  for (const char* name :
       {"residuals_cannot_hold_declared_vertices", "residuals_cannot_hold_declared_vertices_tutte",
        "reference_frame_cannot_hold_declared_vertices", "anchors_cannot_hold_declared_count"}) {
    const StatusOr<std::vector<uint8_t>> stream = ReadFileBytes(
        std::string(DMC_SOURCE_DIR) + "/conformance/vectors/invalid/" + name + ".dmc");
    ASSERT_TRUE(stream.ok()) << stream.status().ToString();
    for (const DecoderOptions& options : {none, DecoderOptions()}) {
      const DecodeCost cost = MeasureDecode(*stream, options);
      EXPECT_TRUE(cost.code == ErrorCode::kCorruptStream || cost.code == ErrorCode::kResourceLimit)
          << name << ": " << ErrorCodeName(cost.code);
      EXPECT_LT(cost.peak_bytes, kMaxPeak) << name;
      std::printf("%s (limit %llu): %s, peak %lld bytes\n", name,
                  static_cast<unsigned long long>(options.max_output_bytes),
                  std::string(ErrorCodeName(cost.code)).c_str(),
                  static_cast<long long>(cost.peak_bytes));
    }
  }
}

}  // namespace
}  // namespace dmc
