#include "decoder/range_decoder.h"

#include <algorithm>
#include <string>

namespace dmc {

Status RangeDecoder::Init(std::span<const uint8_t> data) {
  data_ = data;
  position_ = 0;
  range_ = 0xFFFFFFFFu;
  code_ = 0;
  overrun_ = false;
  error_ = Status::Ok();
  if (data.size() < 5) {
    return TruncatedStreamError("range-coded payload has " + std::to_string(data.size()) +
                                " byte(s), at least 5 are needed");
  }
  if (NextByte() != 0) return CorruptStreamError("range-coded payload does not start with 0");
  for (int i = 0; i < 4; ++i) code_ = (code_ << 8) | NextByte();
  return Status::Ok();
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

bool RangeDecoder::TryDecodeEscape(IntegerContexts& contexts, uint64_t* m) {
  int n = 0;
  while (DecodeBit(contexts.escape[std::min(n, IntegerContexts::kEscapeContexts - 1)])) {
    if (++n > IntegerContexts::kMaxEscapeBits) {
      return Fail(CorruptStreamError("exp-Golomb escape longer than " +
                                     std::to_string(IntegerContexts::kMaxEscapeBits) + " bits"));
    }
    if (overrun_) {
      return Fail(TruncatedStreamError("range-coded payload ended inside an escape code"));
    }
  }
  const uint64_t e_plus_1 = (uint64_t{1} << n) | DecodeBypassBits(n);
  *m = e_plus_1 - 1 + IntegerContexts::kUnaryLength;
  return true;
}

Status RangeDecoder::DecodeUnsigned(IntegerContexts& contexts, uint64_t* value) {
  if (DecodeBit(contexts.zero)) {
    *value = 0;
    return Status::Ok();
  }
  uint64_t m;
  if (!TryDecodeMagnitude(contexts, &m)) return error_;
  *value = m + 1;
  return Status::Ok();
}

Status RangeDecoder::CheckNotOverrun(const char* what) const {
  if (overrun_) return TruncatedStreamError(std::string(what) + ": range-coded payload truncated");
  return Status::Ok();
}

}  // namespace dmc
