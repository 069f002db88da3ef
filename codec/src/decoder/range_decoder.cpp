#include "decoder/range_decoder.h"

#include <string>

namespace dmc {

Status RangeDecoder::Init(std::span<const uint8_t> data) {
  data_ = data;
  position_ = 0;
  range_ = 0xFFFFFFFFu;
  code_ = 0;
  overrun_ = false;
  if (data.size() < 5) {
    return TruncatedStreamError("range-coded payload has " + std::to_string(data.size()) +
                                " byte(s), at least 5 are needed");
  }
  if (NextByte() != 0) return CorruptStreamError("range-coded payload does not start with 0");
  for (int i = 0; i < 4; ++i) code_ = (code_ << 8) | NextByte();
  return Status::Ok();
}

int RangeDecoder::DecodeBit(AdaptiveBit& model) {
  const uint32_t bound = (range_ >> 16) * model.p0();
  int bit;
  if (code_ < bound) {
    range_ = bound;
    bit = 0;
  } else {
    code_ -= bound;
    range_ -= bound;
    bit = 1;
  }
  model.Update(bit);
  Normalize();
  return bit;
}

int RangeDecoder::DecodeBypass() {
  range_ >>= 1;
  int bit = 0;
  if (code_ >= range_) {
    code_ -= range_;
    bit = 1;
  }
  Normalize();
  return bit;
}

uint64_t RangeDecoder::DecodeBypassBits(int count) {
  uint64_t value = 0;
  for (int i = 0; i < count; ++i) value = (value << 1) | static_cast<uint64_t>(DecodeBypass());
  return value;
}

Status RangeDecoder::DecodeMagnitude(IntegerContexts& contexts, uint64_t* m) {
  for (int i = 0; i < IntegerContexts::kUnaryLength; ++i) {
    if (!DecodeBit(contexts.greater[i])) {
      *m = static_cast<uint64_t>(i);
      return Status::Ok();
    }
  }
  int n = 0;
  while (DecodeBit(contexts.escape[std::min(n, IntegerContexts::kEscapeContexts - 1)])) {
    if (++n > IntegerContexts::kMaxEscapeBits) {
      return CorruptStreamError("exp-Golomb escape longer than " +
                                std::to_string(IntegerContexts::kMaxEscapeBits) + " bits");
    }
    if (overrun_) return TruncatedStreamError("range-coded payload ended inside an escape code");
  }
  const uint64_t e_plus_1 = (uint64_t{1} << n) | DecodeBypassBits(n);
  *m = e_plus_1 - 1 + IntegerContexts::kUnaryLength;
  return Status::Ok();
}

Status RangeDecoder::DecodeUnsigned(IntegerContexts& contexts, uint64_t* value) {
  if (DecodeBit(contexts.zero)) {
    *value = 0;
    return Status::Ok();
  }
  uint64_t m;
  DMC_RETURN_IF_ERROR(DecodeMagnitude(contexts, &m));
  *value = m + 1;
  return Status::Ok();
}

Status RangeDecoder::DecodeSigned(IntegerContexts& contexts, int64_t* value) {
  if (DecodeBit(contexts.zero)) {
    *value = 0;
    return Status::Ok();
  }
  const int negative = DecodeBit(contexts.sign);
  uint64_t m;
  DMC_RETURN_IF_ERROR(DecodeMagnitude(contexts, &m));
  if (m >= (uint64_t{1} << 62)) return CorruptStreamError("coded integer exceeds 2^62");
  *value = negative ? -static_cast<int64_t>(m + 1) : static_cast<int64_t>(m + 1);
  return Status::Ok();
}

Status RangeDecoder::CheckNotOverrun(const char* what) const {
  if (overrun_) return TruncatedStreamError(std::string(what) + ": range-coded payload truncated");
  return Status::Ok();
}

}  // namespace dmc
