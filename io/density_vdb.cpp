#include "io/density_vdb.h"

#include <openvdb/io/Compression.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "io/atomic_file.h"
#include "io/vdb_axes.h"
#include "sim/core/parallel.h"

namespace shellmpm {
namespace {

using FloatLeaf = openvdb::FloatTree::LeafNodeType;
using VecLeaf = openvdb::Vec3STree::LeafNodeType;
constexpr int kLeafDim = 8;   // FloatLeaf::DIM
constexpr int kLeafLog2 = 3;  // FloatLeaf::LOG2DIM
constexpr int kKeyBits = 21;  // bits per axis of a packed leaf key
constexpr std::int64_t kKeyOffset = std::int64_t(1) << (kKeyBits - 1);
/// Largest |index-space coordinate| accepted, so that leaf coordinates fit the key.
constexpr double kMaxIndex = double(kKeyOffset - 2) * kLeafDim;
static_assert(FloatLeaf::DIM == kLeafDim && VecLeaf::DIM == kLeafDim, "leaf size");

/// Leaf coordinates (voxel index >> 3) packed into one sortable key (x major).
std::uint64_t pack_leaf(const std::array<int, 3>& l) {
  std::uint64_t k = 0;
  for (int a = 0; a < 3; ++a)
    k = (k << kKeyBits) | static_cast<std::uint64_t>(std::int64_t(l[a]) + kKeyOffset);
  return k;
}
std::array<int, 3> unpack_leaf(std::uint64_t k) {
  std::array<int, 3> l{};
  const std::uint64_t mask = (std::uint64_t(1) << kKeyBits) - 1;
  for (int a = 2; a >= 0; --a) {
    l[a] = static_cast<int>(std::int64_t(k & mask) - kKeyOffset);
    k >>= kKeyBits;
  }
  return l;
}

/// Floor division by the leaf size for negative indices too.
int leaf_of(int i) {
  return i >= 0 ? i / kLeafDim : -((-i + kLeafDim - 1) / kLeafDim);
}

/// Quadratic B-spline stencil of one particle along one axis: the first node index
/// `base` and weights for nodes base, base+1, base+2 (they sum to 1).
struct Stencil1 {
  int base;
  double w[3];
};
Stencil1 stencil(double g) {  // g: position in index space (voxel centers at integers)
  Stencil1 s;
  const double fb = std::floor(g - 0.5);
  s.base = static_cast<int>(fb);
  const double fx = g - fb;  // in [0.5, 1.5)
  s.w[0] = 0.5 * (1.5 - fx) * (1.5 - fx);
  s.w[1] = 0.75 - (fx - 1.0) * (fx - 1.0);
  s.w[2] = 0.5 * (fx - 0.5) * (fx - 0.5);
  return s;
}

std::string describe(const Vec3& x) {
  std::ostringstream os;
  os << "(" << x.x() << ", " << x.y() << ", " << x.z() << ")";
  return os.str();
}

/// What openvdb::io::File::write does (a seekable archive, so readers get the grid
/// offsets), but onto a stream we give it: io::File writes through its own std::ofstream
/// and never checks it, which left truncated files behind on a full disk. Our stream is
/// a CheckedFile, whose close() reports any failed write.
class VdbFileWriter : public openvdb::io::Archive {
 public:
  void write_file(std::ostream& os, const openvdb::GridPtrVec& grids,
                  const openvdb::MetaMap& meta) const {
    Archive::write(os, grids, /*seekable=*/true, meta);
  }
};

void add_metadata(openvdb::MetaMap& m, const VdbOptions& o) {
  m.insertMeta("frame", openvdb::Int32Metadata(o.frame));
  m.insertMeta("time", openvdb::FloatMetadata(static_cast<float>(o.time)));
  m.insertMeta("units", openvdb::StringMetadata(o.units));
  m.insertMeta("voxel_size", openvdb::DoubleMetadata(o.voxel_size));
}

/// Blosc when this OpenVDB build has it (Debian 12's does), zip otherwise.
std::uint32_t compression_flags() {
  return (openvdb::io::Archive::hasBloscCompression() ? openvdb::io::COMPRESS_BLOSC
                                                      : openvdb::io::COMPRESS_ZIP) |
         openvdb::io::COMPRESS_ACTIVE_MASK;
}

/// (leaf key, particle index) for every particle, sorted: the leaf holding its first stencil
/// node. Throws for a non-finite position, a negative volume or a position out of range.
std::vector<std::pair<std::uint64_t, std::size_t>> particles_by_leaf(const DensityInput& in,
                                                                     double inv_h) {
  const std::size_t n = in.count;
  std::vector<std::pair<std::uint64_t, std::size_t>> order(n);
  std::vector<std::size_t> bad_chunk((n + 4095) / 4096, n);
  parallel_for(n, 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t p = b; p < e; ++p) {
      const Vec3& x = in.positions[p];
      std::array<int, 3> leaf{};
      bool ok = std::isfinite(static_cast<double>(in.volume(p))) && in.volume(p) >= 0;
      for (int a = 0; a < 3 && ok; ++a) {
        const double g = static_cast<double>(x[a]) * inv_h;
        ok = std::isfinite(g) && std::abs(g) < kMaxIndex;
        if (ok) leaf[a] = leaf_of(stencil(g).base);
      }
      if (!ok) {
        bad_chunk[b / 4096] = std::min(bad_chunk[b / 4096], p);
        leaf = {0, 0, 0};
      }
      order[p] = {pack_leaf(leaf), p};
    }
  });
  for (std::size_t c : bad_chunk)
    if (c < n) {
      std::ostringstream os;
      os << "write_density_vdb: particle " << c << " has position " << describe(in.positions[c])
         << " and volume " << in.volume(c) << " (non-finite, negative volume, or beyond "
         << kMaxIndex << " voxels from the origin)";
      throw std::invalid_argument(os.str());
    }
  // (key, index) pairs are unique, so the sorted order does not depend on threads.
  tbb::parallel_sort(order.begin(), order.end());
  return order;
}

/// Runs of particles with the same leaf key, and the output leaves they reach: a bucket's
/// leaf and its +1 neighbours (a stencil starting in leaf L reaches at most 2 voxels into
/// L+1).
struct Buckets {
  std::vector<std::uint64_t> key;
  std::vector<std::size_t> begin;  ///< first sorted index of each bucket, plus n at the end
  std::vector<std::uint64_t> out_keys;
};

Buckets make_buckets(const std::vector<std::pair<std::uint64_t, std::size_t>>& order) {
  Buckets bk;
  const std::size_t n = order.size();
  for (std::size_t i = 0; i < n; ++i)
    if (i == 0 || order[i].first != order[i - 1].first) {
      bk.key.push_back(order[i].first);
      bk.begin.push_back(i);
    }
  bk.begin.push_back(n);
  bk.out_keys.reserve(bk.key.size() * 8);
  for (std::uint64_t k : bk.key) {
    const auto l = unpack_leaf(k);
    for (int d = 0; d < 8; ++d)
      bk.out_keys.push_back(pack_leaf({l[0] + (d & 1), l[1] + ((d >> 1) & 1), l[2] + (d >> 2)}));
  }
  std::sort(bk.out_keys.begin(), bk.out_keys.end());
  bk.out_keys.erase(std::unique(bk.out_keys.begin(), bk.out_keys.end()), bk.out_keys.end());
  return bk;
}

/// One particle's stencil in the sorted order (contiguous for the gather).
struct Stencil3 {
  int base[3];
  double w[3][3];  // w[0] is premultiplied by the particle volume
};

/// Sums into one output leaf's dense 8^3 block (acc: density weights; mom: momentum) the
/// particles of the (up to) 8 buckets that can reach it, always in the same order. Returns
/// whether any particle touched it.
bool gather_leaf(std::uint64_t leaf_key, const Buckets& bk, const std::vector<Stencil3>& st,
                 const std::vector<Vec3d>& vel_sorted, bool want_vel, std::vector<double>& acc,
                 std::vector<double>& mom) {
  const auto l = unpack_leaf(leaf_key);
  const int origin[3] = {l[0] * kLeafDim, l[1] * kLeafDim, l[2] * kLeafDim};
  std::fill(acc.begin(), acc.end(), 0.0);
  std::fill(mom.begin(), mom.end(), 0.0);
  bool any = false;
  for (int d = 7; d >= 0; --d) {  // source buckets L - {0,1}^3, in a fixed order
    const std::uint64_t sk = pack_leaf({l[0] - (d & 1), l[1] - ((d >> 1) & 1), l[2] - (d >> 2)});
    const auto it = std::lower_bound(bk.key.begin(), bk.key.end(), sk);
    if (it == bk.key.end() || *it != sk) continue;
    const std::size_t bi = static_cast<std::size_t>(it - bk.key.begin());
    for (std::size_t s = bk.begin[bi]; s < bk.begin[bi + 1]; ++s) {
      const Stencil3& ps = st[s];
      int lo[3], hi[3];
      bool touches = true;
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::max(0, origin[a] - ps.base[a]);
        hi[a] = std::min(2, origin[a] + kLeafDim - 1 - ps.base[a]);
        touches = touches && lo[a] <= hi[a];
      }
      if (!touches) continue;
      any = true;
      const int o0 = ps.base[0] - origin[0], o1 = ps.base[1] - origin[1],
                o2 = ps.base[2] - origin[2];
      for (int i = lo[0]; i <= hi[0]; ++i) {
        const double wi = ps.w[0][i];
        const int oi = (o0 + i) << (2 * kLeafLog2);
        for (int j = lo[1]; j <= hi[1]; ++j) {
          const double wij = wi * ps.w[1][j];
          const int oij = oi | ((o1 + j) << kLeafLog2);
          for (int k = lo[2]; k <= hi[2]; ++k) acc[oij | (o2 + k)] += wij * ps.w[2][k];
          if (!want_vel) continue;
          const Vec3d& v = vel_sorted[s];
          for (int k = lo[2]; k <= hi[2]; ++k) {
            const double w = wij * ps.w[2][k];
            double* m = &mom[3 * (oij | (o2 + k))];
            m[0] += w * v[0];
            m[1] += w * v[1];
            m[2] += w * v[2];
          }
        }
      }
    }
  }
  return any;
}

/// The density (and velocity) leaves of one gathered block; null where nothing is active.
std::pair<std::unique_ptr<FloatLeaf>, std::unique_ptr<VecLeaf>> make_leaves(
    std::uint64_t leaf_key, const std::vector<double>& acc, const std::vector<double>& mom,
    bool want_vel, double inv_cell_volume) {
  const auto l = unpack_leaf(leaf_key);
  const openvdb::Coord c(l[0] * kLeafDim, l[1] * kLeafDim, l[2] * kLeafDim);
  auto dl = std::make_unique<FloatLeaf>(c, 0.0f, false);
  std::unique_ptr<VecLeaf> vl;
  if (want_vel) vl = std::make_unique<VecLeaf>(c, openvdb::Vec3s(0.0f), false);
  bool active = false;
  for (openvdb::Index off = 0; off < FloatLeaf::SIZE; ++off) {
    if (!(acc[off] > 0.0)) continue;
    const float value = static_cast<float>(acc[off] * inv_cell_volume);
    if (value == 0.0f) continue;  // underflow: keep "0 means inactive" exact
    active = true;
    dl->setValueOn(off, value);
    if (want_vel) {
      const double inv = 1.0 / acc[off];
      vl->setValueOn(off, openvdb::Vec3s(static_cast<float>(mom[3 * off] * inv),
                                         static_cast<float>(mom[3 * off + 1] * inv),
                                         static_cast<float>(mom[3 * off + 2] * inv)));
    }
  }
  if (!active) return {nullptr, nullptr};
  return {std::move(dl), std::move(vl)};
}

/// A grid of the leaves, in sorted order, with the file's transform and metadata.
template <class GridT, class LeafT>
typename GridT::Ptr make_grid(const char* name, typename GridT::ValueType background,
                              const openvdb::math::Transform::Ptr& xform, const VdbOptions& o,
                              std::vector<std::unique_ptr<LeafT>>& leaves) {
  typename GridT::Ptr g = GridT::create(background);
  g->setName(name);
  g->setTransform(xform);
  g->setSaveFloatAsHalf(o.half_float);
  g->setCreator("shellmpm");
  add_metadata(*g, o);
  for (auto& leaf : leaves)
    if (leaf) g->tree().addLeaf(leaf.release());
  return g;
}

}  // namespace

void write_density_vdb(const std::string& path, const DensityInput& in, const VdbOptions& o) {
  const double h = o.voxel_size;
  if (!(h > 0.0) || !std::isfinite(h))
    throw std::invalid_argument("write_density_vdb: voxel size must be positive and finite");
  if (in.count > 0 && (!in.positions || !in.volumes))
    throw std::invalid_argument("write_density_vdb: positions and volumes are required");
  if (o.velocity && in.count > 0 && !in.velocities)
    throw std::invalid_argument("write_density_vdb: velocity grid asked for without velocities");
  openvdb::initialize();
  const std::size_t n = in.count;
  const double inv_h = 1.0 / h;
  // 1. Each particle's leaf key, sorted; 2. the buckets and the leaves they reach.
  const std::vector<std::pair<std::uint64_t, std::size_t>> order = particles_by_leaf(in, inv_h);
  const Buckets bk = make_buckets(order);
  // 3. Each particle's stencil, once, in sorted order.
  std::vector<Stencil3> st(n);
  const bool want_vel = o.velocity;
  std::vector<Vec3d> vel_sorted(want_vel ? n : 0);
  parallel_for(n, 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t s = b; s < e; ++s) {
      const std::size_t p = order[s].second;
      for (int a = 0; a < 3; ++a) {
        const Stencil1 s1 = stencil(static_cast<double>(in.positions[p][a]) * inv_h);
        st[s].base[a] = s1.base;
        const double scale = a == 0 ? static_cast<double>(in.volume(p)) : 1.0;
        for (int q = 0; q < 3; ++q) st[s].w[a][q] = scale * s1.w[q];
      }
      if (want_vel) vel_sorted[s] = in.velocities[p].template cast<double>();
    }
  });
  // 4. Gather per output leaf: no atomics, and a leaf's result does not depend on which
  //    thread computes it.
  std::vector<std::unique_ptr<FloatLeaf>> dens_leaves(bk.out_keys.size());
  std::vector<std::unique_ptr<VecLeaf>> vel_leaves(want_vel ? bk.out_keys.size() : 0);
  const double inv_cell_volume = inv_h * inv_h * inv_h;
  parallel_for(bk.out_keys.size(), 4, [&](std::size_t lb, std::size_t le) {
    std::vector<double> acc(FloatLeaf::SIZE), mom(want_vel ? 3 * FloatLeaf::SIZE : 0);
    for (std::size_t li = lb; li < le; ++li) {
      if (!gather_leaf(bk.out_keys[li], bk, st, vel_sorted, want_vel, acc, mom)) continue;
      auto leaves = make_leaves(bk.out_keys[li], acc, mom, want_vel, inv_cell_volume);
      dens_leaves[li] = std::move(leaves.first);
      if (want_vel) vel_leaves[li] = std::move(leaves.second);
    }
  });
  // 5. Trees from the leaves, in sorted order.
  auto xform = openvdb::math::Transform::createLinearTransform(h);
  openvdb::FloatGrid::Ptr density =
      make_grid<openvdb::FloatGrid>("density", 0.0f, xform, o, dens_leaves);
  density->setGridClass(openvdb::GRID_FOG_VOLUME);
  // 6. In the output axes (a voxel permutation; nothing for Y up).
  openvdb::GridPtrVec grids{scalar_grid_to_output_axes<openvdb::FloatGrid>(density, o.up_axis)};
  if (want_vel) {
    openvdb::Vec3SGrid::Ptr vel =
        make_grid<openvdb::Vec3SGrid>("vel", openvdb::Vec3s(0.0f), xform->copy(), o, vel_leaves);
    vel->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    grids.push_back(vector_grid_to_output_axes(vel, o.up_axis));
  }
  openvdb::MetaMap file_meta;
  add_metadata(file_meta, o);
  VdbFileWriter archive;
  archive.setCompression(compression_flags());
  write_stream_atomic(
      path, [&](CheckedFile& out) { archive.write_file(out.stream(), grids, file_meta); });
}

DensityStats read_density_vdb(const std::string& path) {
  openvdb::initialize();
  openvdb::io::File file(path);
  try {
    file.open();
  } catch (const openvdb::Exception& e) {
    throw std::runtime_error("cannot open VDB file '" + path + "': " + e.what());
  }
  DensityStats s;
  s.has_vel = file.hasGrid("vel");
  s.compression = openvdb::io::compressionToString(file.compression());
  openvdb::GridBase::Ptr base = file.hasGrid("density") ? file.readGrid("density") : nullptr;
  file.close();
  openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
  if (!grid) throw std::runtime_error("VDB file '" + path + "' has no float grid 'density'");
  s.grid_name = grid->getName();
  s.grid_class = openvdb::GridBase::gridClassToString(grid->getGridClass());
  s.voxel_size = grid->voxelSize()[0];
  s.half_float = grid->saveFloatAsHalf();
  s.active_voxels = grid->activeVoxelCount();
  double sum = 0.0, mx = 0.0;
  for (auto it = grid->cbeginValueOn(); it; ++it) {
    sum += static_cast<double>(*it) * static_cast<double>(it.getVoxelCount());
    mx = std::max(mx, static_cast<double>(*it));
  }
  s.integral = sum * s.voxel_size * s.voxel_size * s.voxel_size;
  s.max_value = mx;
  if (auto m = grid->getMetadata<openvdb::Int32Metadata>("frame")) {
    s.has_frame = true;
    s.frame = m->value();
  }
  if (auto m = grid->getMetadata<openvdb::FloatMetadata>("time")) {
    s.has_time = true;
    s.time = m->value();
  }
  if (auto m = grid->getMetadata<openvdb::StringMetadata>("units")) s.units = m->value();
  return s;
}

}  // namespace shellmpm
