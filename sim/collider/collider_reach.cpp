#include "sim/collider/collider_reach.h"

#include <algorithm>

#include "sim/core/parallel.h"
#include "sim/mpm/bspline.h"

namespace shellmpm {

void ColliderReach::compute(const SparseGrid& grid, const std::vector<Vec3>* first,
                            const std::vector<Vec3>* first_v, const std::vector<Vec3>& x,
                            const std::vector<Vec3>& v, const std::vector<Collider>& colliders,
                            double reach, double dt, bool serial,
                            const std::vector<Real>* first_offset) {
  const std::size_t nb = grid.num_particle_blocks();
  const std::size_t nf = first ? first->size() : 0;
  const std::size_t nk = std::min<std::size_t>(colliders.size(), 32);
  const double dx = grid.dx();
  double most = 0;  // the largest offset
  if (first_offset)
    for (Real o : *first_offset) most = std::max(most, double(o));
  buf_.resize(nb);
  touched_.assign(nb, 0);
  parallel_for_each(
      nb, 4,
      [&](std::size_t b) {
        std::array<std::uint32_t, kPadNodes>& buf = buf_[b];
        const Vec3i corner = unpack_block(grid.pblock_key[b]) * kBlockSize;
        // The block's points and the nodes they reach lie within 2.5 dx of its cells; a
        // point that moves further in a step is caught by the particle projection.
        Aabb box;
        box.lo = grid.node_position(corner).array() - 2.5 * dx - reach;
        box.hi =
            grid.node_position(corner + Vec3i::Constant(kBlockSize)).array() + 2.5 * dx + reach;
        // A collider (a ground plane's bounds are infinite) farther from the box's centre
        // than its half diagonal plus reach cannot have a point of it within reach.
        const Vec3d centre = 0.5 * (box.lo + box.hi);
        const double radius = 0.5 * (box.hi - box.lo).norm();
        std::uint32_t near = 0;
        for (std::size_t k = 0; k < nk; ++k)
          if (colliders[k].bounds().overlaps(box) &&
              colliders[k].phi(centre) <= radius + reach + most)
            near |= 1u << k;
        if (!near) return;
        bool touched = false;
        grid.for_each_point(b, [&](std::uint32_t i) {
          const Vec3& p = i < nf ? (*first)[i] : x[i - nf];
          const Vec3d pd = p.cast<double>();
          const Vec3d pe = pd + dt * (i < nf ? (*first_v)[i] : v[i - nf]).cast<double>();
          // A shell point's contact surface lies its offset (half its contact thickness)
          // out from it.
          // It engages within a fifth of the reach past that (kSurfaceReachShare): a point
          // stops where it engages, so with the full reach a cloth rested up to 0.1 dx
          // above a sphere (0.096 dx at dx 0.0125).
          const double at = i < nf && first_offset
                                ? kSurfaceReachShare * reach + double((*first_offset)[i])
                                : reach;
          std::uint32_t bits = 0;
          for (std::size_t k = 0; k < nk; ++k)
            if (((near >> k) & 1u) && std::min(colliders[k].phi(pd), colliders[k].phi(pe)) <= at)
              bits |= 1u << k;
          if (!bits) return;
          if (!touched) buf.fill(0);
          touched = true;
          const QuadraticWeights W(grid.grid_coord(p));
          const int lx = W.base[0] - corner[0], ly = W.base[1] - corner[1],
                    lz = W.base[2] - corner[2];
          for (int a = 0; a < 3; ++a)
            for (int c = 0; c < 3; ++c)
              for (int d = 0; d < 3; ++d) buf[pad_node(lx + a, ly + c, lz + d)] |= bits;
        });
        touched_[b] = touched;
      },
      serial);
  // Marks only for the grid blocks that gather from a marked buffer (numbered in block
  // order); the others engage nothing.
  const std::size_t ng = grid.num_grid_blocks();
  slot_.resize(ng);
  std::uint32_t slots = 0;
  for (std::size_t g = 0; g < ng; ++g) {
    bool any = false;
    for (int src : grid.gblock_src[g]) any = any || (src >= 0 && touched_[std::size_t(src)]);
    slot_[g] = any ? slots++ : kNone;
  }
  mask_.assign(std::size_t(slots) * kBlockNodes, 0);
  parallel_for_each(
      ng, 16,
      [&](std::size_t g) {
        if (slot_[g] == kNone) return;
        std::uint32_t* m = &mask_[std::size_t(slot_[g]) * kBlockNodes];
        grid.for_each_buffer_node(g, [&](int bn, std::size_t src, int pn) {
          if (touched_[src]) m[bn] |= buf_[src][pn];
        });
      },
      serial);
  computed_ = true;
}

std::size_t ColliderReach::count() const {
  return static_cast<std::size_t>(
      std::count_if(mask_.begin(), mask_.end(), [](std::uint32_t m) { return m != 0; }));
}

}  // namespace shellmpm
