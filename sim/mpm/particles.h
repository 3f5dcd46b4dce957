// Bulk MPM particles, stored as named attribute arrays (house style 6).
#pragma once
#include <cstdint>
#include <vector>

#include "sim/core/types.h"

namespace shellmpm {

/// Structure of arrays. Mass is volume * rest density of the particle's material.
///
/// A particle's material and rest volume are those of its kind: the particles of one
/// source share both (one sampling spacing), so they are kept once per kind, not per
/// particle (a 2-byte kind instead of a 4-byte volume and a 2-byte material).
struct ParticleSet {
  std::vector<Vec3> x;              ///< position [m]
  std::vector<Vec3> v;              ///< velocity [m/s]
  std::vector<Mat3> C;              ///< APIC affine velocity matrix [1/s]
  std::vector<Mat3> F;              ///< (elastic) deformation gradient
  std::vector<std::uint16_t> kind;  ///< index into kind_material and kind_volume
  std::vector<std::uint32_t> id;    ///< stable id, in order of creation
  std::vector<Real> plastic;        ///< plastic scalar; empty when no material needs it
  /// Per kind: index into the solver's material table, and rest volume V0 [m^3].
  std::vector<std::uint16_t> kind_material;
  std::vector<Real> kind_volume;

  std::size_t size() const { return x.size(); }
  std::uint16_t material_of(std::size_t i) const { return kind_material[kind[i]]; }
  Real volume_of(std::size_t i) const { return kind_volume[kind[i]]; }
  /// The kind of material `mat` and rest volume `vol`, added when new (at most 65,536).
  std::uint16_t kind_of(std::uint16_t mat, Real vol);
  bool has_plastic() const { return keep_plastic; }
  bool keep_plastic = false;  ///< allocate `plastic` (set when any material is plastic)

  /// Appends one particle at rest deformation.
  void push_back(const Vec3& pos, const Vec3& vel, Real vol, std::uint16_t mat, Real plastic0) {
    x.push_back(pos);
    v.push_back(vel);
    C.push_back(Mat3::Zero());
    F.push_back(Mat3::Identity());
    kind.push_back(kind_of(mat, vol));
    id.push_back(next_id++);
    if (keep_plastic) plastic.push_back(plastic0);
  }
  /// Room for `n` more particles. exact: exactly that many (the sources' initial fill,
  /// whose count is known); otherwise at least 1.5x the current size, so that emission
  /// step after step stays amortised O(1) per particle. Without it push_back's doubling
  /// left up to twice the memory: 209 B per particle at 1M and 4M particles against 106
  /// at 262,144 = 2^18 (bench/cost_model).
  void reserve_more(std::size_t n, bool exact);
  /// Reorders every attribute so that new index i holds old index order[i].
  void permute(const std::vector<std::uint32_t>& order);
  /// Bytes held by the particle arrays (capacity), per particle when divided by size().
  std::size_t bytes() const;

  std::uint32_t next_id = 0;
};

}  // namespace shellmpm
