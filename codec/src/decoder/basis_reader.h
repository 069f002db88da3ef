// Parsing of the basis chunk (spec §8.3; the mirror of encoder/basis_writer.h).
#pragma once

#include <cstdint>
#include <span>

#include "decoder/segment_reconstruction.h"
#include "dmc/status.h"

namespace dmc::syntax {

// Decodes the segment's basis (syntax.header's frame count, rank and basis bits) into
// syntax.basis, in the syntax of the stream's minor version: 0 = one bit depth for every column,
// >= 1 = a bit depth per column coded in the payload. corrupt-stream for a depth or a sample out
// of range, truncated-stream when the payload runs out.
Status ReadBasis(std::span<const uint8_t> payload, SegmentSyntax& syntax, int minor_version);

}  // namespace dmc::syntax
