#include "decoder/basis_reader.h"

#include <memory>
#include <string>
#include <vector>

#include "bitstream/syntax.h"
#include "decoder/range_decoder.h"

namespace dmc::syntax {

namespace {

Status SampleOutOfRange(int k, int f) {
  return CorruptStreamError("basis vector " + std::to_string(k) + " sample " + std::to_string(f) +
                            " exceeds its quantiser range");
}

// Format 1.0: every column at header.basis_bits, one first/second-order decision per column.
Status ReadBasis10(RangeDecoder& decoder, SegmentSyntax& syntax) {
  const int frames = static_cast<int>(syntax.header.frame_count);
  const int rank = static_cast<int>(syntax.header.rank);
  const int64_t levels = (int64_t{1} << (syntax.header.basis_bits - 1)) - 1;
  auto contexts = std::make_unique<format::BasisContexts>();
  std::vector<int64_t> q(frames);
  for (int k = 0; k < rank; ++k) {
    const int g = std::min(k, format::kBasisColumnGroups - 1);
    const bool second_order = decoder.DecodeBit(contexts->second_order[g]) != 0;
    for (int axis = 0; axis < 3; ++axis) {
      for (int f = 0; f < frames; ++f) {
        int64_t prediction = 0;
        if (f == 1 || (f >= 2 && !second_order)) prediction = q[f - 1];
        if (f >= 2 && second_order) prediction = 2 * q[f - 1] - q[f - 2];
        int64_t d = 0;
        DMC_RETURN_IF_ERROR(
            decoder.DecodeSigned(f == 0 ? contexts->first[g] : contexts->delta[g], &d));
        q[f] = prediction + d;
        if (q[f] > levels || q[f] < -levels) return SampleOutOfRange(k, f);
        syntax.basis(3 * f + axis, k) = static_cast<double>(q[f]) / static_cast<double>(levels);
      }
    }
  }
  return Status::Ok();
}

// Format 1.1: per column a bit depth (a signed difference from the previous column's, the first
// from the header's basis_bits), a predictor mode, then the samples.
Status ReadBasis11(RangeDecoder& decoder, SegmentSyntax& syntax) {
  const int frames = static_cast<int>(syntax.header.frame_count);
  const int rank = static_cast<int>(syntax.header.rank);
  const int max_depth = syntax.header.basis_bits;
  auto contexts = std::make_unique<format::BasisContexts>();
  std::vector<int64_t> q(frames);
  int depth = max_depth;
  for (int k = 0; k < rank; ++k) {
    int64_t change = 0;
    DMC_RETURN_IF_ERROR(decoder.DecodeSigned(contexts->depth, &change));
    if (change < format::kMinBasisBits - depth || change > max_depth - depth) {
      return CorruptStreamError("basis vector " + std::to_string(k) + " bit depth " +
                                std::to_string(depth + change) + " is outside [" +
                                std::to_string(format::kMinBasisBits) + ", " +
                                std::to_string(max_depth) + "]");
    }
    depth += static_cast<int>(change);
    const int g = format::BasisContextGroup(k, depth);
    const int64_t levels = (int64_t{1} << (depth - 1)) - 1;
    const int high = decoder.DecodeBit(contexts->predictor_high[g]);
    const int mode = 2 * high + decoder.DecodeBit(contexts->predictor_low[g][high]);
    for (int axis = 0; axis < 3; ++axis) {
      for (int f = 0; f < frames; ++f) {
        const int64_t prediction = format::PredictBasisSample(mode, q.data(), f);
        int64_t d = 0;
        DMC_RETURN_IF_ERROR(
            decoder.DecodeSigned(f == 0 ? contexts->first[g] : contexts->delta[g], &d));
        q[f] = prediction + d;
        if (q[f] > levels || q[f] < -levels) return SampleOutOfRange(k, f);
        syntax.basis(3 * f + axis, k) = static_cast<double>(q[f]) / static_cast<double>(levels);
      }
    }
  }
  return Status::Ok();
}

}  // namespace

Status ReadBasis(std::span<const uint8_t> payload, SegmentSyntax& syntax, int minor_version) {
  const int frames = static_cast<int>(syntax.header.frame_count);
  const int rank = static_cast<int>(syntax.header.rank);
  syntax.basis.resize(3 * frames, rank);
  if (rank == 0) return Status::Ok();
  RangeDecoder decoder;
  DMC_RETURN_IF_ERROR(decoder.Init(payload));
  if (minor_version >= 1) {
    // A payload that ran out reads as zeros: report the truncation, not the values it garbled.
    const Status status = ReadBasis11(decoder, syntax);
    if (!status.ok() && decoder.overrun()) return decoder.CheckNotOverrun("basis chunk");
    DMC_RETURN_IF_ERROR(status);
  } else {
    DMC_RETURN_IF_ERROR(ReadBasis10(decoder, syntax));
  }
  return decoder.CheckNotOverrun("basis chunk");
}

}  // namespace dmc::syntax
