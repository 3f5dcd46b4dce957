// Dense indices for keys in order of first appearance in a sequence cut into chunks, with
// most of the work per chunk (in parallel): each chunk first numbers its own distinct keys
// (local()), then number() gives them global indices chunk by chunk. The serial part runs
// once per distinct key of a chunk instead of once per element, and the indices are the
// ones a serial walk over the whole sequence would give (a key first appears in the first
// chunk that holds it, at that chunk's first occurrence).
#pragma once
#include <cstdint>
#include <vector>

#include "sim/core/block_hash.h"

namespace shellmpm {

class ChunkedKeys {
 public:
  /// Makes room for `chunks` chunks (kept between uses).
  void resize(std::size_t chunks) {
    if (chunks_.size() < chunks) chunks_.resize(chunks);
    used_ = chunks;
  }
  /// Forgets chunk c's keys; call before its first local().
  void begin_chunk(std::size_t c) {
    Chunk& ch = chunks_[c];
    ch.hash.clear();
    ch.keys.clear();
  }
  /// Chunk c's own index of `key` (0, 1, ... by first appearance in the chunk).
  int local(std::size_t c, std::uint64_t key) {
    Chunk& ch = chunks_[c];
    const int id = ch.hash.insert(key);
    if (static_cast<std::size_t>(id) == ch.keys.size()) ch.keys.push_back(key);
    return id;
  }
  /// Number of distinct keys of chunk c.
  std::size_t distinct(std::size_t c) const { return chunks_[c].keys.size(); }
  /// Numbers the chunks' keys, in chunk order, in `global` (cleared by the caller or
  /// holding earlier keys); keys new to it are appended to `keys`.
  void number(BlockHash& global, std::vector<std::uint64_t>& keys) {
    for (std::size_t c = 0; c < used_; ++c) {
      Chunk& ch = chunks_[c];
      ch.global.resize(ch.keys.size());
      for (std::size_t i = 0; i < ch.keys.size(); ++i) {
        const int id = global.insert(ch.keys[i]);
        if (static_cast<std::size_t>(id) == keys.size()) keys.push_back(ch.keys[i]);
        ch.global[i] = id;
      }
    }
  }
  /// Global index of chunk c's local key i (after number()).
  int global(std::size_t c, int i) const { return chunks_[c].global[static_cast<std::size_t>(i)]; }
  /// Bytes held.
  std::size_t bytes() const {
    std::size_t b = chunks_.capacity() * sizeof(Chunk);
    for (const Chunk& ch : chunks_)
      b += ch.hash.bytes() + ch.keys.capacity() * 8 + ch.global.capacity() * 4;
    return b;
  }

 private:
  struct Chunk {
    BlockHash hash;
    std::vector<std::uint64_t> keys;
    std::vector<int> global;
  };
  std::vector<Chunk> chunks_;
  std::size_t used_ = 0;
};

}  // namespace shellmpm
