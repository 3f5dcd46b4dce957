#include "sim/contact/shell_contact.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <unordered_map>

#include "sim/core/check.h"
#include "sim/core/parallel.h"
#include "sim/mpm/stress_batch.h"
#include "sim/shell/shell_quadrature.h"

namespace shellmpm {
namespace {
constexpr std::size_t kGrain = 2048;
constexpr Real kCompressionTolerance = Real(1e-4);
constexpr Real kSeparationTolerance = Real(1e-6);

/// A Vec3 as (x, y, z, 0) in one vector (the stencil sums run on these).
typedef Real R4 __attribute__((vector_size(4 * sizeof(Real))));
inline void load3(const Vec3& v, R4& out) {
  out = R4{v[0], v[1], v[2], Real(0)};
}

}  // namespace

ShellContact::ShellContact(const LoopBasis& basis, const std::vector<Vec3d>& rest, double thickness,
                           int samples, const ContactParams& params)
    : params_(params) {
  const TriangleQuadrature rule = triangle_quadrature(samples);
  const int nf = basis.num_faces();
  const std::size_t ns = static_cast<std::size_t>(nf) * rule.points.size();
  off.reserve(ns + 1);
  off.push_back(0);
  x.resize(ns);
  a3e.resize(ns);
  G3.assign(ns, Vec3::Zero());
  G12_.assign(ns, GradRows{});
  a1_.assign(ns, Vec3::Zero());
  a2_.assign(ns, Vec3::Zero());
  volume.resize(ns);
  state.assign(ns, static_cast<std::uint8_t>(ContactState::Separated));
  C.assign(rest.size(), Mat3::Zero());
  weight_row_.resize(ns);
  // Distinct weight lists, by their bits.
  std::unordered_map<std::string, std::uint32_t> rows;
  std::vector<StencilWeight> w;
  BasisPoint bp;
  std::size_t p = 0;
  for (int f = 0; f < nf; ++f)
    for (std::size_t q = 0; q < rule.points.size(); ++q, ++p) {
      basis.evaluate(f, rule.points[q].x(), rule.points[q].y(), bp);
      Vec3d pos = Vec3d::Zero(), a1 = Vec3d::Zero(), a2 = Vec3d::Zero();
      w.clear();
      for (std::size_t k = 0; k < bp.ctrl.size(); ++k) {
        const Vec3d& r = rest[bp.ctrl[k]];
        pos += bp.N[k] * r;
        a1 += bp.N1[k] * r;
        a2 += bp.N2[k] * r;
        idx.push_back(static_cast<std::uint32_t>(bp.ctrl[k]));
        w.push_back(
            {static_cast<Real>(bp.N[k]), static_cast<Real>(bp.N1[k]), static_cast<Real>(bp.N2[k])});
      }
      std::string key(reinterpret_cast<const char*>(w.data()), w.size() * sizeof(StencilWeight));
      const auto [at, added] =
          rows.emplace(std::move(key), static_cast<std::uint32_t>(weight_table_.size()));
      if (added) weight_table_.insert(weight_table_.end(), w.begin(), w.end());
      weight_row_[p] = at->second;
      off.push_back(static_cast<std::uint32_t>(idx.size()));
      const Vec3d n = a1.cross(a2);
      const double jac = n.norm();
      SHELLMPM_CHECK(jac > 0, << "degenerate rest tangents at face " << f);
      x[p] = pos.cast<Real>();
      a3e[p] = (n / jac).cast<Real>();  // rest normal: s = (0, 0, 1)
      volume[p] = static_cast<Real>(rule.weights[q] * jac * thickness);
    }
  // Transpose the stencils (counting sort by control point; sites stay ascending).
  const std::size_t nc = rest.size();
  toff.assign(nc + 1, 0);
  for (std::uint32_t j : idx) ++toff[j + 1];
  for (std::size_t j = 0; j < nc; ++j) toff[j + 1] += toff[j];
  tsite.resize(idx.size());
  tN1.resize(idx.size());
  tN2.resize(idx.size());
  std::vector<std::uint32_t> cur(toff.begin(), toff.end() - 1);
  for (std::size_t s = 0; s < ns; ++s) {
    const StencilWeight* ws = weights(s);
    for (std::uint32_t k = off[s]; k < off[s + 1]; ++k) {
      const std::uint32_t at = cur[idx[k]]++;
      tsite[at] = static_cast<std::uint32_t>(s);
      tN1[at] = ws[k - off[s]].N1;
      tN2[at] = ws[k - off[s]].N2;
    }
  }
}

void ShellContact::tangents(const Vec3* ctrl, std::size_t p, Vec3& a1, Vec3& a2) const {
  Vec3 xp;
  position_and_tangents(ctrl, p, xp, a1, a2);
}

void ShellContact::position_and_tangents(const Vec3* ctrl, std::size_t p, Vec3& xp, Vec3& a1,
                                         Vec3& a2) const {
  // Differences to the first control point: the dN sum to zero, so this is exact and
  // keeps float precision far from the origin. Each sum on a 4-vector (x, y, z, 0).
  R4 ref, d = {}, t1 = {}, t2 = {};
  load3(ctrl[idx[off[p]]], ref);
  const StencilWeight* w = weights(p);
  for (std::uint32_t k = off[p]; k < off[p + 1]; ++k) {
    R4 c;
    load3(ctrl[idx[k]], c);
    const R4 dk = c - ref;
    d += w[k - off[p]].N * dk;
    t1 += w[k - off[p]].N1 * dk;
    t2 += w[k - off[p]].N2 * dk;
  }
  xp = Vec3(ref[0] + d[0], ref[1] + d[1], ref[2] + d[2]);
  a1 = Vec3(t1[0], t1[1], t1[2]);
  a2 = Vec3(t2[0], t2[1], t2[2]);
}

Vec3 ShellContact::position(const Vec3* ctrl, std::size_t p) const {
  const Vec3 ref = ctrl[idx[off[p]]];
  Vec3 d = Vec3::Zero();
  const StencilWeight* w = weights(p);
  for (std::uint32_t k = off[p]; k < off[p + 1]; ++k) d += w[k - off[p]].N * (ctrl[idx[k]] - ref);
  return ref + d;
}

void ShellContact::update_positions(const Vec3* ctrl, bool serial) {
  parallel_for(
      num_sites(), kGrain,
      [&](std::size_t b, std::size_t e) {
        for (std::size_t p = b; p < e; ++p) x[p] = position(ctrl, p);
      },
      serial);
}

void ShellContact::reset(const Vec3* ctrl, bool serial) {
  update_positions(ctrl, serial);
  parallel_for(
      num_sites(), kGrain,
      [&](std::size_t b, std::size_t e) {
        for (std::size_t p = b; p < e; ++p) {
          Vec3 a1, a2;
          tangents(ctrl, p, a1, a2);
          a3e[p] = a1.cross(a2).normalized();
          state[p] = static_cast<std::uint8_t>(ContactState::Separated);
        }
      },
      serial);
  for (Mat3& c : C) c.setZero();
}

double ShellContact::forces(const Vec3* ctrl, Vec3* f, bool serial) {
  // Positions and tangents: those of the last return mapping where it saw these control
  // points, else one pass over each stencil. Then the gradients of kFrameLanes sites at a
  // time (their square roots and divisions overlap), the energy summed in site order.
  const std::size_t nc = num_control_points();
  const bool kept = tangents_ctrl_.size() == nc &&
                    std::memcmp(static_cast<const void*>(tangents_ctrl_.data()),
                                static_cast<const void*>(ctrl), nc * sizeof(Vec3)) == 0;
  const auto separated = static_cast<std::uint8_t>(ContactState::Separated);
  const double e =
      ordered_reduce_chunks(num_sites(), kGrain, serial, 0.0, [&](std::size_t b, std::size_t en) {
        double acc = 0.0;
        // Sites the last return mapping left separated have no force: their a3E is the unit
        // normal of these tangents (s = (0, 0, 1) up to round-off, psi = 0). The others
        // kFrameLanes at a time, in site order.
        std::size_t sites[kFrameLanes];
        int n = 0;
        const auto flush = [&]() {
          GradientLanes gl;
          for (int j = 0; j < kFrameLanes; ++j) {
            const std::size_t p = sites[j < n ? j : 0];  // lanes past n repeat the first
            Vec3 a1, a2;
            if (kept) {
              a1 = a1_[p];
              a2 = a2_[p];
            } else if (j < n) {
              position_and_tangents(ctrl, p, x[p], a1, a2);
            } else {
              a1 = Vec3(gl.a1[0][0], gl.a1[1][0], gl.a1[2][0]);
              a2 = Vec3(gl.a2[0][0], gl.a2[1][0], gl.a2[2][0]);
            }
            for (int c = 0; c < 3; ++c) {
              gl.a1[c][j] = a1[c];
              gl.a2[c][j] = a2[c];
              gl.a3e[c][j] = a3e[p][c];
            }
          }
          contact_lanes::gradients(gl, params_);
          for (int j = 0; j < n; ++j) {
            const std::size_t p = sites[j];
            const Real V = volume[p];
            GradRows& G = G12_[p];
            for (int c = 0; c < 3; ++c) {
              G.g1[c] = V * gl.g[0][c][j];
              G.g2[c] = V * gl.g[1][c][j];
            }
            G3[p] = Vec3(gl.g[2][0][j], gl.g[2][1][j], gl.g[2][2][j]);
            acc += static_cast<double>(V * gl.psi[j]);
          }
          n = 0;
        };
        for (std::size_t p = b; p < en; ++p) {
          if (state[p] == separated) {
            if (!kept) x[p] = position(ctrl, p);
            G12_[p] = GradRows{};
            G3[p] = Vec3::Zero();
            continue;
          }
          sites[n++] = p;
          if (n == kFrameLanes) flush();
        }
        if (n) flush();
        return acc;
      });
  parallel_for(
      num_control_points(), kGrain,
      [&](std::size_t b, std::size_t en) {
        for (std::size_t j = b; j < en; ++j) {
          // acc += N1 G1 + N2 G2 per component, on (x, y, z, 0).
          R4 acc = {};
          for (std::uint32_t k = toff[j]; k < toff[j + 1]; ++k) {
            const GradRows& G = G12_[tsite[k]];
            R4 g1, g2;
            std::memcpy(&g1, G.g1, sizeof g1);
            std::memcpy(&g2, G.g2, sizeof g2);
            acc += tN1[k] * g1 + tN2[k] * g2;
          }
          f[j] -= Vec3(acc[0], acc[1], acc[2]);
        }
      },
      serial);
  return e;
}

double ShellContact::energy(const Vec3* ctrl, bool serial) const {
  return ordered_reduce(num_sites(), kGrain, serial, 0.0, [&](std::size_t p) {
    Vec3 a1, a2;
    tangents(ctrl, p, a1, a2);
    return static_cast<double>(volume[p] *
                               contact_gradient<Real>(a1, a2, a3e[p], params_, nullptr));
  });
}

ShellContact::ReturnMapSums ShellContact::return_map_site(std::size_t p, const FrameLanes& fl,
                                                          int j, bool apart) {
  // The frame in double: in float |q3| = 1 - O(1e-7) with a bias, and rebuilding a3E from
  // it every step would shrink a sticking column steadily (a spurious compression).
  Vec3d q[3];
  for (int i = 0; i < 3; ++i) q[i] = Vec3d(fl.q[i][0][j], fl.q[i][1][j], fl.q[i][2][j]);
  Vec3 s(static_cast<Real>(fl.s[0][j]), static_cast<Real>(fl.s[1][j]),
         static_cast<Real>(fl.s[2][j]));
  // Round-off separation: a column within kSeparationTolerance of its rest length is
  // treated as separated (stored energy below k_c 1e-18 / 3).
  if (s[2] > Real(1) - kSeparationTolerance) s[2] = std::max(s[2], Real(1));
  const Real psi0 = contact_energy_density<Real>(s, params_);
  if (apart) s = Vec3(0, 0, 1);  // separated from every other body: no contact state
  const Real slip0 = std::hypot(s[0], s[1]);
  const ContactState st = contact_return_map<Real>(s, params_);
  a3e[p] = (static_cast<double>(s[0]) * q[0] + static_cast<double>(s[1]) * q[1] +
            static_cast<double>(s[2]) * q[2])
               .cast<Real>();
  state[p] = static_cast<std::uint8_t>(st);
  ReturnMapSums r;
  const double V = static_cast<double>(volume[p]);
  if (st == ContactState::Separated) {
    r.separation = V * static_cast<double>(psi0 - contact_energy_density<Real>(s, params_));
  } else {
    // Counted as in contact when the compression is above round-off.
    r.compressed = s[2] < Real(1) - kCompressionTolerance ? 1 : 0;
    if (st == ContactState::Sliding) {
      // Plastic work: shear stress on the cone times the slip (the return mapping's
      // analogue of sigma_y * delta eps_p; the trial energy's excess over it is a
      // discretization term of order dt).
      const Real slip1 = std::hypot(s[0], s[1]);
      r.sliding = 1;
      r.friction = V * static_cast<double>(params_.gamma) * static_cast<double>(slip1) *
                   static_cast<double>(slip0 - slip1);
    }
  }
  return r;
}

ContactStepStats ShellContact::return_map(const Vec3* ctrl, bool serial,
                                          const std::uint8_t* release) {
  using Acc = ReturnMapSums;
  static_assert(sizeof(StencilWeight) == 3 * sizeof(Real));
  const contact_lanes::SiteStencils stencils{
      ctrl,     off.data(), idx.data(), weight_row_.data(), &weight_table_.data()->N,
      x.data(), a1_.data(), a2_.data()};
  // The frames of kFrameLanes sites at a time (FrameLanes: their square roots and
  // divisions overlap), then each site's return mapping in site order.
  const Acc a =
      ordered_reduce_chunks(num_sites(), kGrain, serial, Acc{}, [&](std::size_t b, std::size_t e) {
        Acc acc;
        // Positions and tangents (kept for the next forces() call): on AVX-512 for the
        // chunk at once, with the same operations.
        const bool wide = simd_level() == SimdLevel::Avx512;
        if (wide) contact_lanes::stencils_avx512(stencils, b, e - b);
        for (std::size_t p0 = b; p0 < e; p0 += kFrameLanes) {
          const int n = static_cast<int>(std::min<std::size_t>(kFrameLanes, e - p0));
          FrameLanes fl;
          for (int j = 0; j < kFrameLanes; ++j) {
            const std::size_t p = p0 + std::size_t(j < n ? j : 0);
            Vec3 a1, a2;
            if (j < n && !wide) {
              position_and_tangents(ctrl, p, x[p], a1, a2);
              a1_[p] = a1;
              a2_[p] = a2;
            } else {
              a1 = a1_[p];
              a2 = a2_[p];
            }
            for (int c = 0; c < 3; ++c) {
              fl.a1[c][j] = static_cast<double>(a1[c]);
              fl.a2[c][j] = static_cast<double>(a2[c]);
              fl.a3e[c][j] = static_cast<double>(a3e[p][c]);
            }
          }
          contact_lanes::frames(fl);
          for (int j = 0; j < n; ++j) {
            const std::size_t p = p0 + std::size_t(j);
            acc += return_map_site(p, fl, j, release && release[p]);
          }
        }
        return acc;
      });
  tangents_ctrl_.assign(ctrl, ctrl + num_control_points());
  ContactStepStats out;
  out.compressed = a.compressed;
  out.sliding = a.sliding;
  out.friction_work = a.friction;
  out.separation_work = a.separation;
  return out;
}

}  // namespace shellmpm
