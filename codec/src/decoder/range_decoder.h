// Binary range decoder, the exact mirror of RangeEncoder. Safe on untrusted input: reading past
// the end yields zero bytes and sets overrun(), which callers turn into kTruncatedStream; malformed
// escape codes become kCorruptStream.
#pragma once

#include <cstdint>
#include <span>

#include "dmc/status.h"
#include "entropy/adaptive_bit.h"

namespace dmc {

class RangeDecoder {
 public:
  // Fails with kCorruptStream if the first byte is not 0 (every valid coder output starts with 0)
  // and kTruncatedStream if fewer than 5 bytes are given.
  Status Init(std::span<const uint8_t> data);

  int DecodeBit(AdaptiveBit& model);
  int DecodeBypass();
  uint64_t DecodeBypassBits(int count);

  Status DecodeUnsigned(IntegerContexts& contexts, uint64_t* value);
  Status DecodeSigned(IntegerContexts& contexts, int64_t* value);

  // True once the decoder needed bytes beyond its input.
  bool overrun() const { return overrun_; }
  // kTruncatedStream naming `what` if the decoder ran past its input, OK otherwise.
  Status CheckNotOverrun(const char* what) const;

 private:
  Status DecodeMagnitude(IntegerContexts& contexts, uint64_t* m);
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
};

}  // namespace dmc
