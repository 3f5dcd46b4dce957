// Open-addressing hash map from a packed block coordinate to a dense block index.
// Insertion order defines the index, so a serial fill in particle order is
// deterministic.
#pragma once
#include <cstdint>
#include <vector>

#include "sim/core/types.h"

namespace shellmpm {

/// Packs block coordinates (each in [0, 2^20)) into one key.
inline std::uint64_t pack_block(int bx, int by, int bz) {
  return (static_cast<std::uint64_t>(bx) << 40) | (static_cast<std::uint64_t>(by) << 20) |
         static_cast<std::uint64_t>(bz);
}
inline Vec3i unpack_block(std::uint64_t k) {
  return Vec3i(static_cast<int>(k >> 40), static_cast<int>((k >> 20) & 0xFFFFF),
               static_cast<int>(k & 0xFFFFF));
}

class BlockHash {
 public:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t(0);

  /// Removes all entries; keeps the capacity.
  void clear() {
    for (std::uint32_t s : used_) keys_[s] = kEmpty;
    used_.clear();
  }
  /// Index of `key`, or -1.
  int find(std::uint64_t key) const {
    if (keys_.empty()) return -1;
    for (std::size_t s = slot(key);; s = (s + 1) & mask_) {
      if (keys_[s] == key) return values_[s];
      if (keys_[s] == kEmpty) return -1;
    }
  }
  /// Index of `key`, inserting it with index size() when absent.
  int insert(std::uint64_t key) {
    if ((used_.size() + 1) * 2 > keys_.size()) grow();
    for (std::size_t s = slot(key);; s = (s + 1) & mask_) {
      if (keys_[s] == key) return values_[s];
      if (keys_[s] == kEmpty) {
        keys_[s] = key;
        values_[s] = static_cast<int>(used_.size());
        used_.push_back(static_cast<std::uint32_t>(s));
        return values_[s];
      }
    }
  }
  std::size_t size() const { return used_.size(); }
  std::size_t bytes() const { return keys_.capacity() * 12 + used_.capacity() * 4; }

 private:
  std::size_t slot(std::uint64_t k) const {
    k ^= k >> 29;
    k *= 0xbf58476d1ce4e5b9ULL;
    k ^= k >> 32;
    return static_cast<std::size_t>(k) & mask_;
  }
  void grow() {
    std::vector<std::uint64_t> old_keys;
    std::vector<int> old_values;
    std::vector<std::uint32_t> old_used;
    old_keys.swap(keys_);
    old_values.swap(values_);
    old_used.swap(used_);
    const std::size_t cap = old_keys.empty() ? 1024 : old_keys.size() * 2;
    keys_.assign(cap, kEmpty);
    values_.assign(cap, -1);
    mask_ = cap - 1;
    // Re-insert in index order so indices are preserved.
    std::vector<std::uint64_t> by_index(old_used.size());
    for (std::uint32_t s : old_used) by_index[old_values[s]] = old_keys[s];
    for (std::uint64_t k : by_index) insert(k);
  }

  std::vector<std::uint64_t> keys_;
  std::vector<int> values_;
  std::vector<std::uint32_t> used_;
  std::size_t mask_ = 0;
};

}  // namespace shellmpm
