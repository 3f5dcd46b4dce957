#include "sim/shell/kl_patches.h"

#include <algorithm>
#include <cstring>
#include <map>

#include "sim/core/check.h"
#include "sim/core/counting_sort.h"

namespace shellmpm::kl {
namespace {

/// Whether points q and r have the same control list.
bool same_ctrl(const std::vector<std::size_t>& begin, const std::vector<int>& ctrl, std::size_t q,
               std::size_t r) {
  const std::size_t m = begin[q + 1] - begin[q];
  return begin[r + 1] - begin[r] == m &&
         std::equal(ctrl.begin() + static_cast<std::ptrdiff_t>(begin[q]),
                    ctrl.begin() + static_cast<std::ptrdiff_t>(begin[q + 1]),
                    ctrl.begin() + static_cast<std::ptrdiff_t>(begin[r]));
}

}  // namespace

Patches build_patches(const std::vector<std::size_t>& begin, const std::vector<int>& ctrl,
                      const std::vector<float>& coef, std::size_t num_ctrl) {
  Patches p;
  const std::size_t nq = begin.size() - 1;
  if (nq == 0) return p;
  // The run length of the first patch; every patch must have it.
  std::size_t P = 1;
  while (P < nq && same_ctrl(begin, ctrl, 0, P)) ++P;
  if (P > std::size_t(Patches::kMaxPoints) || nq % P != 0) return p;
  const std::size_t np = nq / P;
  for (std::size_t g = 0; g < np; ++g) {
    const std::size_t q0 = g * P;
    const std::size_t m = begin[q0 + 1] - begin[q0];
    if (m == 0 || m > std::size_t(Patches::kMaxCtrl)) return p;
    for (std::size_t k = 1; k < P; ++k)
      if (!same_ctrl(begin, ctrl, q0, q0 + k)) return p;
    // Maximal runs: the next patch must not continue this one.
    if (g + 1 < np && same_ctrl(begin, ctrl, q0, q0 + P)) return p;
  }
  p.points = static_cast<int>(P);
  // Patterns: the patch's [k][c][5] coefficients, deduplicated bit for bit.
  std::map<std::vector<std::uint32_t>, std::uint32_t> ids;
  std::vector<std::uint32_t> key;
  p.pattern.resize(np);
  p.begin.resize(np + 1);
  for (std::size_t g = 0; g < np; ++g) {
    const std::size_t q0 = g * P;
    const std::size_t m = begin[q0 + 1] - begin[q0];
    p.begin[g] = static_cast<std::uint32_t>(p.ctrl.size());
    p.ctrl.insert(p.ctrl.end(), ctrl.begin() + static_cast<std::ptrdiff_t>(begin[q0]),
                  ctrl.begin() + static_cast<std::ptrdiff_t>(begin[q0 + 1]));
    key.assign(1 + 5 * m * P, 0);
    key[0] = static_cast<std::uint32_t>(m);
    for (std::size_t k = 0; k < P; ++k)
      std::memcpy(&key[1 + 5 * m * k], &coef[5 * begin[q0 + k]], 5 * m * sizeof(float));
    const auto [it, added] = ids.emplace(key, static_cast<std::uint32_t>(p.pattern_size.size()));
    if (added) {
      p.pattern_size.push_back(static_cast<std::uint32_t>(m));
      p.pattern_coef.push_back(static_cast<std::uint32_t>(p.coefs.size()));
      p.coefs.resize(p.coefs.size() + 5 * m * P);
      std::memcpy(p.coefs.data() + p.pattern_coef.back(), &key[1], 5 * m * P * sizeof(float));
    }
    p.pattern[g] = it->second;
  }
  p.begin[np] = static_cast<std::uint32_t>(p.ctrl.size());
  SHELLMPM_CHECK(p.ctrl.size() < (std::size_t(1) << 32), "too many patch entries");
  // Patches by pattern (stable), and the gather map of the patch entries.
  std::vector<std::uint32_t> pattern_start;
  counting_sort(
      np, p.pattern_size.size(), [&](std::size_t g) { return p.pattern[g]; }, pattern_start,
      p.order);
  std::vector<std::size_t> order;
  counting_sort(
      p.ctrl.size(), num_ctrl, [&](std::size_t e) { return p.ctrl[e]; }, p.gather_begin, order);
  p.slot.resize(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) p.slot[order[i]] = static_cast<std::uint32_t>(i);
  return p;
}

void lay_out_lanes(Patches& p, const std::vector<float>& B, const std::vector<float>& area,
                   int num_layers) {
  const std::size_t np = p.num_patches(), P = std::size_t(p.points), L = std::size_t(num_layers);
  constexpr std::size_t kB = Patches::kLaneBlock;
  const std::size_t blocks = (np + kB - 1) / kB;
  // (The padding: B = (1, 1, 1, 1) and area 1, finite for the lanes that read it.)
  p.B_lanes.assign(blocks * P * L * 4 * kB + kB, 1.0f);
  p.area_lanes.assign(blocks * P * kB + kB, 1.0f);
  for (std::size_t c = 0; c < blocks; ++c)
    for (std::size_t o = 0; o < kB; ++o) {
      const std::size_t g = p.order[std::min(c * kB + o, np - 1)];
      for (std::size_t k = 0; k < P; ++k) {
        const std::size_t q = g * P + k;
        p.area_lanes[(c * P + k) * kB + o] = area[q];
        for (std::size_t l = 0; l < L; ++l)
          for (std::size_t e = 0; e < 4; ++e)
            p.B_lanes[(((c * P + k) * L + l) * 4 + e) * kB + o] = B[4 * (q * L + l) + e];
      }
    }
}

}  // namespace shellmpm::kl
