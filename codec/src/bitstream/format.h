// The .dmc container and segment syntax shared by the encoder and the decoder.
// Normative description: bitstream-spec/dmc-format.md. Every constant here is frozen per version.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "dmc/wire_ids.h"

namespace dmc::format {

inline constexpr std::array<uint8_t, 4> kMagic = {'D', 'M', 'C', 0x1A};
inline constexpr uint8_t kVersionMajor = 1;
inline constexpr uint8_t kVersionMinor = 3;

// Chunk types and connectivity methods are frozen wire IDs: dmc/wire_ids.h.
using ChunkType = ::dmc::ChunkType;
using ConnectivityMethod = ::dmc::ConnectivityMethod;

// Limits a decoder enforces before allocating (a stream exceeding them is corrupt).
inline constexpr uint64_t kMaxVertices = 1u << 26;
inline constexpr uint64_t kMaxTriangles = 1u << 27;
inline constexpr uint64_t kMaxFrames = 1u << 20;
inline constexpr uint64_t kMaxSegmentFrames = 4096;
inline constexpr uint64_t kMaxRank = 1024;
inline constexpr uint64_t kMaxChunkBytes = uint64_t{1} << 32;
inline constexpr uint32_t kMaxNameLength = 256;
// Largest |q| of a quantised residual (spec §8.6): a decoder reports corrupt-stream beyond it, so
// an encoder must never write one.
inline constexpr int64_t kMaxResidualMagnitude = int64_t{1} << 40;
// Largest quantisation step (§8.1; also the reference frame's step, §8.4), |q| of a mean value
// (§8.2) and of a reference frame coordinate (§8.4), and the anchor weight's range (§8.1): the
// decoder rejects a stream beyond them, so the encoder checks what it writes against the same.
inline constexpr double kMaxStep = 0x1p64;
inline constexpr int64_t kMaxMeanMagnitude = int64_t{1} << 52;
inline constexpr int64_t kMaxReferenceMagnitude = int64_t{1} << 40;
// Format 1.2 step shaping (spec §8.5.1): each anchor carries a step exponent e, |e| ≤ this, and
// the vertices of its region use the residual step times 2^(e/4).
inline constexpr int kMaxStepExponent = 16;
inline constexpr int kStepExponentsPerOctave = 4;
// Format 1.3 scene chunk (spec §6.3): its kinds and compressions, and the largest scene.
inline constexpr uint8_t kFirstSceneMinor = 3;
inline constexpr uint8_t kSceneKindGlb = 1;
inline constexpr uint8_t kSceneStored = 0;
inline constexpr uint8_t kSceneZstd = 1;
inline constexpr uint64_t kMaxSceneBytes = uint64_t{1} << 30;
inline constexpr double kMinAnchorWeight = 0x1p-32;
inline constexpr double kMaxAnchorWeight = 0x1p32;

// Most binary decisions a range-coded payload of P bytes can hold without overrunning (spec §5.5):
// every decision narrows the range by at least -log2(1 - 3825/2^24) > 1/3041 bit, so decoding N
// of them reads more than 5 + (N/3041 - 8)/8 bytes. A payload that cannot hold the decisions its
// declared sizes need is corrupt, and is refused before anything is sized by them.
inline constexpr uint64_t kMaxDecisionsPerPayloadByte = 24328;
constexpr uint64_t MaxDecisions(uint64_t payload_bytes) {
  return kMaxDecisionsPerPayloadByte * payload_bytes;
}

struct SequenceHeader {
  uint32_t vertex_count = 0;
  uint32_t triangle_count = 0;
  uint32_t frame_count = 0;
  uint32_t segment_count = 0;
  double frame_rate = 0.0;
  uint8_t flags = 0;  // bit 0: vertex order is the codec's own (reordered); others MUST be 0
  std::string name;
};
inline constexpr uint8_t kFlagReordered = 1;

struct SegmentHeader {
  uint32_t first_frame = 0;
  uint32_t frame_count = 0;
  uint32_t rank = 0;              // PCA basis vectors kept (0 allowed: mean only)
  uint8_t operator_id = 0;        // OperatorId wire value
  uint8_t basis_bits = 10;        // basis samples quantised to 2^(bits-1)-1 levels per sign
  uint8_t weight_bits = 8;        // DDL weights in units of 2^-weight_bits
  uint8_t weight_prediction = 1;  // WeightPrediction of the DDL weight coder
  uint32_t anchor_count = 0;
  double mean_step = 0.0;      // quantisation step of the mean trajectory
  double residual_step = 0.0;  // quantisation step of delta-trajectories
  double anchor_step = 0.0;    // quantisation step of anchor coefficients
  double anchor_weight = 1.0;  // weight of anchor rows in the normal equations
  // Not a header field: the stream's minor version (preamble, §4.1), which selects the syntax of
  // the segment's payloads. The decoder sets it from the preamble; encoders write kVersionMinor.
  uint8_t version_minor = kVersionMinor;
};

// Bits of a segment's chunks and of the whole stream, by syntax element (bytes incl. framing).
struct ChunkSizes {
  uint64_t header = 0;
  uint64_t connectivity = 0;
  uint64_t mean = 0;
  uint64_t basis = 0;
  uint64_t operator_info = 0;
  uint64_t anchors = 0;
  uint64_t residuals = 0;
  uint64_t scene = 0;  // the scene chunk (format 1.3), 0 without one
};

}  // namespace dmc::format
