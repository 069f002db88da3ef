// Conformance-vector toolkit shared by the runner (dmc_conform) and the generator
// (dmc_conformance_generate): container framing, the syntax digests, the reference-position
// files, the tolerance check and the manifests. Normative definitions: bitstream-spec/dmc-format.md
// §12 (Conformance).
//
// Contract: every function is safe on untrusted bytes (the runner feeds it hostile vectors) and
// reports failure through Status; nothing here throws across its API (JSON parse errors are
// caught and turned into kParseError).
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "bitstream/format.h"
#include "decoder/segment_reconstruction.h"
#include "dmc/decoder.h"
#include "dmc/sequence.h"
#include "dmc/status.h"
#include "dmc/topology.h"

namespace dmc::conformance {

// The vectors' codes are the stream's own (spec §11.1): they are checked with no caller limit on
// the output, which would report resource-limit first (§4.4) for the streams declaring 2^26
// vertices.
inline constexpr DecoderOptions kNoCallerLimit{.max_output_bytes = 0};

// Tolerance a conforming decoder must meet on every decoded coordinate x against the reference
// value r (spec §12.3): |x - r| <= kToleranceDiagonalFraction * D + kToleranceValueFraction * |r|,
// D the bounding-box diagonal of the reference sequence over all frames. The second term allows
// float32 rounding of large coordinates (2 ulp); the first is far below any quantisation step
// the format can express relative to D, yet far above double-precision solver differences.
inline constexpr double kToleranceDiagonalFraction = 1.0 / (1 << 20);
inline constexpr double kToleranceValueFraction = 1.0 / (1 << 22);

// The 7-byte preamble (magic, version, reserved) and one framed chunk of a stream.
inline constexpr size_t kPreambleBytes = 7;
struct Chunk {
  uint8_t type = 0;
  std::vector<uint8_t> payload;
  uint32_t checksum = 0;  // as stored (may be wrong in a hostile stream)
};

// Splits a stream into its preamble and framed chunks up to and including the first end chunk,
// without interpreting payloads or verifying checksums (so it can take apart streams that are
// about to be made invalid). Fails on a short preamble, a truncated chunk or a missing end chunk.
struct Framed {
  std::vector<uint8_t> preamble;
  std::vector<Chunk> chunks;
  std::vector<uint8_t> trailing;  // bytes after the end chunk
};
StatusOr<Framed> SplitFramed(std::span<const uint8_t> stream);

// Reassembles framed chunks; `recompute_checksums` writes the XXH32 each payload needs, otherwise
// the stored checksum is kept.
std::vector<uint8_t> JoinFramed(const Framed& framed, bool recompute_checksums = true);

// A stream parsed down to its entropy-decoded syntax elements with the reference decoder's
// syntax readers (after the public decoder has accepted the container): what the digests hash
// and what the generator edits to make invalid vectors.
struct ParsedStream {
  Framed framed;
  size_t first_segment_chunk = 2;  // 3 after a scene chunk (format 1.3, spec §4.4)
  format::SequenceHeader header;
  Triangles triangles;
  MeshTopology topology;
  std::vector<int32_t> vertex_order;  // residual coding order
  std::vector<SegmentSyntax> segments;
};
StatusOr<ParsedStream> ParseStream(std::span<const uint8_t> stream);

// The syntax digests of spec §12.2: XXH64 (seed 0) over the entropy-decoded integers of the
// connectivity chunk and of each segment, in the order the spec lists. Computed by parsing the
// stream with the reference decoder's syntax readers; fails with the decoder's error on an
// invalid stream.
struct SyntaxDigests {
  uint8_t connectivity_method = 0;
  uint64_t connectivity = 0;
  std::vector<uint64_t> segments;
};
StatusOr<SyntaxDigests> ComputeSyntaxDigests(std::span<const uint8_t> stream);

// XXH64 (seed 0) of the float32 little-endian bytes of frame f of a sequence.
uint64_t FrameHash(const MeshSequence& sequence, int frame);

// Bounding-box diagonal over every frame.
double SequenceDiagonal(const MeshSequence& sequence);

// Reference positions file (*.ref.zst): one zstd frame holding the float32 little-endian
// coordinates, frame after frame, vertex after vertex, x y z.
std::vector<uint8_t> CompressPositions(const MeshSequence& sequence);
// Decompresses and checks that exactly `expected_values` floats are present.
StatusOr<std::vector<float>> DecompressPositions(std::span<const uint8_t> compressed,
                                                 size_t expected_values);

struct PositionComparison {
  bool within_tolerance = true;
  double max_error = 0.0;        // max |x - r|
  double max_error_ratio = 0.0;  // max |x - r| / allowed(r); <= 1 within tolerance
  int bit_exact_frames = 0;      // frames whose XXH64 matches the manifest's
  std::string first_violation;   // "frame f vertex v axis a: ..." when not within tolerance
};
PositionComparison ComparePositions(const MeshSequence& decoded, std::span<const float> reference,
                                    double diagonal, const std::vector<uint64_t>& frame_hashes);

// Hex form of a 64-bit hash ("0x" + 16 lower-case digits) and back.
std::string HashHex(uint64_t value);
StatusOr<uint64_t> ParseHashHex(const std::string& text);

// Result of checking one vector against its manifest.
struct VectorResult {
  std::string name;
  bool passed = false;
  std::string detail;  // one line: what was checked, or why it failed
};

struct CheckOptions {
  bool require_bit_exact = false;  // also demand identical float bytes (same reference build)
};

// Checks the vector described by `manifest_path` (a *.json sidecar of a valid or invalid vector).
VectorResult CheckVector(const std::filesystem::path& manifest_path, const CheckOptions& options);

// Every *.json manifest under `root` (recursively), sorted by path.
std::vector<std::filesystem::path> FindManifests(const std::filesystem::path& root);

// Reads a whole file.
StatusOr<std::vector<uint8_t>> ReadBytes(const std::filesystem::path& path);
// Writes a whole file atomically (dmc::WriteFileAtomically). Defined in vector_writer.cpp, in
// dmc_conformance_writer, the generator's library: the runner never writes.
Status WriteBytes(const std::filesystem::path& path, std::span<const uint8_t> bytes);

}  // namespace dmc::conformance
