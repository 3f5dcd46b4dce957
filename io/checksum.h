// CRC-32 (the IEEE 802.3 polynomial, reflected: 0xEDB88320; initial value and final
// xor 0xFFFFFFFF), the checksum that guards checkpoint files against damage. It finds
// every burst of errors up to 32 bits long and misses other damage with probability
// 2^-32.
#pragma once
#include <cstddef>
#include <cstdint>

namespace shellmpm {

/// Incremental CRC-32: update() with the bytes in order, then value().
class Crc32 {
 public:
  void update(const void* data, std::size_t size);
  std::uint32_t value() const { return ~state_; }

 private:
  std::uint32_t state_ = 0xFFFFFFFFu;
};

/// CRC-32 of `size` bytes; crc32("123456789", 9) == 0xCBF43926.
std::uint32_t crc32(const void* data, std::size_t size);

}  // namespace shellmpm
