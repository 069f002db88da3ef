// Binary range encoder (LZMA-style carry-propagating range coder with 16-bit probabilities).
// The exact arithmetic is normative: see bitstream-spec/dmc-format.md §5.1 and §5.4, and
// codec/src/decoder/range_decoder.h for the mirror.
#pragma once

#include <cstdint>
#include <vector>

#include "entropy/adaptive_bit.h"

namespace dmc {

class RangeEncoder {
 public:
  void EncodeBit(AdaptiveBit& model, int bit);
  // A bit with fixed probability 1/2 (no model).
  void EncodeBypass(int bit);
  void EncodeBypassBits(uint64_t value, int count);  // most significant first

  void EncodeUnsigned(IntegerContexts& contexts, uint64_t value);
  void EncodeSigned(IntegerContexts& contexts, int64_t value);

  // Flushes the coder state; the result is the complete coded byte string.
  std::vector<uint8_t> Finish();

 private:
  void EncodeMagnitude(IntegerContexts& contexts, uint64_t m);
  void ShiftLow();
  void Normalize() {
    while (range_ < (1u << 24)) {
      range_ <<= 8;
      ShiftLow();
    }
  }

  uint64_t low_ = 0;
  uint32_t range_ = 0xFFFFFFFFu;
  uint8_t cache_ = 0;
  uint64_t cache_size_ = 1;
  std::vector<uint8_t> out_;
};

}  // namespace dmc
