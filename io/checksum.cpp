#include "io/checksum.h"

#include <array>

namespace shellmpm {
namespace {

/// Remainder of each byte value, shifted through the reflected polynomial bit by bit.
constexpr std::array<std::uint32_t, 256> make_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t b = 0; b < 256; ++b) {
    std::uint32_t r = b;
    for (int k = 0; k < 8; ++k) r = (r & 1u) ? (r >> 1) ^ 0xEDB88320u : r >> 1;
    t[b] = r;
  }
  return t;
}

constexpr std::array<std::uint32_t, 256> kTable = make_table();

}  // namespace

void Crc32::update(const void* data, std::size_t size) {
  const auto* p = static_cast<const unsigned char*>(data);
  std::uint32_t s = state_;
  for (std::size_t i = 0; i < size; ++i) s = kTable[(s ^ p[i]) & 0xFFu] ^ (s >> 8);
  state_ = s;
}

std::uint32_t crc32(const void* data, std::size_t size) {
  Crc32 c;
  c.update(data, size);
  return c.value();
}

}  // namespace shellmpm
