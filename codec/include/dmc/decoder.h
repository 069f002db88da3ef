// Decoding .dmc streams. Links no encoder code.
//
// Contract: every function is safe on untrusted input and never throws. Sizes and indices are
// checked before use, and a damaged stream yields kCorruptStream (checksum mismatch, impossible
// value), kTruncatedStream (ends early) or kUnsupported (a newer version or an unknown method),
// naming the chunk and field at fault. Work and memory are O(stream bytes + declared output):
// before anything grows with a declared size, every payload is checked to be long enough for the
// values that size makes it code (spec §5.5), and the declared output against the caller's limit
// (DecoderOptions, kResourceLimit). Memory that runs out anyway is kResourceLimit too.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "dmc/sequence.h"
#include "dmc/status.h"
#include "dmc/topology.h"

namespace dmc {

struct SegmentInfo {
  int first_frame = 0;
  int frame_count = 0;
  int rank = 0;
  std::string operator_name;  // registry name of the operator
  int operator_id = 0;        // its frozen wire ID
  int basis_bits = 0;
  int weight_bits = 0;
  int anchor_count = 0;
  double residual_step = 0.0;
  double anchor_step = 0.0;
  // Payload bytes (with chunk framing) per syntax element.
  uint64_t header_bytes = 0, mean_bytes = 0, basis_bytes = 0, operator_bytes = 0, anchor_bytes = 0,
           residual_bytes = 0;
};

struct StreamInfo {
  int version_major = 0;
  int version_minor = 0;
  int vertex_count = 0;
  int triangle_count = 0;
  int frame_count = 0;
  double frame_rate = 0.0;
  bool reordered = false;  // vertex order is the codec's own, not the input's
  std::string name;
  uint64_t total_bytes = 0;
  uint64_t header_bytes = 0;
  uint64_t connectivity_bytes = 0;
  // Format 1.3: the scene chunk (what a glTF input holds besides its motion, spec §6.3): its
  // bytes in the stream (framing included) and once decompressed; 0 without one.
  uint64_t scene_bytes = 0;
  uint64_t scene_size = 0;
  std::vector<SegmentInfo> segments;
};

// Limits a caller puts on decoding, in the spirit of libpng's user limits: a stream within the
// format's limits (spec §6.2) may still describe more than a caller wants to hold.
struct DecoderOptions {
  // Largest declared output a call accepts: 12·V·F bytes of float32 positions plus 12·T of
  // triangles for the whole stream (what Decode returns and DecodeToPc2 writes; Decoder::Open
  // checks the whole stream too). A stream above it is refused with kResourceLimit before
  // anything is allocated for it. 0 means no limit beyond the format's 16 GiB.
  // The scene (format 1.3) counts too.
  uint64_t max_output_bytes = uint64_t{4} << 30;
  // Largest normal matrix LᵀL + anchors and Cholesky factor of one segment (SolverOptions::
  // max_matrix_bytes): their size follows the connectivity's structure, not its size alone (one
  // vertex of degree d puts d² entries in LᵀL), so a short connectivity can demand far more than
  // the output. One above it is refused with kResourceLimit before it is built. 0: no bound.
  uint64_t max_matrix_bytes = uint64_t{4} << 30;
};

// 12·V·F + 12·T + the scene's size: the bytes of float32 positions, int32 triangles and scene a
// stream declares.
uint64_t DeclaredOutputBytes(const StreamInfo& info);

// Parses the container, the headers and the connectivity (verifying checksums and that every
// payload can hold what its headers declare) without reconstructing. Applies no output limit and
// does no work that grows with the vertex count beyond the connectivity's own.
StatusOr<StreamInfo> ReadStreamInfo(std::span<const uint8_t> stream);

// Decodes a whole stream. `scene`, when given, receives the stream's scene (format 1.3,
// DecodeScene), empty without one: a caller that wants both opens the stream once.
StatusOr<MeshSequence> Decode(std::span<const uint8_t> stream, const DecoderOptions& options = {},
                              std::vector<uint8_t>* scene = nullptr);
StatusOr<MeshSequence> DecodeFile(const std::filesystem::path& path,
                                  const DecoderOptions& options = {});

// The stream's scene (format 1.3, spec §6.3): a glTF binary (GLB) file with what the encoder's glTF
// input held besides vertex motion (nodes, materials, textures, UVs, clips; bitstream spec
// Appendix C), decompressed; empty when the stream has none. Validates the stream as Open does.
StatusOr<std::vector<uint8_t>> DecodeScene(std::span<const uint8_t> stream,
                                           const DecoderOptions& options = {});

// Segment-by-segment decoding for bounded memory and seeking: Open parses the container; each
// DecodeSegment(i) returns the frames of segment i alone (with the shared triangles).
class Decoder {
 public:
  // Parses the stream (as ReadStreamInfo), checks its declared output against `options` and
  // builds the topology the segments share.
  Status Open(std::span<const uint8_t> stream, const DecoderOptions& options = {});
  const StreamInfo& info() const { return info_; }
  int segment_count() const { return static_cast<int>(info_.segments.size()); }
  const Triangles& triangles() const { return triangles_; }
  // The decompressed scene (format 1.3), empty without one.
  const std::vector<uint8_t>& scene() const { return scene_; }
  // Thread-safe: segments may be decoded concurrently.
  StatusOr<MeshSequence> DecodeSegment(int index) const;

  // Where a segment's frames go: called once per segment, only after its syntax has been decoded
  // and its coefficients solved, so a caller can defer allocating the output until the stream
  // has proved it holds real data. Returns the segment's first float (F_s × V × 3 values).
  using FrameDestination = std::function<StatusOr<float*>(int segment_index)>;
  // Decodes segment `index` into the memory `destination` hands out. Thread-safe.
  Status DecodeSegmentInto(int index, const FrameDestination& destination) const;

 private:
  struct ChunkRef {
    uint8_t type;
    size_t offset;
    size_t size;
  };
  std::span<const uint8_t> stream_;
  StreamInfo info_;
  Triangles triangles_;
  MeshTopology topology_;
  std::vector<int32_t> vertex_order_;  // residual coding order, shared by all segments
  std::vector<std::vector<ChunkRef>> segment_chunks_;
  std::vector<uint8_t> scene_;
  uint64_t max_matrix_bytes_ = 0;  // DecoderOptions::max_matrix_bytes

  Status OpenImpl(std::span<const uint8_t> stream, const DecoderOptions* options);
  Status DecodeSegmentIntoImpl(int index, const FrameDestination& destination) const;
  friend StatusOr<StreamInfo> ReadStreamInfo(std::span<const uint8_t> stream);
};

StatusOr<std::vector<uint8_t>> ReadFileBytes(const std::filesystem::path& path);

// Progress of a streaming decode: frames written so far and the frame count; one call at a time,
// possibly from a worker thread.
using DecodeProgressCallback = std::function<void(int frames_done, int frames_total)>;

// Decodes `stream` segment by segment into the PC2 cache `output` and its connectivity mesh
// <stem>.obj beside it: byte for byte the files WriteSequence(Decode(stream), output) writes, but
// holding at most `segments_in_flight` decoded segments (12·V·F_s bytes each, plus each one's
// factorisation while it decodes) instead of the whole sequence. Segments decode concurrently
// when segments_in_flight > 1 and are written in order, with the same output for any value:
// normal matrices below 300k vertices are ordered by AMD (deterministic), larger ones by METIS,
// whose analyses the solver runs one at a time (its random state is global to the process).
// Both files are written under temporary names and renamed into place at the end, the mesh
// first; on any failure (a damaged stream, a full disk) neither is left behind and existing files
// are untouched. Errors: those of Decode, kIoError for the files, kInvalidArgument for
// segments_in_flight < 1, kResourceLimit for a stream above options' limit.
// Defined in dmc_decoder_files (dmc_decoder plus dmc_io), not in dmc_decoder.
Status DecodeToPc2(std::span<const uint8_t> stream, const std::filesystem::path& output,
                   const DecodeProgressCallback& progress = {}, int segments_in_flight = 1,
                   const DecoderOptions& options = {});

}  // namespace dmc
