#include "encoder/range_encoder.h"

#include <bit>

namespace dmc {

void RangeEncoder::EncodeBit(AdaptiveBit& model, int bit) {
  const uint32_t bound = (range_ >> 16) * model.p0();
  if (bit == 0) {
    range_ = bound;
  } else {
    low_ += bound;
    range_ -= bound;
  }
  model.Update(bit);
  Normalize();
}

void RangeEncoder::EncodeBypass(int bit) {
  range_ >>= 1;
  if (bit) low_ += range_;
  Normalize();
}

void RangeEncoder::EncodeBypassBits(uint64_t value, int count) {
  for (int i = count - 1; i >= 0; --i) EncodeBypass(static_cast<int>((value >> i) & 1));
}

void RangeEncoder::EncodeMagnitude(IntegerContexts& contexts, uint64_t m) {
  for (int i = 0; i < IntegerContexts::kUnaryLength; ++i) {
    const int greater = m > static_cast<uint64_t>(i) ? 1 : 0;
    EncodeBit(contexts.greater[i], greater);
    if (!greater) return;
  }
  const uint64_t e_plus_1 = m - IntegerContexts::kUnaryLength + 1;
  const int n = std::bit_width(e_plus_1) - 1;
  for (int k = 0; k < n; ++k) {
    EncodeBit(contexts.escape[std::min(k, IntegerContexts::kEscapeContexts - 1)], 1);
  }
  EncodeBit(contexts.escape[std::min(n, IntegerContexts::kEscapeContexts - 1)], 0);
  EncodeBypassBits(e_plus_1, n);  // the n bits below the leading one
}

void RangeEncoder::EncodeUnsigned(IntegerContexts& contexts, uint64_t value) {
  EncodeBit(contexts.zero, value == 0 ? 1 : 0);
  if (value != 0) EncodeMagnitude(contexts, value - 1);
}

void RangeEncoder::EncodeSigned(IntegerContexts& contexts, int64_t value) {
  EncodeBit(contexts.zero, value == 0 ? 1 : 0);
  if (value == 0) return;
  EncodeBit(contexts.sign, value < 0 ? 1 : 0);
  const uint64_t magnitude = value < 0 ? static_cast<uint64_t>(-(value + 1)) + 1 : value;
  EncodeMagnitude(contexts, magnitude - 1);
}

void RangeEncoder::ShiftLow() {
  if (static_cast<uint32_t>(low_) < 0xFF000000u || (low_ >> 32) != 0) {
    const uint8_t carry = static_cast<uint8_t>(low_ >> 32);
    uint8_t pending = cache_;
    do {
      out_.push_back(static_cast<uint8_t>(pending + carry));
      pending = 0xFF;
    } while (--cache_size_ != 0);
    cache_ = static_cast<uint8_t>(low_ >> 24);
  }
  ++cache_size_;
  low_ = (low_ & 0x00FFFFFFu) << 8;
}

std::vector<uint8_t> RangeEncoder::Finish() {
  for (int i = 0; i < 5; ++i) ShiftLow();
  return std::move(out_);
}

}  // namespace dmc
