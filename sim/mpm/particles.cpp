#include "sim/mpm/particles.h"

#include <algorithm>
#include <cstring>

#include "sim/core/check.h"
#include "sim/core/parallel.h"

namespace shellmpm {
namespace {

template <class T>
void permute_one(std::vector<T>& a, const std::vector<std::uint32_t>& order,
                 std::vector<unsigned char>& scratch) {
  if (a.empty()) return;
  const std::size_t n = a.size();
  scratch.resize(n * sizeof(T));
  T* out = reinterpret_cast<T*>(scratch.data());
  parallel_for(n, 8192, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) out[i] = a[order[i]];
  });
  std::memcpy(static_cast<void*>(a.data()), out, n * sizeof(T));
}

}  // namespace

void ParticleSet::permute(const std::vector<std::uint32_t>& order) {
  SHELLMPM_CHECK(order.size() == size(), << order.size() << " vs " << size());
  std::vector<unsigned char> scratch;
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
