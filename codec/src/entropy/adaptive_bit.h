// Adaptive binary probability models shared by the range encoder and decoder.
//
// Normative (bitstream spec §5.2): a model holds two 16-bit estimates of P(bit = 0),
// `fast` and `slow`, both starting at 32768, and an adaptation count starting at 0. The probability
// used to code a bit is p0 = (fast + slow) >> 1 (always within [15, 65521]). After coding a bit b,
// with shifts sf = min(1 + count, 4) and ss = min(1 + count, 7):
//   b = 0: fast += (65536 - fast) >> sf; slow += (65536 - slow) >> ss
//   b = 1: fast -= fast >> sf;           slow -= slow >> ss
// then count = min(count + 1, 6). The fast estimate tracks local statistics, the slow one the
// long-run average; early updates are large so a fresh context learns quickly.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>

namespace dmc {

struct AdaptiveBit {
  uint16_t fast = 32768;
  uint16_t slow = 32768;
  uint8_t count = 0;

  uint32_t p0() const { return (static_cast<uint32_t>(fast) + slow) >> 1; }

  void Update(int bit) {
    const int shift_fast = std::min(1 + count, 4);
    const int shift_slow = std::min(1 + count, 7);
    if (bit == 0) {
      fast = static_cast<uint16_t>(fast + ((65536u - fast) >> shift_fast));
      slow = static_cast<uint16_t>(slow + ((65536u - slow) >> shift_slow));
    } else {
      fast = static_cast<uint16_t>(fast - (fast >> shift_fast));
      slow = static_cast<uint16_t>(slow - (slow >> shift_slow));
    }
    count = static_cast<uint8_t>(std::min(count + 1, 6));
  }
};

// Binarisation of integers (normative):
//   unsigned u: zero flag (1 if u == 0, context `zero`); if u > 0, m = u - 1 is sent as
//   "m > i" flags for i = 0 .. kUnaryLength-1 (context greater[i]), stopping at the first 0;
//   if all are 1, e = m - kUnaryLength is sent as an order-0 exp-Golomb code: n = floor(log2(e+1))
//   as n one-bits and a zero-bit (context escape[min(k, kEscapeContexts-1)] for the k-th bit), then
//   the n low bits of e + 1, most significant first, as bypass bits. n > kMaxEscapeBits is corrupt.
//   signed s: zero flag as above; if s != 0, a sign bit (1 = negative, context `sign`) and then
//   |s| - 1 as m above.
struct IntegerContexts {
  static constexpr int kUnaryLength = 14;
  static constexpr int kEscapeContexts = 8;
  static constexpr int kMaxEscapeBits = 62;
  AdaptiveBit zero;
  AdaptiveBit sign;
  std::array<AdaptiveBit, kUnaryLength> greater;
  std::array<AdaptiveBit, kEscapeContexts> escape;
};

}  // namespace dmc
