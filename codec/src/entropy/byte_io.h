// Little-endian byte writing and bounds-checked reading, with LEB128 varints.
//
// ByteReader never reads past its span: every accessor returns kTruncatedStream naming the field
// when the bytes run out, so decoders built on it are safe on untrusted input.
#pragma once

#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dmc/status.h"

namespace dmc {

// Zig-zag mapping of signed to unsigned values, small magnitudes first:
// 0, -1, 1, -2, 2, ... -> 0, 1, 2, 3, 4, ...
constexpr uint64_t ZigZagEncode(int64_t value) {
  return (static_cast<uint64_t>(value) << 1) ^ static_cast<uint64_t>(value >> 63);
}
constexpr int64_t ZigZagDecode(uint64_t value) {
  return static_cast<int64_t>(value >> 1) ^ -static_cast<int64_t>(value & 1);
}

class ByteWriter {
 public:
  void PutU8(uint8_t value) { bytes_.push_back(value); }
  void PutU32(uint32_t value) { PutLittleEndian(value, 4); }
  void PutU64(uint64_t value) { PutLittleEndian(value, 8); }
  void PutF64(double value) {
    uint64_t bits;
    std::memcpy(&bits, &value, 8);
    PutU64(bits);
  }
  // Unsigned LEB128: 7 bits per byte, low groups first, high bit = more bytes follow.
  void PutVarU(uint64_t value) {
    while (value >= 0x80) {
      bytes_.push_back(static_cast<uint8_t>(value | 0x80));
      value >>= 7;
    }
    bytes_.push_back(static_cast<uint8_t>(value));
  }
  // Signed values are zig-zag mapped, then PutVarU.
  void PutVarS(int64_t value) { PutVarU(ZigZagEncode(value)); }
  void PutBytes(std::span<const uint8_t> data) {
    bytes_.insert(bytes_.end(), data.begin(), data.end());
  }
  void PutString(std::string_view text) {
    PutVarU(text.size());
    bytes_.insert(bytes_.end(), text.begin(), text.end());
  }

  size_t size() const { return bytes_.size(); }
  const std::vector<uint8_t>& bytes() const { return bytes_; }
  std::vector<uint8_t> Take() { return std::move(bytes_); }

 private:
  void PutLittleEndian(uint64_t value, int count) {
    for (int i = 0; i < count; ++i) bytes_.push_back(static_cast<uint8_t>(value >> (8 * i)));
  }
  std::vector<uint8_t> bytes_;
};

class ByteReader {
 public:
  explicit ByteReader(std::span<const uint8_t> data) : data_(data) {}

  size_t position() const { return position_; }
  size_t remaining() const { return data_.size() - position_; }
  bool at_end() const { return position_ == data_.size(); }

  Status GetU8(uint8_t* value, std::string_view field) {
    DMC_RETURN_IF_ERROR(Require(1, field));
    *value = data_[position_++];
    return Status::Ok();
  }
  Status GetU32(uint32_t* value, std::string_view field) { return GetLE(value, 4, field); }
  Status GetU64(uint64_t* value, std::string_view field) { return GetLE(value, 8, field); }
  Status GetF64(double* value, std::string_view field) {
    uint64_t bits = 0;
    DMC_RETURN_IF_ERROR(GetU64(&bits, field));
    std::memcpy(value, &bits, 8);
    return Status::Ok();
  }
  Status GetVarU(uint64_t* value, std::string_view field) {
    uint64_t result = 0;
    for (int shift = 0; shift < 64; shift += 7) {
      uint8_t byte;
      DMC_RETURN_IF_ERROR(GetU8(&byte, field));
      if (shift == 63 && byte > 1) break;  // would overflow 64 bits
      result |= static_cast<uint64_t>(byte & 0x7f) << shift;
      if ((byte & 0x80) == 0) {
        *value = result;
        return Status::Ok();
      }
    }
    return CorruptStreamError(std::string(field) + ": varint longer than 64 bits");
  }
  Status GetVarS(int64_t* value, std::string_view field) {
    uint64_t raw;
    DMC_RETURN_IF_ERROR(GetVarU(&raw, field));
    *value = ZigZagDecode(raw);
    return Status::Ok();
  }
  // Reads a varint and checks it lies in [min_value, max_value].
  Status GetVarURange(uint64_t* value, uint64_t min_value, uint64_t max_value,
                      std::string_view field) {
    DMC_RETURN_IF_ERROR(GetVarU(value, field));
    if (*value < min_value || *value > max_value) {
      return CorruptStreamError(std::string(field) + " = " + std::to_string(*value) +
                                " is outside [" + std::to_string(min_value) + ", " +
                                std::to_string(max_value) + "]");
    }
    return Status::Ok();
  }
  Status GetBytes(size_t count, std::span<const uint8_t>* out, std::string_view field) {
    DMC_RETURN_IF_ERROR(Require(count, field));
    *out = data_.subspan(position_, count);
    position_ += count;
    return Status::Ok();
  }
  Status GetString(std::string* text, size_t max_length, std::string_view field) {
    uint64_t length;
    DMC_RETURN_IF_ERROR(GetVarURange(&length, 0, max_length, field));
    std::span<const uint8_t> raw;
    DMC_RETURN_IF_ERROR(GetBytes(length, &raw, field));
    text->assign(raw.begin(), raw.end());
    return Status::Ok();
  }

 private:
  Status Require(size_t count, std::string_view field) const {
    if (remaining() < count) {
      return TruncatedStreamError(std::string(field) + ": needs " + std::to_string(count) +
                                  " byte(s) at offset " + std::to_string(position_) + ", only " +
                                  std::to_string(remaining()) + " left");
    }
    return Status::Ok();
  }
  template <typename T>
  Status GetLE(T* value, int count, std::string_view field) {
    DMC_RETURN_IF_ERROR(Require(count, field));
    uint64_t result = 0;
    for (int i = 0; i < count; ++i)
      result |= static_cast<uint64_t>(data_[position_ + i]) << (8 * i);
    position_ += count;
    *value = static_cast<T>(result);
    return Status::Ok();
  }

  std::span<const uint8_t> data_;
  size_t position_ = 0;
};

}  // namespace dmc
