// Parsing of chunk payloads (the mirror of encoder/syntax_writer.h). Every function validates
// what it reads against the limits in bitstream/format.h and the already decoded headers.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "bitstream/format.h"
#include "decoder/segment_reconstruction.h"
#include "dmc/sequence.h"
#include "dmc/status.h"
#include "dmc/topology.h"

namespace dmc::syntax {

StatusOr<format::SequenceHeader> ReadSequenceHeader(std::span<const uint8_t> payload);

// The scene chunk (format 1.3, spec §6.3): its fields checked; `data` views the payload's bytes
// after them (stored or zstd-compressed).
struct SceneHeader {
  uint8_t kind = 0;
  uint8_t compression = 0;
  uint64_t size = 0;  // bytes of the scene once decompressed
  std::span<const uint8_t> data;
};
StatusOr<SceneHeader> ReadSceneHeader(std::span<const uint8_t> payload);
// The scene's bytes: exactly `header.size` of them (a stored payload of another length, or zstd
// data that is not one frame decompressing to that size, is corrupt-stream).
StatusOr<std::vector<uint8_t>> ReadScene(const SceneHeader& header);
// `frames_left`: frames of the sequence not yet covered by earlier segments. `version_minor`, the
// stream's (preamble), is kept in the header: the payload readers below follow its syntax.
StatusOr<format::SegmentHeader> ReadSegmentHeader(std::span<const uint8_t> payload,
                                                  uint32_t expected_first_frame,
                                                  uint32_t frames_left, uint32_t vertex_count,
                                                  uint8_t version_minor = format::kVersionMinor);
// corrupt-stream unless each of the segment's range-coded payloads (given by their byte sizes) can
// hold the fewest decisions its header makes it code (spec §8.7): 3·F' for the mean, r·(1 + 3·F')
// for the basis, 3·V for a reference frame, A·(1 + r) for the anchors, V·r for the residuals.
// Needs only the headers, so it runs before the connectivity is decoded.
struct SegmentPayloadSizes {
  uint64_t mean = 0, basis = 0, operator_info = 0, anchors = 0, residuals = 0;
};
Status CheckPayloadCapacity(const format::SegmentHeader& header, uint32_t vertex_count,
                            const SegmentPayloadSizes& sizes);

Status ReadMean(std::span<const uint8_t> payload, SegmentSyntax& syntax);
// ReadBasis: decoder/basis_reader.h.
Status ReadOperator(std::span<const uint8_t> payload, const MeshTopology& topology,
                    SegmentSyntax& syntax);
Status ReadAnchors(std::span<const uint8_t> payload, int vertex_count, SegmentSyntax& syntax);
Status ReadResiduals(std::span<const uint8_t> payload, const MeshTopology& topology,
                     const std::vector<int32_t>& vertex_order, SegmentSyntax& syntax);

}  // namespace dmc::syntax
