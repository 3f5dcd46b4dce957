// Density fog volumes: MPM particles rasterized with the quadratic B-spline kernel
// and written as an OpenVDB file (DESIGN.md, output conventions: float fog volume
// "density", optional vec3 "vel", frame/time/units metadata, Blosc, optional half).
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>

#include "sim/core/types.h"
#include "sim/scene/scene.h"

namespace shellmpm {

/// Views over particle arrays (not owned); all arrays hold `count` entries.
struct DensityInput {
  const Vec3* positions = nullptr;   ///< world positions [m]
  const Vec3* velocities = nullptr;  ///< [m/s]; may be null when no "vel" grid is asked for
  const Real* volumes = nullptr;     ///< particle volume = mass / rest density [m^3], >= 0
  std::size_t count = 0;
  /// When set, `volumes` is per kind (ParticleSet::kind_volume): particle p's volume is
  /// volumes[kinds[p]].
  const std::uint16_t* kinds = nullptr;

  Real volume(std::size_t p) const { return kinds ? volumes[kinds[p]] : volumes[p]; }
};

/// How to write the volume.
struct VdbOptions {
  double voxel_size = 0.02;  ///< voxel edge h [m]; voxel centers sit at integer multiples of h
  bool velocity = false;     ///< also write the vec3 grid "vel"
  bool half_float = false;   ///< store the grids as 16-bit floats
  int frame = 1;             ///< "frame" metadata
  double time = 0.0;         ///< "time" metadata [s]
  std::string units = "m";   ///< "units" metadata
  /// Axes of the file (output.up_axis). Z: the volume rasterized Y-up, then voxel (i, j, k)
  /// moved to (i, -k, j) and `vel` values (x, y, z) turned to (x, -z, y) (io/vdb_axes.h):
  /// an exact rotation; transform, voxel size and metadata unchanged.
  UpAxis up_axis = UpAxis::Y;
};

/// Rasterizes particles into a fog volume and writes it atomically to `path`.
///
/// density(x_i) = sum_p V_p w(x_i - x_p) / h^3, with w the tensor-product quadratic
/// B-spline N(x/h)N(y/h)N(z/h), N(r) = 3/4 - r^2 for |r| < 1/2, (3/2 - |r|)^2 / 2 for
/// 1/2 <= |r| < 3/2, 0 beyond. Packed material reads ~1 (dimensionless volume fraction)
/// and, by the partition of unity, sum_i density_i h^3 = sum_p V_p up to round-off.
/// "vel" (when asked) is the volume-weighted velocity sum_p V_p w v_p / sum_p V_p w,
/// which is the mass-weighted velocity for a single rest density; it is active exactly
/// where density is. Voxels with zero density are inactive (background 0).
///
/// Deterministic: the values depend only on the input arrays (their order included),
/// never on the TBB thread count. Grid transform: linear, voxel size h, index (i,j,k)
/// centered at (i,j,k)*h. Metadata on both grids and on the file: "frame" (int32),
/// "time" (float, s), "units" (string), "voxel_size" (double, m).
/// Compression: Blosc (+ active mask) when the OpenVDB build has it, else zip.
///
/// Throws std::invalid_argument for a non-positive voxel size, missing arrays, a
/// non-finite position/volume or a position too far out for the index space,
/// and std::system_error / openvdb::Exception for I/O failures.
void write_density_vdb(const std::string& path, const DensityInput& input,
                       const VdbOptions& options);

/// What a density file holds, read back (tests, `shellmpm inspect`).
struct DensityStats {
  std::string grid_name;    ///< first grid's name ("density")
  std::string grid_class;   ///< OpenVDB class name, "fog volume" for ours
  double voxel_size = 0.0;  ///< [m]
  double integral = 0.0;    ///< sum of active values * voxel volume [m^3]
  double max_value = 0.0;   ///< largest density value
  std::uint64_t active_voxels = 0;
  bool has_frame = false, has_time = false;
  int frame = 0;
  double time = 0.0;  ///< [s]
  std::string units;
  bool half_float = false;  ///< saved as half floats
  bool has_vel = false;     ///< a "vel" vec3 grid is present
  std::string compression;  ///< e.g. "BLOSC + ACTIVE_MASK"
};

/// Reads a file written by write_density_vdb. Throws std::runtime_error when the file
/// cannot be opened or has no float grid named "density".
DensityStats read_density_vdb(const std::string& path);

}  // namespace shellmpm
