#include "sim/mpm/particles.h"

#include <algorithm>
#include <cstring>

#include "sim/core/check.h"
#include "sim/core/parallel.h"

namespace shellmpm {
namespace {

// a[i] = a[order[i]] for every i, one word (4 or 2 bytes) of the element at a time, so the
// scratch is one word per particle, not one element (36 B for a Mat3): the reorder's
// transient memory stays at 4 B per particle.
template <class Word, class T>
void permute_words(std::vector<T>& a, const std::vector<std::uint32_t>& order,
                   std::vector<std::uint32_t>& scratch) {
  static_assert(sizeof(T) % sizeof(Word) == 0 && sizeof(Word) <= sizeof(std::uint32_t));
  constexpr std::size_t kWords = sizeof(T) / sizeof(Word);
  const std::size_t n = a.size();
  scratch.resize(n);
  auto* bytes = reinterpret_cast<unsigned char*>(a.data());
  for (std::size_t w = 0; w < kWords; ++w) {
    parallel_for(n, 8192, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        Word x;
        std::memcpy(&x, bytes + order[i] * sizeof(T) + w * sizeof(Word), sizeof(Word));
        scratch[i] = x;
      }
    });
    parallel_for(n, 8192, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        const Word x = static_cast<Word>(scratch[i]);
        std::memcpy(bytes + i * sizeof(T) + w * sizeof(Word), &x, sizeof(Word));
      }
    });
  }
}

template <class T>
void permute_one(std::vector<T>& a, const std::vector<std::uint32_t>& order,
                 std::vector<std::uint32_t>& scratch) {
  if (a.empty()) return;
  if constexpr (sizeof(T) % 4 == 0)
    permute_words<std::uint32_t>(a, order, scratch);
  else
    permute_words<std::uint16_t>(a, order, scratch);
}

}  // namespace

void ParticleSet::permute(const std::vector<std::uint32_t>& order) {
  SHELLMPM_CHECK(order.size() == size(), << order.size() << " vs " << size());
  std::vector<std::uint32_t> scratch;
  permute_one(x, order, scratch);
  permute_one(v, order, scratch);
  permute_one(C, order, scratch);
  permute_one(F, order, scratch);
  permute_one(volume, order, scratch);
  permute_one(material, order, scratch);
  permute_one(id, order, scratch);
  permute_one(plastic, order, scratch);
}

void ParticleSet::reserve_more(std::size_t n, bool exact) {
  const std::size_t need = size() + n;
  if (need <= x.capacity()) return;
  const std::size_t cap = exact ? need : std::max(need, size() + size() / 2);
  x.reserve(cap);
  v.reserve(cap);
  C.reserve(cap);
  F.reserve(cap);
  volume.reserve(cap);
  material.reserve(cap);
  id.reserve(cap);
  if (keep_plastic) plastic.reserve(cap);
}

std::size_t ParticleSet::bytes() const {
  return x.capacity() * sizeof(Vec3) + v.capacity() * sizeof(Vec3) + C.capacity() * sizeof(Mat3) +
         F.capacity() * sizeof(Mat3) + volume.capacity() * sizeof(Real) +
         material.capacity() * sizeof(std::uint16_t) + id.capacity() * sizeof(std::uint32_t) +
         plastic.capacity() * sizeof(Real);
}

}  // namespace shellmpm
