// Binary range decoder, the exact mirror of RangeEncoder. Safe on untrusted input: reading past
// the end yields zero bytes and sets overrun(), which callers turn into kTruncatedStream; malformed
// escape codes become kCorruptStream.
//
// The per-bit and per-integer paths are inline and Status-free (TryDecodeSigned), because the
// residual loop decodes V × r integers: a function call and a Status per symbol cost as much as
// the arithmetic decoding itself. Only the rare exp-Golomb escape is out of line.
#pragma once

#include <cstdint>
#include <span>
#include <utility>

#include "dmc/status.h"
#include "entropy/adaptive_bit.h"

namespace dmc {

class RangeDecoder {
 public:
  // Fails with kCorruptStream if the first byte is not 0 (every valid coder output starts with 0)
  // and kTruncatedStream if fewer than 5 bytes are given.
  Status Init(std::span<const uint8_t> data);

  int DecodeBit(AdaptiveBit& model) {
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
  int DecodeBypass();
  uint64_t DecodeBypassBits(int count);

  Status DecodeUnsigned(IntegerContexts& contexts, uint64_t* value);
  Status DecodeSigned(IntegerContexts& contexts, int64_t* value) {
    return TryDecodeSigned(contexts, value) ? Status::Ok() : error_;
  }

  // DecodeSigned without a Status per call: false when the integer is malformed, with the reason
  // in error(). The bits consumed are exactly DecodeSigned's.
  bool TryDecodeSigned(IntegerContexts& contexts, int64_t* value) {
    if (DecodeBit(contexts.zero)) {
      *value = 0;
      return true;
    }
    const int negative = DecodeBit(contexts.sign);
    uint64_t m = 0;
    if (!TryDecodeMagnitude(contexts, &m)) return false;
    if (m >= (uint64_t{1} << 62)) return Fail(CorruptStreamError("coded integer exceeds 2^62"));
    *value = negative ? -static_cast<int64_t>(m + 1) : static_cast<int64_t>(m + 1);
    return true;
  }
  // Why the last Try* call failed.
  const Status& error() const { return error_; }

  // True once the decoder needed bytes beyond its input.
  bool overrun() const { return overrun_; }
  // kTruncatedStream naming `what` if the decoder ran past its input, OK otherwise.
  Status CheckNotOverrun(const char* what) const;

 private:
  // m = |s| - 1 (or u - 1): unary flags, then the exp-Golomb escape (out of line).
  bool TryDecodeMagnitude(IntegerContexts& contexts, uint64_t* m) {
    for (int i = 0; i < IntegerContexts::kUnaryLength; ++i) {
      if (!DecodeBit(contexts.greater[i])) {
        *m = static_cast<uint64_t>(i);
        return true;
      }
    }
    return TryDecodeEscape(contexts, m);
  }
  bool TryDecodeEscape(IntegerContexts& contexts, uint64_t* m);
  bool Fail(Status status) {
    error_ = std::move(status);
    return false;
  }
  uint8_t NextByte() {
    if (position_ < data_.size()) return data_[position_++];
    overrun_ = true;
    return 0;
  }
  void Normalize() {
    while (range_ < (1u << 24)) {
      range_ <<= 8;
      code_ = (code_ << 8) | NextByte();
    }
  }

  std::span<const uint8_t> data_;
  size_t position_ = 0;
  uint32_t range_ = 0xFFFFFFFFu;
  uint32_t code_ = 0;
  bool overrun_ = false;
  Status error_;
};

}  // namespace dmc
