// What coding a value would cost, in bits, under the current state of adaptive models, without
// coding it or updating them: the encoder's rate estimates (rate–distortion optimised
// quantisation). The binarisation is the one of entropy/adaptive_bit.h (IntegerContexts).
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>

#include "entropy/adaptive_bit.h"

namespace dmc {

// −log2 P(bit) under the model, from a 4096-entry table of −log2(p / 65536).
inline double BitCost(const AdaptiveBit& model, int bit) {
  static const std::array<float, 4097> kCost = [] {
    std::array<float, 4097> table{};
    for (int i = 0; i <= 4096; ++i) {
      table[i] = static_cast<float>(-std::log2(std::max(i, 1) / 4096.0));
    }
    return table;
  }();
  const uint32_t p0 = model.p0();
  const uint32_t p = bit == 0 ? p0 : 65536u - p0;
  return kCost[p >> 4];
}

inline double MagnitudeCost(const IntegerContexts& contexts, uint64_t m) {
  double bits = 0.0;
  for (int i = 0; i < IntegerContexts::kUnaryLength; ++i) {
    const int greater = m > static_cast<uint64_t>(i) ? 1 : 0;
    bits += BitCost(contexts.greater[i], greater);
    if (!greater) return bits;
  }
  const uint64_t e_plus_1 = m - IntegerContexts::kUnaryLength + 1;
  const int n = std::bit_width(e_plus_1) - 1;
  for (int k = 0; k < n; ++k) {
    bits += BitCost(contexts.escape[std::min(k, IntegerContexts::kEscapeContexts - 1)], 1);
  }
  bits += BitCost(contexts.escape[std::min(n, IntegerContexts::kEscapeContexts - 1)], 0);
  return bits + n;
}

// The bits of RangeEncoder::EncodeSigned(contexts, value).
inline double SignedCost(const IntegerContexts& contexts, int64_t value) {
  double bits = BitCost(contexts.zero, value == 0 ? 1 : 0);
  if (value == 0) return bits;
  bits += BitCost(contexts.sign, value < 0 ? 1 : 0);
  const uint64_t magnitude = value < 0 ? static_cast<uint64_t>(-(value + 1)) + 1 : value;
  return bits + MagnitudeCost(contexts, magnitude - 1);
}

// Rate–distortion optimised rounding of `steps` (a value in quantisation steps): the nearest
// level, or the next one toward zero when that has the lower squared error (in steps²) plus
// `lambda` times its bits under the current contexts. lambda = 0 is plain rounding (halves away
// from zero, as std::llround). Greedy: the choice's effect on later symbols' contexts is ignored.
inline int64_t RdoLevel(double steps, const IntegerContexts& contexts, double lambda) {
  const int64_t nearest = std::llround(steps);
  if (lambda <= 0.0 || nearest == 0) return nearest;
  const int64_t lower = nearest > 0 ? nearest - 1 : nearest + 1;
  const double error_nearest = steps - static_cast<double>(nearest);
  const double error_lower = steps - static_cast<double>(lower);
  const double cost_nearest =
      error_nearest * error_nearest + lambda * SignedCost(contexts, nearest);
  const double cost_lower = error_lower * error_lower + lambda * SignedCost(contexts, lower);
  return cost_lower < cost_nearest ? lower : nearest;
}

}  // namespace dmc
