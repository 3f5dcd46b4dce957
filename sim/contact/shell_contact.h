// Contact particles of one shell (the supplement's type (iii) particles): fixed
// parametric sites on every triangle of the control mesh, each with its rest volume,
// its position and tangents interpolated from the control points, and its own normal
// column a3E advected with the grid (METHOD.md, "Contact elasticity and friction").
// Also holds the control points' APIC matrices, which exist only when the shell's
// control points are MPM particles.
#pragma once
#include <cstdint>
#include <vector>

#include "sim/contact/contact_energy.h"
#include "sim/contact/contact_lanes.h"
#include "sim/contact/friction_return_map.h"
#include "sim/core/types.h"
#include "sim/shell/loop_basis.h"

namespace shellmpm {

/// Per-step counts of what the friction return mapping did.
struct ContactStepStats {
  std::size_t compressed = 0;  ///< particles with s3 < 1 after the projection
  std::size_t sliding = 0;     ///< particles whose shear was scaled onto the Coulomb cone
  double friction_work = 0;    ///< energy removed by sliding [J]
  double separation_work = 0;  ///< shear energy dropped by separated particles [J]
};

class ShellContact {
 public:
  /// samples: sites per triangle (1, 3, 6 or 7: the Dunavant points, whose weights give
  /// each site's share of the triangle's rest area). Volume = area share * thickness.
  ShellContact(const LoopBasis& basis, const std::vector<Vec3d>& rest, double thickness,
               int samples, const ContactParams& params);

  std::size_t num_sites() const { return volume.size(); }
  std::size_t num_control_points() const { return C.size(); }
  const ContactParams& params() const { return params_; }

  /// Site positions x from the control points.
  void update_positions(const Vec3* ctrl, bool serial);
  /// Contact energy sum V psi [J]. Updates the site positions x (update_positions), stores
  /// dpsi/da3E per site in `G3` (for the grid's normal force) and adds the tangential part, f_j =
  /// -sum_p V_p sum_beta dN_j/dxi_beta dpsi/da_beta, to the control-point forces f (deterministic
  /// gather per point). Sites whose `state` is Separated count zero: the return mapping
  /// that set it made their a3E the unit normal of the control points it saw, which the
  /// explicit step passes here unmoved (s = (0, 0, 1) up to round-off).
  double forces(const Vec3* ctrl, Vec3* f, bool serial);
  /// Energy only [J].
  double energy(const Vec3* ctrl, bool serial) const;
  /// Coulomb return mapping with the current control points and a3E; rewrites a3E and
  /// updates the site positions x. release (may be null): per site, 1 where the site is
  /// apart from every other body (ShellFields::apart_sites): it is reset as separated.
  ContactStepStats return_map(const Vec3* ctrl, bool serial, const std::uint8_t* release = nullptr);
  /// Makes the current shape the contact rest state: a3E = the unit normal, C = 0, and
  /// the positions updated (after a pre-roll moved the control points).
  void reset(const Vec3* ctrl, bool serial);
  /// Tangents a_1, a_2 of site p.
  void tangents(const Vec3* ctrl, std::size_t p, Vec3& a1, Vec3& a2) const;

  // Per site.
  std::vector<Vec3> x;              ///< position (from the control points) [m]
  std::vector<Vec3> a3e;            ///< elastic normal column
  std::vector<Vec3> G3;             ///< dpsi/da3E from the last forces() call [Pa]
  std::vector<Real> volume;         ///< rest volume [m^3]
  std::vector<std::uint8_t> state;  ///< ContactState after the last return mapping
  // Per control point.
  std::vector<Mat3> C;  ///< APIC affine velocity matrix [1/s]

  // Site stencils (CSR): control points idx[k], k in [off[p], off[p+1]), with the basis
  // values weights(p)[k - off[p]].
  std::vector<std::uint32_t> off, idx;
  struct StencilWeight {
    Real N, N1, N2;  ///< N_k, dN_k/dxi1, dN_k/dxi2 at the site
  };
  /// Site p's stencil weights, one per control point. Sites with the same weights (every
  /// site at one place of a regular patch) share one table, so the stencil walks stream
  /// the control point indices only.
  const StencilWeight* weights(std::size_t p) const { return &weight_table_[weight_row_[p]]; }

 private:
  /// The friction return mapping's sums over sites.
  struct ReturnMapSums {
    std::size_t compressed = 0, sliding = 0;
    double friction = 0, separation = 0;
    ReturnMapSums& operator+=(const ReturnMapSums& o) {
      compressed += o.compressed;
      sliding += o.sliding;
      friction += o.friction;
      separation += o.separation;
      return *this;
    }
  };
  static constexpr int kFrameLanes = contact_lanes::kLanes;
  using FrameLanes = contact_lanes::FrameLanes;
  using GradientLanes = contact_lanes::GradientLanes;
  /// The return mapping of site p with its frame in lane j of fl.
  ReturnMapSums return_map_site(std::size_t p, const FrameLanes& fl, int j, bool apart);

  /// Site p's position (update_positions).
  Vec3 position(const Vec3* ctrl, std::size_t p) const;
  /// Site p's position and tangents in one pass over its stencil (the sums of
  /// update_positions and tangents).
  void position_and_tangents(const Vec3* ctrl, std::size_t p, Vec3& xp, Vec3& a1, Vec3& a2) const;

  ContactParams params_;
  // The tangents of the last return mapping and the control points they came from: the
  // next forces() call takes them (and the positions it wrote) instead of walking the
  // stencils again when the control points are bit for bit the same.
  std::vector<Vec3> a1_, a2_, tangents_ctrl_;
  // Transposed stencils for the force gather: for control point j, entries
  // [toff[j], toff[j+1]) name a site and its dN/dxi.
  std::vector<std::uint32_t> toff, tsite;
  std::vector<Real> tN1, tN2;
  // The distinct stencil weights (weights()): site p's from weight_table_[weight_row_[p]].
  std::vector<StencilWeight> weight_table_;
  std::vector<std::uint32_t> weight_row_;
  /// Per site, V dpsi/da1 and V dpsi/da2 of the last forces() call, each as (x, y, z, 0)
  /// in one 32-byte row (the force gather reads both with two vector loads).
  struct GradRows {
    alignas(32) Real g1[4];
    Real g2[4];
  };
  std::vector<GradRows> G12_;
};

}  // namespace shellmpm
