// Density fog volumes (io/density_vdb) and crash-safe file output (io/atomic_file).
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <tbb/global_control.h>
#include <unistd.h>
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/atomic_file.h"
#include "io/density_vdb.h"
#include "tests/support/temp_dir.h"

namespace fs = std::filesystem;
using namespace shellmpm;
using shellmpm_test::read_text;
using shellmpm_test::TempDir;

namespace {

/// Particles on a regular lattice of spacing h/2 (8 per cell) filling the cells
/// [lo, hi)^3, each of volume (h/2)^3: packed material.
struct Particles {
  std::vector<Vec3> x, v;
  std::vector<Real> vol;
  DensityInput input() const {
    return DensityInput{x.data(), v.empty() ? nullptr : v.data(), vol.data(), x.size()};
  }
  double total_volume() const {
    double s = 0;
    for (Real w : vol) s += w;
    return s;
  }
};

Particles packed_block(double h, int lo, int hi) {
  Particles p;
  for (int k = 2 * lo; k < 2 * hi; ++k)
    for (int j = 2 * lo; j < 2 * hi; ++j)
      for (int i = 2 * lo; i < 2 * hi; ++i) {
        // cell c spans [(c - 1/2) h, (c + 1/2) h); particles at c h -/+ h/4
        p.x.emplace_back(Vec3(Real((i + 0.5) * h / 2 - h / 2), Real((j + 0.5) * h / 2 - h / 2),
                              Real((k + 0.5) * h / 2 - h / 2)));
        p.v.emplace_back(Vec3(1, -2, 0.5));
        p.vol.push_back(Real(h * h * h / 8));
      }
  return p;
}

Particles random_cloud(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> pos(-0.37, 0.52), vol(1e-7, 3e-6), vel(-3, 3);
  Particles p;
  for (std::size_t i = 0; i < n; ++i) {
    p.x.emplace_back(Vec3(Real(pos(rng)), Real(pos(rng) * 0.5), Real(pos(rng) - 0.2)));
    p.v.emplace_back(Vec3(Real(vel(rng)), Real(vel(rng)), Real(vel(rng))));
    p.vol.push_back(Real(vol(rng)));
  }
  return p;
}

openvdb::FloatGrid::Ptr read_float(const std::string& path, const std::string& name) {
  openvdb::initialize();
  openvdb::io::File f(path);
  f.open();
  auto g = openvdb::gridPtrCast<openvdb::FloatGrid>(f.readGrid(name));
  f.close();
  return g;
}

openvdb::Vec3SGrid::Ptr read_vec(const std::string& path, const std::string& name) {
  openvdb::initialize();
  openvdb::io::File f(path);
  f.open();
  auto g = openvdb::gridPtrCast<openvdb::Vec3SGrid>(f.readGrid(name));
  f.close();
  return g;
}

/// Every active voxel of `a` and `b` agrees (same topology, |difference| <= tol).
bool same_values(const openvdb::FloatGrid& a, const openvdb::FloatGrid& b, double tol) {
  if (a.activeVoxelCount() != b.activeVoxelCount()) return false;
  auto acc = b.getConstAccessor();
  for (auto it = a.cbeginValueOn(); it; ++it) {
    if (!acc.isValueOn(it.getCoord())) return false;
    if (std::abs(double(*it) - double(acc.getValue(it.getCoord()))) > tol) return false;
  }
  return true;
}

}  // namespace

TEST_CASE("frame_path pads the '#' run", "[vdb]") {
  CHECK(frame_path("out", "density.####.vdb", 1) == "out/density.0001.vdb");
  CHECK(frame_path("out/", "density.####.vdb", 42) == "out/density.0042.vdb");
  CHECK(frame_path("", "p.##.bin", 7) == "p.07.bin");
  CHECK(frame_path("d", "shell.####.ply", 12345) == "d/shell.12345.ply");
  CHECK(frame_path("d", "#", 3) == "d/3");
  CHECK_THROWS_AS(frame_path("d", "density.vdb", 1), std::invalid_argument);
  CHECK_THROWS_AS(frame_path("d", "a.##.b.##.vdb", 1), std::invalid_argument);
}

TEST_CASE("atomic writes leave no temporaries and never clobber on failure", "[vdb]") {
  TempDir dir("atomic");
  const std::string path = dir.file("stats.json");
  write_text_atomic(path, "first\n");
  CHECK(read_text(path) == "first\n");
  write_text_atomic(path, "second\n");
  CHECK(read_text(path) == "second\n");
  const unsigned char bytes[4] = {0, 1, 2, 255};
  write_bytes_atomic(dir.file("b.bin"), bytes, sizeof bytes);
  CHECK(read_text(dir.file("b.bin")) == std::string("\0\1\2\377", 4));
  CHECK(dir.temp_files() == 0);

  // A writer that fails halfway: the old file stays, the temporary goes.
  CHECK_THROWS_WITH(write_file_atomic(path,
                                      [](const std::string& tmp) {
                                        std::ofstream(tmp) << "half a fr";
                                        throw std::runtime_error("killed");
                                      }),
                    "killed");
  CHECK(read_text(path) == "second\n");
  CHECK(dir.temp_files() == 0);

  // A writer that creates nothing is an error too, and leaves the target alone.
  CHECK_THROWS(write_file_atomic(path, [](const std::string&) {}));
  CHECK(read_text(path) == "second\n");
  // An unwritable target directory.
  CHECK_THROWS(write_text_atomic(dir.file("missing/dir/x.txt"), "x"));
  CHECK(dir.temp_files() == 0);
}

TEST_CASE("density fog volume: class, transform, metadata, exact integral", "[vdb]") {
  TempDir dir("vdb");
  const double h = 0.02;
  const Particles p = packed_block(h, -5, 11);  // 16^3 cells, 32768 particles
  VdbOptions o;
  o.voxel_size = h;
  o.frame = 7;
  o.time = 7 / 24.0;
  o.units = "m";
  const std::string path = frame_path(dir.path.string(), "density.####.vdb", o.frame);
  write_density_vdb(path, p.input(), o);
  CHECK(dir.temp_files() == 0);

  const DensityStats s = read_density_vdb(path);
  CHECK(s.grid_name == "density");
  CHECK(s.grid_class == "fog volume");
  CHECK(s.voxel_size == Approx(h).epsilon(1e-12));
  CHECK(s.has_frame);
  CHECK(s.frame == 7);
  CHECK(s.has_time);
  CHECK(s.time == Approx(7 / 24.0).epsilon(1e-6));
  CHECK(s.units == "m");
  CHECK_FALSE(s.has_vel);
  CHECK_FALSE(s.half_float);
  CHECK(s.compression.find("blosc") != std::string::npos);  // "blosc + active values"
  // Partition of unity: the integral is the particles' total volume (to round-off).
  CHECK(s.integral == Approx(p.total_volume()).epsilon(1e-5));
  // The stencil reaches one voxel beyond the block on every side.
  CHECK(s.active_voxels == 18u * 18u * 18u);

  auto g = read_float(path, "density");
  REQUIRE(g);
  CHECK(g->getGridClass() == openvdb::GRID_FOG_VOLUME);
  CHECK(g->background() == 0.0f);
  // Voxel (i,j,k) is centered at (i,j,k) h in world space.
  const openvdb::Vec3d w = g->indexToWorld(openvdb::Vec3d(3, -2, 5));
  CHECK(w.x() == Approx(3 * h));
  CHECK(w.y() == Approx(-2 * h));
  CHECK(w.z() == Approx(5 * h));
  // File-level metadata as well.
  openvdb::io::File f(path);
  f.open();
  auto meta = f.getMetadata();
  CHECK((*meta)["frame"]->str() == "7");
  CHECK(meta->metaValue<std::string>("units") == "m");
  f.close();
  // Packed material reads 1 inside (8 particles of volume h^3/8 per cell), 0 outside.
  auto acc = g->getConstAccessor();
  for (int i = -4; i <= 9; ++i)
    for (int j = -4; j <= 9; ++j)
      CHECK(acc.getValue(openvdb::Coord(i, j, 3)) == Approx(1.0f).epsilon(1e-5));
  CHECK(acc.getValue(openvdb::Coord(3, 3, -5)) > 0.0f);  // first cell: partly covered
  CHECK(acc.getValue(openvdb::Coord(3, 3, -5)) < 1.0f);
  CHECK(acc.getValue(openvdb::Coord(3, 3, -7)) == 0.0f);
  CHECK_FALSE(acc.isValueOn(openvdb::Coord(3, 3, -7)));
  CHECK(s.max_value == Approx(1.0).epsilon(1e-5));
}

TEST_CASE("density integral equals total volume for a random cloud", "[vdb]") {
  TempDir dir("vdb_random");
  const Particles p = random_cloud(20000, 3);
  for (double h : {0.01, 0.037}) {
    VdbOptions o;
    o.voxel_size = h;
    const std::string path = dir.file("r.vdb");
    write_density_vdb(path, p.input(), o);
    const DensityStats s = read_density_vdb(path);
    CHECK(s.integral == Approx(p.total_volume()).epsilon(1e-4));
  }
}

TEST_CASE("half floats read back within 1e-3", "[vdb]") {
  TempDir dir("vdb_half");
  const Particles p = random_cloud(5000, 5);
  VdbOptions o;
  o.voxel_size = 0.05;
  write_density_vdb(dir.file("full.vdb"), p.input(), o);
  o.half_float = true;
  write_density_vdb(dir.file("half.vdb"), p.input(), o);
  CHECK(read_density_vdb(dir.file("half.vdb")).half_float);
  auto full = read_float(dir.file("full.vdb"), "density");
  auto half = read_float(dir.file("half.vdb"), "density");
  REQUIRE(full->activeVoxelCount() > 100);
  CHECK(full->activeVoxelCount() == half->activeVoxelCount());
  auto acc = half->getConstAccessor();
  for (auto it = full->cbeginValueOn(); it; ++it)
    CHECK(double(acc.getValue(it.getCoord())) == Approx(double(*it)).epsilon(1e-3).margin(1e-6));
  CHECK(fs::file_size(dir.file("half.vdb")) < fs::file_size(dir.file("full.vdb")));
}

TEST_CASE("velocity grid: contravariant, mass-weighted, same topology", "[vdb]") {
  TempDir dir("vdb_vel");
  const double h = 0.02;
  Particles p = packed_block(h, 0, 4);
  // Two overlapping populations with different velocities and volumes.
  Particles q = packed_block(h, 0, 4);
  for (auto& v : q.v) v = Vec3(3, 0, 0);
  for (auto& w : q.vol) w *= 3;
  p.x.insert(p.x.end(), q.x.begin(), q.x.end());
  p.v.insert(p.v.end(), q.v.begin(), q.v.end());
  p.vol.insert(p.vol.end(), q.vol.begin(), q.vol.end());
  VdbOptions o;
  o.voxel_size = h;
  o.velocity = true;
  const std::string path = dir.file("v.vdb");
  write_density_vdb(path, p.input(), o);
  CHECK(read_density_vdb(path).has_vel);
  auto d = read_float(path, "density");
  auto v = read_vec(path, "vel");
  REQUIRE(v);
  CHECK(v->getName() == "vel");
  CHECK(v->getVectorType() == openvdb::VEC_CONTRAVARIANT_RELATIVE);
  CHECK(v->voxelSize()[0] == Approx(h));
  CHECK(v->tree().hasSameTopology(d->tree()));
  REQUIRE(v->activeVoxelCount() > 0);
  // Weighted 1:3 between (1,-2,0.5) and (3,0,0) everywhere.
  for (auto it = v->cbeginValueOn(); it; ++it) {
    CHECK((*it).x() == Approx(2.5).epsilon(1e-5));
    CHECK((*it).y() == Approx(-0.5).epsilon(1e-5));
    CHECK((*it).z() == Approx(0.125).epsilon(1e-5));
  }
  // Asking for velocities without passing them is a programming error.
  DensityInput no_v = p.input();
  no_v.velocities = nullptr;
  CHECK_THROWS_AS(write_density_vdb(dir.file("x.vdb"), no_v, o), std::invalid_argument);
}

TEST_CASE("rasterization does not depend on the thread count", "[vdb]") {
  TempDir dir("vdb_threads");
  const Particles p = random_cloud(60000, 11);
  VdbOptions o;
  o.voxel_size = 0.013;
  o.velocity = true;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    write_density_vdb(dir.file("t1.vdb"), p.input(), o);
  }
  {
    tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
    write_density_vdb(dir.file("t2.vdb"), p.input(), o);
  }
  write_density_vdb(dir.file("tn.vdb"), p.input(), o);
  auto d1 = read_float(dir.file("t1.vdb"), "density");
  CHECK(same_values(*d1, *read_float(dir.file("t2.vdb"), "density"), 0.0));
  CHECK(same_values(*d1, *read_float(dir.file("tn.vdb"), "density"), 0.0));
  auto v1 = read_vec(dir.file("t1.vdb"), "vel");
  auto v2 = read_vec(dir.file("t2.vdb"), "vel");
  auto acc = v2->getConstAccessor();
  bool same = v1->activeVoxelCount() == v2->activeVoxelCount();
  for (auto it = v1->cbeginValueOn(); it && same; ++it) same = *it == acc.getValue(it.getCoord());
  CHECK(same);
}

TEST_CASE("edge cases: empty input, bad input", "[vdb]") {
  TempDir dir("vdb_edge");
  VdbOptions o;
  o.voxel_size = 0.1;
  write_density_vdb(dir.file("empty.vdb"), DensityInput{}, o);
  const DensityStats s = read_density_vdb(dir.file("empty.vdb"));
  CHECK(s.grid_name == "density");
  CHECK(s.active_voxels == 0);
  CHECK(s.integral == 0.0);

  Particles p = random_cloud(10, 1);
  o.voxel_size = 0;
  CHECK_THROWS_AS(write_density_vdb(dir.file("bad.vdb"), p.input(), o), std::invalid_argument);
  o.voxel_size = 0.1;
  p.x[4].y() = std::numeric_limits<Real>::quiet_NaN();
  CHECK_THROWS_WITH(write_density_vdb(dir.file("bad.vdb"), p.input(), o),
                    Catch::Contains("particle 4"));
  CHECK_FALSE(fs::exists(dir.file("bad.vdb")));
  CHECK(dir.temp_files() == 0);
  CHECK_THROWS_AS(read_density_vdb(dir.file("nothing.vdb")), std::runtime_error);
}

TEST_CASE("output.up_axis z: the volume turned exactly, voxel size and metadata kept",
          "[vdb][axes]") {
  TempDir dir("vdb_up_axis");
  Particles p = random_cloud(3000, 11);
  p.v.resize(p.x.size());
  for (std::size_t i = 0; i < p.x.size(); ++i)  // a velocity field with all three components
    p.v[i] = Vec3(Real(0.5) + p.x[i].y(), Real(-1) * p.x[i].z(), Real(2) + p.x[i].x());
  VdbOptions o;
  o.voxel_size = 0.03;
  o.velocity = true;
  o.frame = 4;
  o.time = 0.125;
  o.units = "cm";
  const std::string y_path = dir.file("y.vdb"), z_path = dir.file("z.vdb");
  write_density_vdb(y_path, p.input(), o);
  o.up_axis = UpAxis::Z;
  write_density_vdb(z_path, p.input(), o);

  auto y = read_float(y_path, "density"), z = read_float(z_path, "density");
  auto yv = read_vec(y_path, "vel"), zv = read_vec(z_path, "vel");
  REQUIRE(y);
  REQUIRE(z);
  REQUIRE(yv);
  REQUIRE(zv);
  // The same voxel size, class, transform (a plain scale) and metadata.
  CHECK(z->voxelSize() == y->voxelSize());
  CHECK(z->transform() == y->transform());
  CHECK(z->getGridClass() == openvdb::GRID_FOG_VOLUME);
  CHECK(zv->getVectorType() == openvdb::VEC_CONTRAVARIANT_RELATIVE);
  const DensityStats sy = read_density_vdb(y_path), sz = read_density_vdb(z_path);
  CHECK(sz.frame == sy.frame);
  CHECK(sz.time == sy.time);
  CHECK(sz.units == "cm");
  CHECK(sz.active_voxels == sy.active_voxels);
  CHECK(sz.integral == sy.integral);
  CHECK(z->evalActiveVoxelBoundingBox() != y->evalActiveVoxelBoundingBox());  // it did turn

  // Voxel by voxel: the value at (i, j, k) of the Y-up file sits at (i, -k, j), and the
  // velocity (x, y, z) there reads (x, -z, y).
  auto za = z->getConstAccessor();
  auto zva = zv->getConstAccessor();
  std::size_t checked = 0;
  for (auto it = y->cbeginValueOn(); it; ++it) {
    const openvdb::Coord c = it.getCoord();
    const openvdb::Coord r(c.x(), -c.z(), c.y());
    REQUIRE(za.isValueOn(r));
    REQUIRE(za.getValue(r) == *it);
    const openvdb::Vec3s u = yv->tree().getValue(c), w = zva.getValue(r);
    REQUIRE(w == openvdb::Vec3s(u.x(), -u.z(), u.y()));
    ++checked;
  }
  CHECK(checked == sy.active_voxels);

  // In world space: the density at p in the Y-up file equals the density at R p in the
  // Z-up one, R the +90 degree turn about X, sampled trilinearly between voxels.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sy_w(*y),
      sz_w(*z);
  int inside = 0;
  for (int s = 0; s < 500; ++s) {
    const openvdb::Vec3d q(u(rng), u(rng), u(rng));
    const float a = sy_w.wsSample(q), b = sz_w.wsSample(openvdb::Vec3d(q.x(), -q.z(), q.y()));
    INFO("p " << q);
    CHECK(b == Approx(a).epsilon(1e-5).margin(1e-7));
    inside += a > 0;
  }
  CHECK(inside > 10);
}
