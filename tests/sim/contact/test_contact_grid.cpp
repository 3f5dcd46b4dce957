// Contact forces on the MPM grid (sim/contact/shell_transfer, shell_contact): the grid
// force of compressed, sheared contact particles is minus the gradient of the contact
// energy with respect to grid node positions over one step (supplement sec. 2), and it
// conserves momentum.
#include <catch2/catch.hpp>

#include <array>
#include <cstring>
#include <map>
#include <random>

#include "sim/contact/friction_return_map.h"
#include "sim/contact/shell_transfer.h"
#include "sim/mpm/transfer.h"
#include "sim/shell/shell_object.h"

using namespace shellmpm;

namespace {

struct Rig {
  ShellDesc desc;
  ShellMaterialDesc mat;
  std::unique_ptr<ShellObject> shell;
  std::unique_ptr<ShellContact> contact;
  std::vector<GridShell> shells;
  ShellPointTable table;
  SparseGrid grid;
  std::vector<Vec3> pts;

  explicit Rig(int samples) {
    desc.kind = ShellDesc::Kind::Sheet;
    desc.size[0] = desc.size[1] = 0.12;
    desc.resolution[0] = desc.resolution[1] = 4;
    desc.rotate_deg = Vec3d(20, 10, 5);
    desc.translate = Vec3d(0.5, 0.5, 0.5);
    mat.youngs_modulus = 1e5;
    mat.thickness = 0.002;
    shell = std::make_unique<ShellObject>(desc, mat, build_shell_rest_mesh(desc));
    ContactParams cp;
    cp.kc = 1e5;
    cp.gamma = 4e4;
    cp.friction = 0.3;
    contact =
        std::make_unique<ShellContact>(shell->basis(), shell->rest, mat.thickness, samples, cp);
    // Deform: small random displacement of the control points; compress and shear a3E.
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    for (auto& x : shell->x) x += Vec3(u(rng), u(rng), u(rng)) * Real(0.004);
    for (auto& a : contact->a3e) {
      const Vec3 t = a.unitOrthogonal();
      a = Real(0.7 + 0.1 * u(rng)) * a + Real(0.1 * u(rng)) * t;
    }
    // In contact (forces() leaves out the sites a return mapping left separated).
    contact->state.assign(contact->num_sites(), static_cast<std::uint8_t>(ContactState::Sticking));
    for (auto& v : shell->v) v.setZero();
    GridShell g;
    g.shell = shell.get();
    g.contact = contact.get();
    g.held.assign(shell->size(), 0);
    shells.push_back(std::move(g));
    table.build(shells);
    contact->update_positions(shell->x.data(), true);
    table.positions(shells, pts);
    grid.setup(0.03, Vec3d::Zero());
    grid.bin(&pts, std::vector<Vec3>{}, true);
  }

  std::uint64_t key(const Vec3i& n) const {
    return (std::uint64_t(n[0]) << 40) | (std::uint64_t(n[1]) << 20) | std::uint64_t(n[2]);
  }

  // Grid forces [N] per node (tangential part through the control points plus the
  // normal part), and node masses.
  void forces(std::map<std::uint64_t, Vec3d>& F, std::map<std::uint64_t, double>& M) {
    GridShell& g = shells[0];
    g.force.assign(shell->size(), Vec3::Zero());
    contact->forces(shell->x.data(), g.force.data(), true);
    for (std::size_t b = 0; b < grid.num_particle_blocks(); ++b) {
      std::array<GridNode, kPadNodes> pad;
      std::fill(pad.begin(), pad.end(), GridNode{0, {0, 0, 0}});
      shell_p2g_block(grid, table, shells, Real(1), b,
                      pad.data());  // dt = 1, v = 0: momentum = force
      grid.add_pad_to_grid(b, pad.data());
    }
    std::map<std::uint64_t, Vec3d> tangential;
    for (std::size_t b = 0; b < grid.num_grid_blocks(); ++b)
      grid.for_each_massive_node(b, [&](GridNode& nd, const Vec3i& n) {
        tangential[key(n)] = Vec3d(nd.v[0], nd.v[1], nd.v[2]);
        M[key(n)] = nd.m;
        nd.v[0] = nd.v[1] = nd.v[2] = 0;
      });
    contact_normal_forces(grid, table, shells, Real(1), true);
    for (std::size_t b = 0; b < grid.num_grid_blocks(); ++b)
      grid.for_each_massive_node(b, [&](GridNode& nd, const Vec3i& n) {
        F[key(n)] = tangential[key(n)] + nd.m * Vec3d(nd.v[0], nd.v[1], nd.v[2]);
      });
  }

  // Contact energy [J] after moving grid node `node` by `u` for one step, in double:
  // control points move with the interpolated displacement, a3E with the restricted
  // displacement gradient, both evaluated at the step's start (as the solver does).
  double energy(const Vec3i& node, const Vec3d& u, const std::map<std::uint64_t, double>& M) const {
    const auto mass = [&](int i, int j, int k) {
      const auto it = M.find(key(Vec3i(i, j, k)));
      return it == M.end() ? 0.0 : it->second;
    };
    std::vector<Vec3d> x(shell->size());
    for (std::size_t j = 0; j < shell->size(); ++j) {
      const QuadraticWeights W(grid.grid_coord(shell->x[j]));
      double w = 1;
      for (int a = 0; a < 3; ++a) {
        const int o = node[a] - W.base[a];
        w *= (o >= 0 && o <= 2) ? static_cast<double>(W.w[a][o]) : 0.0;
      }
      x[j] = shell->x[j].cast<double>() + w * u;
    }
    double e = 0;
    const ContactParams& p = contact->params();
    for (std::size_t s = 0; s < contact->num_sites(); ++s) {
      Vec3d a1 = Vec3d::Zero(), a2 = Vec3d::Zero();
      const ShellContact::StencilWeight* ws = contact->weights(s);
      for (std::uint32_t k = contact->off[s]; k < contact->off[s + 1]; ++k) {
        a1 += static_cast<double>(ws[k - contact->off[s]].N1) * x[contact->idx[k]];
        a2 += static_cast<double>(ws[k - contact->off[s]].N2) * x[contact->idx[k]];
      }
      const SiteStencil st = site_stencil(grid, contact->x[s], mass);
      Vec3d a3 = contact->a3e[s].cast<double>();
      int n = 0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          for (int k = 0; k < 3; ++k, ++n)
            if (st.base[0] + i == node[0] && st.base[1] + j == node[1] && st.base[2] + k == node[2])
              a3 += u * st.grad[n].cast<double>().dot(contact->a3e[s].cast<double>());
      e += static_cast<double>(contact->volume[s]) *
           contact_gradient<double>(a1, a2, a3, p, nullptr);
    }
    return e;
  }
};

}  // namespace

TEST_CASE("contact grid force is minus the energy gradient over one step", "[contact]") {
  for (int samples : {1, 3}) {
    Rig rig(samples);
    std::map<std::uint64_t, Vec3d> F;
    std::map<std::uint64_t, double> M;
    rig.forces(F, M);
    REQUIRE(F.size() > 50);
    double fmax = 0;
    for (const auto& [k, f] : F) fmax = std::max(fmax, f.norm());
    REQUIRE(fmax > 0);
    // Every 7th node, all components, two step sizes.
    double err_big = 0, err_small = 0;
    int checked = 0, idx = 0;
    for (const auto& [k, f] : F) {
      if (idx++ % 7) continue;
      const Vec3i n(int(k >> 40), int((k >> 20) & 0xFFFFF), int(k & 0xFFFFF));
      for (int a = 0; a < 3; ++a) {
        auto fd = [&](double h) {
          Vec3d u = Vec3d::Zero();
          u[a] = h;
          return -(rig.energy(n, u, M) - rig.energy(n, -u, M)) / (2 * h);
        };
        err_big = std::max(err_big, std::abs(fd(3e-3) - f[a]));
        err_small = std::max(err_small, std::abs(fd(3e-4) - f[a]));
        ++checked;
      }
    }
    INFO("samples " << samples << ", max |f| " << fmax << ", FD error h=3e-3: " << err_big
                    << ", h=3e-4: " << err_small);
    CHECK(checked > 20);
    CHECK(err_small < 2e-3 * fmax);
    CHECK(err_small < err_big);
  }
}

TEST_CASE("contact grid forces sum to zero (momentum)", "[contact]") {
  Rig rig(3);
  std::map<std::uint64_t, Vec3d> F;
  std::map<std::uint64_t, double> M;
  rig.forces(F, M);
  Vec3d sum = Vec3d::Zero();
  double fmax = 0;
  for (const auto& [k, f] : F) {
    sum += f;
    fmax = std::max(fmax, f.norm());
  }
  INFO("sum " << sum.transpose() << " max " << fmax);
  CHECK(fmax > 0);
  CHECK(sum.norm() < 1e-5 * fmax);
}

TEST_CASE("P2G of blocks of shell points alone adds only the nodes they reach, with the same bits",
          "[contact]") {
  // particles_to_grid on blocks without bulk particles (a clean buffer per thread, only
  // the box of the nodes the points reached added to the grid, and zeroed again) against
  // the whole padded buffer of each block added, colour by colour: every grid node the
  // same, bit for bit. The sheet is tilted, moving and has forces, so that momentum and
  // the affine term are not 0.
  Rig rig(3);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  GridShell& g = rig.shells[0];
  for (auto& v : rig.shell->v) v = Vec3(u(rng), u(rng), u(rng)) * Real(0.5);
  g.force.assign(rig.shell->size(), Vec3::Zero());
  rig.contact->forces(rig.shell->x.data(), g.force.data(), true);
  for (Mat3& C : rig.contact->C) C = Mat3::Random();
  std::vector<std::vector<std::array<GridNode, kBlockNodes>>> runs;
  std::size_t partial = 0;  // boxes short of the whole buffer: nodes left out of the add
  for (const bool boxed : {false, true}) {
    SparseGrid grid;
    grid.setup(0.011, Vec3d::Zero());  // several particle blocks, many shared nodes
    grid.bin(&rig.pts, std::vector<Vec3>{}, true);
    REQUIRE(grid.num_particle_blocks() > 4);
    TransferParams tp;
    tp.dt = Real(1e-3);
    tp.stress = false;
    tp.serial = true;
    tp.first_bulk = static_cast<std::uint32_t>(rig.table.size());
    if (boxed) {
      tp.others = [&](std::size_t b, GridNode* buf, PadBox* box) {
        REQUIRE(box);
        shell_p2g_block(grid, rig.table, rig.shells, tp.dt, b, buf, nullptr, box);
        CHECK(!box->empty());
        int volume = 1;
        for (int a = 0; a < 3; ++a) volume *= box->hi[a] - box->lo[a];
        partial += volume < kPadNodes;
      };
      ParticleSet none;
      particles_to_grid(none, grid, tp);
    } else {
      grid.for_each_block_by_colour(
          [&](std::size_t b) {
            std::array<GridNode, kPadNodes> pad{};
            shell_p2g_block(grid, rig.table, rig.shells, tp.dt, b, pad.data());
            grid.add_pad_to_grid(b, pad.data());
          },
          true);
      grid.zero_unset_blocks(true);
    }
    runs.push_back(grid.gblock_nodes);
  }
  REQUIRE(runs[0].size() == runs[1].size());
  std::size_t differ = 0, mass = 0;
  for (std::size_t b = 0; b < runs[0].size(); ++b)
    for (int n = 0; n < kBlockNodes; ++n) {
      differ += std::memcmp(&runs[0][b][n], &runs[1][b][n], sizeof(GridNode)) != 0;
      mass += runs[0][b][n].m > 0;
    }
  CHECK(mass > 50);
  CHECK(partial > 0);
  CHECK(differ == 0);
}
