// ChunkedKeys and the sparse grid's binning against plain serial definitions: block
// indices by first appearance, each block's points in order, grid blocks and their
// sources, columns by colour.
#include <algorithm>
#include <catch2/catch.hpp>
#include <map>
#include <random>

#include "sim/core/chunked_keys.h"
#include "sim/core/parallel.h"
#include "sim/mpm/sparse_grid.h"

using namespace shellmpm;

namespace {

/// First-appearance indices of a key sequence, serially.
std::vector<int> serial_numbering(const std::vector<std::uint64_t>& keys,
                                  std::vector<std::uint64_t>& distinct) {
  std::map<std::uint64_t, int> id;
  std::vector<int> out;
  for (std::uint64_t k : keys) {
    auto it = id.find(k);
    if (it == id.end()) {
      it = id.emplace(k, static_cast<int>(distinct.size())).first;
      distinct.push_back(k);
    }
    out.push_back(it->second);
  }
  return out;
}

}  // namespace

TEST_CASE("chunked key numbering gives the serial first-appearance indices", "[grid]") {
  std::mt19937 rng(5);
  ChunkedKeys ck;
  for (std::size_t chunk : {std::size_t(1), std::size_t(7), std::size_t(100), std::size_t(5000)}) {
    // Keys in runs with repeats far apart, as binned points give.
    std::vector<std::uint64_t> keys;
    std::uniform_int_distribution<int> pick(0, 300), run(1, 9);
    while (keys.size() < 4000) {
      const std::uint64_t k = pack_block(pick(rng), pick(rng) % 5, 3);
      for (int r = run(rng); r > 0; --r) keys.push_back(k);
    }
    std::vector<std::uint64_t> want_keys;
    const std::vector<int> want = serial_numbering(keys, want_keys);
    const std::size_t nc = (keys.size() + chunk - 1) / chunk;
    std::vector<int> local(keys.size());
    ThreadLimit lim(2);
    ck.resize(nc);
    parallel_for_each(nc, 1, [&](std::size_t c) {
      ck.begin_chunk(c);
      for (std::size_t i = c * chunk; i < std::min(keys.size(), (c + 1) * chunk); ++i)
        local[i] = ck.local(c, keys[i]);
    });
    BlockHash global;
    std::vector<std::uint64_t> got_keys;
    ck.number(global, got_keys);
    CHECK(got_keys == want_keys);
    std::size_t mismatches = 0;
    for (std::size_t i = 0; i < keys.size(); ++i)
      mismatches += ck.global(i / chunk, local[i]) != want[i];
    CHECK(mismatches == 0);
    for (std::size_t c = 0; c < nc; ++c) CHECK(ck.distinct(c) <= chunk);
  }
}

TEST_CASE("binning matches its serial definition across binning chunks", "[grid]") {
  // 50k points (four binning chunks): shuffled (many runs) and sorted along x (few).
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.05, 0.6);
  std::vector<Vec3> x(50000);
  for (Vec3& p : x) p = Vec3(Real(u(rng)), Real(u(rng)), Real(0.3 * u(rng)));
  for (bool sorted : {false, true}) {
    if (sorted)
      std::sort(x.begin(), x.end(), [](const Vec3& a, const Vec3& b) { return a[0] < b[0]; });
    SparseGrid g;
    g.setup(1.0 / 64, Vec3d::Zero());
    {
      ThreadLimit lim(2);
      g.bin(x);
    }
    // Particle blocks by first appearance; each block's points ascending.
    std::vector<std::uint64_t> pkeys, want_pkeys;
    for (const Vec3& p : x) pkeys.push_back(g.block_key(g.grid_coord(p)));
    const std::vector<int> pid = serial_numbering(pkeys, want_pkeys);
    REQUIRE(g.pblock_key == want_pkeys);
    const std::size_t nb = want_pkeys.size();
    std::vector<std::vector<std::uint32_t>> want_pts(nb);
    for (std::size_t i = 0; i < x.size(); ++i)
      want_pts[static_cast<std::size_t>(pid[i])].push_back(static_cast<std::uint32_t>(i));
    std::size_t wrong_blocks = 0;
    for (std::size_t b = 0; b < nb; ++b) {
      std::vector<std::uint32_t> got;
      g.for_each_point(b, [&](std::uint32_t i) { got.push_back(i); });
      const std::vector<std::uint32_t> slice(g.order().begin() + g.pblock_start[b],
                                             g.order().begin() + g.pblock_start[b + 1]);
      wrong_blocks += got != want_pts[b] || slice != want_pts[b];
    }
    CHECK(wrong_blocks == 0);
    // Grid blocks by first appearance over (block, neighbour o); sources by definition.
    std::vector<std::uint64_t> nkeys, want_gkeys;
    for (std::uint64_t k : want_pkeys) {
      const Vec3i c = unpack_block(k);
      for (int o = 0; o < 8; ++o)
        nkeys.push_back(pack_block(c[0] + (o >> 2), c[1] + ((o >> 1) & 1), c[2] + (o & 1)));
    }
    const std::vector<int> gid = serial_numbering(nkeys, want_gkeys);
    REQUIRE(g.gblock_key == want_gkeys);
    std::size_t wrong_nbr = 0, wrong_src = 0;
    for (std::size_t b = 0; b < nb; ++b)
      for (int o = 0; o < 8; ++o) wrong_nbr += g.pblock_nbr[b][o] != gid[8 * b + o];
    std::map<std::uint64_t, int> pblock;
    for (std::size_t b = 0; b < nb; ++b) pblock[want_pkeys[b]] = static_cast<int>(b);
    for (std::size_t gb = 0; gb < want_gkeys.size(); ++gb) {
      const Vec3i c = unpack_block(want_gkeys[gb]);
      for (int o = 0; o < 8; ++o) {
        const int sx = c[0] - (o >> 2), sy = c[1] - ((o >> 1) & 1), sz = c[2] - (o & 1);
        const auto it = pblock.find(pack_block(sx, sy, sz));
        const int want_src = (sx < 0 || sy < 0 || sz < 0 || it == pblock.end()) ? -1 : it->second;
        wrong_src += g.gblock_src[gb][o] != want_src;
      }
    }
    CHECK(wrong_nbr == 0);
    CHECK(wrong_src == 0);
    // Columns: every block once, ordered by (colour, x, y, z), a column per (x, y).
    std::vector<std::uint32_t> want_cols(nb);
    for (std::size_t b = 0; b < nb; ++b) want_cols[b] = static_cast<std::uint32_t>(b);
    auto col_key = [&](std::uint32_t b) {
      const Vec3i c = unpack_block(want_pkeys[b]);
      return std::array<int, 4>{((c[0] & 1) << 1) | (c[1] & 1), c[0], c[1], c[2]};
    };
    std::sort(want_cols.begin(), want_cols.end(),
              [&](std::uint32_t a, std::uint32_t b) { return col_key(a) < col_key(b); });
    CHECK(g.column_blocks == want_cols);
    std::size_t columns = 0;
    for (std::size_t i = 0; i < nb; ++i)
      columns += i == 0 || col_key(want_cols[i])[1] != col_key(want_cols[i - 1])[1] ||
                 col_key(want_cols[i])[2] != col_key(want_cols[i - 1])[2];
    CHECK(g.column_start.size() == columns + 1);
    CHECK(g.colour_columns[4] == columns);
  }
}
