#include <catch2/catch.hpp>
#include <cstring>
#include <random>

#include "sim/core/parallel.h"
#include "sim/mpm/transfer.h"

using namespace shellmpm;

namespace {

struct Totals {
  double mass = 0;
  Vec3d p = Vec3d::Zero(), L = Vec3d::Zero();
};

Totals grid_totals(const SparseGrid& g, bool velocity) {
  Totals t;
  for (std::size_t b = 0; b < g.num_grid_blocks(); ++b) {
    const Vec3i c = unpack_block(g.gblock_key[b]) * kBlockSize;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        for (int k = 0; k < 4; ++k) {
          const GridNode& n = g.gblock_nodes[b][block_node(i, j, k)];
          const Vec3d x = g.node_position(c + Vec3i(i, j, k));
          Vec3d mv(n.v[0], n.v[1], n.v[2]);
          if (velocity) mv *= n.m;
          t.mass += n.m;
          t.p += mv;
          t.L += x.cross(mv);
        }
  }
  return t;
}

void momentum_to_velocity(SparseGrid& g) {
  for (auto& blk : g.gblock_nodes)
    for (GridNode& n : blk)
      if (n.m > 0)
        for (Real& v : n.v) v /= n.m;
}

ParticleSet random_particles(int n, unsigned seed) {
  ParticleSet p;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> pos(0.3, 0.7), vel(-1, 1);
  for (int i = 0; i < n; ++i) {
    p.push_back(Vec3(Real(pos(rng)), Real(pos(rng)), Real(pos(rng))),
                Vec3(Real(vel(rng)), Real(vel(rng)), Real(vel(rng))), Real(1e-6 * (1 + pos(rng))),
                0, 1);
    for (int a = 0; a < 9; ++a) p.C.back()(a) = Real(5 * vel(rng));
  }
  return p;
}

}  // namespace

TEST_CASE("P2G then G2P conserves mass, linear and angular momentum", "[transfer]") {
  for (bool mls : {false, true}) {
    ParticleSet p = random_particles(3000, mls ? 2 : 1);
    SparseGrid grid;
    grid.setup(1.0 / 64, Vec3d::Zero());
    std::vector<ConstitutiveModel> models(1);
    std::vector<Real> rho{1000};
    TransferParams tp{0, mls, false, false, &models, &rho, 0, {}};
    double m = 0;
    Vec3d mom = Vec3d::Zero();
    for (std::size_t i = 0; i < p.size(); ++i) {
      m += double(p.volume_of(i)) * rho[0];
      mom += double(p.volume_of(i)) * rho[0] * p.v[i].cast<double>();
    }
    grid.bin(p.x);
    particles_to_grid(p, grid, tp);
    const Totals t1 = grid_totals(grid, false);
    REQUIRE(t1.mass == Approx(m).epsilon(1e-5));
    REQUIRE((t1.p - mom).norm() <= 1e-5 * mom.norm() + 1e-9);
    momentum_to_velocity(grid);
    grid_to_particles(p, grid, tp);  // dt = 0: positions stay
    // Particle linear momentum after G2P equals the grid's.
    Vec3d mom2 = Vec3d::Zero();
    for (std::size_t i = 0; i < p.size(); ++i)
      mom2 += double(p.volume_of(i)) * rho[0] * p.v[i].cast<double>();
    REQUIRE((mom2 - t1.p).norm() <= 1e-4 * t1.p.norm() + 1e-9);
    // A second P2G gives back the same grid angular momentum: APIC keeps it.
    grid.bin(p.x);
    particles_to_grid(p, grid, tp);
    const Totals t2 = grid_totals(grid, false);
    REQUIRE(t2.mass == Approx(t1.mass).epsilon(1e-6));
    REQUIRE((t2.p - t1.p).norm() <= 1e-4 * t1.p.norm());
    REQUIRE((t2.L - t1.L).norm() <= 1e-4 * t1.L.norm());
  }
}

TEST_CASE("P2G without C loses angular momentum (the APIC check can fail)", "[transfer]") {
  ParticleSet p = random_particles(2000, 5);
  SparseGrid grid;
  grid.setup(1.0 / 64, Vec3d::Zero());
  std::vector<ConstitutiveModel> models(1);
  std::vector<Real> rho{1000};
  TransferParams tp{0, false, false, false, &models, &rho, 0, {}};
  grid.bin(p.x);
  particles_to_grid(p, grid, tp);
  const Totals t1 = grid_totals(grid, false);
  momentum_to_velocity(grid);
  grid_to_particles(p, grid, tp);
  for (auto& c : p.C) c.setZero();  // PIC: drop the affine part
  grid.bin(p.x);
  particles_to_grid(p, grid, tp);
  const Totals t2 = grid_totals(grid, false);
  REQUIRE((t2.L - t1.L).norm() > 1e-3 * t1.L.norm());
}

TEST_CASE("transfers are bit-identical serial and parallel", "[transfer][determinism]") {
  ParticleSet a = random_particles(20000, 9), b = a;
  std::vector<ConstitutiveModel> models(1);
  models[0] = ConstitutiveModel::from_desc(MaterialDesc{});
  std::vector<Real> rho{1000};
  SparseGrid ga, gb;
  ga.setup(1.0 / 64, Vec3d::Zero());
  gb.setup(1.0 / 64, Vec3d::Zero());
  for (int step = 0; step < 3; ++step) {
    TransferParams ts{1e-4f, false, true, true, &models, &rho, 0, {}};
    TransferParams tpar{1e-4f, false, false, true, &models, &rho, 0, {}};
    ga.bin(a.x, true);
    particles_to_grid(a, ga, ts);
    momentum_to_velocity(ga);
    grid_to_particles(a, ga, ts);
    {
      ThreadLimit lim(2);
      gb.bin(b.x, false);
      particles_to_grid(b, gb, tpar);
      momentum_to_velocity(gb);
      grid_to_particles(b, gb, tpar);
    }
  }
  REQUIRE(std::memcmp(a.x.data(), b.x.data(), a.size() * sizeof(Vec3)) == 0);
  REQUIRE(std::memcmp(a.v.data(), b.v.data(), a.size() * sizeof(Vec3)) == 0);
  REQUIRE(std::memcmp(a.F.data(), b.F.data(), a.size() * sizeof(Mat3)) == 0);
}

TEST_CASE("sparse grid allocates only blocks near particles", "[grid]") {
  // Two tiny clusters far apart in a huge domain: a handful of blocks, not a dense array.
  std::vector<Vec3> x;
  for (int i = 0; i < 100; ++i) {
    x.emplace_back(Real(1.0 + 0.001 * i), 1, 1);
    x.emplace_back(Real(900.0 + 0.001 * i), 500, 700);
  }
  SparseGrid g;
  g.setup(0.01, Vec3d::Zero());
  g.bin(x);
  REQUIRE(g.num_particle_blocks() <= 8);
  REQUIRE(g.num_grid_blocks() <= 64);
  REQUIRE(g.bytes() < (1u << 20));
  // Every particle is listed exactly once in block order.
  std::vector<int> seen(x.size(), 0);
  for (auto q : g.order()) seen[q]++;
  for (int s : seen) REQUIRE(s == 1);
}

TEST_CASE("a re-binned grid's nodes are those of a fresh grid", "[transfer][grid]") {
  // The grid blocks are set where the P2G first reaches them: nothing of the last step's
  // nodes may stay, where the blocks are reused or only partly reached.
  std::vector<ConstitutiveModel> models(1);
  models[0] = ConstitutiveModel::from_desc(MaterialDesc{});
  std::vector<Real> rho{1000};
  const TransferParams tp{1e-4f, false, false, true, &models, &rho, 0, {}};
  ParticleSet a = random_particles(20000, 3), b = random_particles(5000, 4);
  for (Vec3& x : b.x) x = Vec3(x[0] * Real(0.5), x[1], x[2] * Real(1.2));  // other blocks
  SparseGrid g, fresh;
  g.setup(1.0 / 64, Vec3d::Zero());
  fresh.setup(1.0 / 64, Vec3d::Zero());
  ThreadLimit lim(2);
  g.bin(a.x);
  particles_to_grid(a, g, tp);
  REQUIRE(grid_totals(g, false).mass > 0);
  g.bin(b.x);
  particles_to_grid(b, g, tp);
  fresh.bin(b.x);
  particles_to_grid(b, fresh, tp);
  REQUIRE(g.gblock_key == fresh.gblock_key);
  REQUIRE(std::memcmp(g.gblock_nodes.data(), fresh.gblock_nodes.data(),
                      fresh.gblock_nodes.size() * sizeof(fresh.gblock_nodes[0])) == 0);
  // Mass: b's particles' and nothing of a's.
  double mb = 0;
  for (std::size_t p = 0; p < b.size(); ++p) mb += b.volume_of(p) * 1000.0;
  CHECK(grid_totals(g, false).mass == Approx(mb).epsilon(1e-5));
}
