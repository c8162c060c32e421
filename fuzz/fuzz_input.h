// Turning the fuzzer's bytes into doubles that cover the hard ranges: any bit pattern (NaN,
// infinities, subnormals), or a sign, a decade between 1e-300 and 1e300 and a mantissa.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace collision_response::fuzz {

class FuzzInput {
 public:
  FuzzInput(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  std::uint8_t byte() { return position_ < size_ ? data_[position_++] : 0; }

  double number() {
    const std::uint8_t kind = byte();
    if (kind < 16) {  // raw bits: NaN, inf, subnormal, anything
      std::uint64_t bits = 0;
      for (int i = 0; i < 8; ++i) bits = (bits << 8) | byte();
      double value;
      std::memcpy(&value, &bits, sizeof value);
      return value;
    }
    if (kind < 48) return static_cast<double>(static_cast<int>(byte()) - 128) / 16.0;  // small
    const double mantissa = 1.0 + byte() / 256.0 + byte() / 65536.0;
    const int decade = static_cast<int>(byte() % 121) - 60;  // 1e-300 .. 1e300 in steps of 1e5
    return ((kind & 1) ? -1.0 : 1.0) * mantissa * std::pow(10.0, 5.0 * decade);
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t position_ = 0;
};

}  // namespace collision_response::fuzz
