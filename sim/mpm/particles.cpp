#include "sim/mpm/particles.h"

#include <algorithm>
#include <cstring>

#include "sim/core/check.h"
#include "sim/core/parallel.h"

namespace shellmpm {
namespace {

// a[i] = a[order[i]] for every i, in place: each cycle of the permutation is followed once,
// holding one element aside, with a bit per particle marking the places already filled
// (`done`, cleared on return). No scratch copy of an attribute: the reorder's transient
// memory is the bit set. Serial; the reorder runs once per frame, and after a frame the
// order is close to the identity (most cycles are a single particle), so the walk reads
// memory almost in sequence.
template <class T>
void permute_in_place(std::vector<T>& a, const std::vector<std::uint32_t>& order,
                      std::vector<std::uint64_t>& done) {
  if (a.empty()) return;
  const std::size_t n = a.size();
  auto is_done = [&](std::size_t i) { return (done[i >> 6] >> (i & 63)) & 1; };
  auto mark = [&](std::size_t i) { done[i >> 6] |= std::uint64_t(1) << (i & 63); };
  for (std::size_t i = 0; i < n; ++i) {
    if (order[i] == i || is_done(i)) continue;
    T held = std::move(a[i]);
    std::size_t j = i;
    for (;;) {
      mark(j);
      const std::size_t k = order[j];
      if (k == i) {
        a[j] = std::move(held);
        break;
      }
      a[j] = std::move(a[k]);
      j = k;
    }
  }
  std::fill(done.begin(), done.end(), 0);
}

}  // namespace

void ParticleSet::permute(const std::vector<std::uint32_t>& order) {
  SHELLMPM_CHECK(order.size() == size(), << order.size() << " vs " << size());
  std::vector<std::uint64_t> done((size() + 63) / 64, 0);
  permute_in_place(x, order, done);
  permute_in_place(v, order, done);
  permute_in_place(C, order, done);
  permute_in_place(F, order, done);
  permute_in_place(kind, order, done);
  permute_in_place(id, order, done);
  permute_in_place(plastic, order, done);
}

void ParticleSet::reserve_more(std::size_t n, bool exact) {
  const std::size_t need = size() + n;
  if (need <= x.capacity()) return;
  const std::size_t cap = exact ? need : std::max(need, size() + size() / 2);
  x.reserve(cap);
  v.reserve(cap);
  C.reserve(cap);
  F.reserve(cap);
  kind.reserve(cap);
  id.reserve(cap);
  if (keep_plastic) plastic.reserve(cap);
}

std::uint16_t ParticleSet::kind_of(std::uint16_t mat, Real vol) {
  // The last particle's kind first: sources add their particles together.
  if (!kind.empty() && kind_material[kind.back()] == mat && kind_volume[kind.back()] == vol)
    return kind.back();
  for (std::size_t k = 0; k < kind_material.size(); ++k)
    if (kind_material[k] == mat && kind_volume[k] == vol) return static_cast<std::uint16_t>(k);
  SHELLMPM_CHECK(kind_material.size() < 65536,
                 << "more than 65,536 particle kinds (material and rest volume pairs)");
  kind_material.push_back(mat);
  kind_volume.push_back(vol);
  return static_cast<std::uint16_t>(kind_material.size() - 1);
}

std::size_t ParticleSet::bytes() const {
  return x.capacity() * sizeof(Vec3) + v.capacity() * sizeof(Vec3) + C.capacity() * sizeof(Mat3) +
         F.capacity() * sizeof(Mat3) + kind.capacity() * sizeof(std::uint16_t) +
         id.capacity() * sizeof(std::uint32_t) + plastic.capacity() * sizeof(Real) +
         kind_material.capacity() * sizeof(std::uint16_t) + kind_volume.capacity() * sizeof(Real);
}

}  // namespace shellmpm
