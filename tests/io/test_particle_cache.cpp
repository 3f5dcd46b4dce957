// Particle caches (io/particle_cache): positions, velocities and ids per particle, in the
// axes output.up_axis asks for.
#include <catch2/catch.hpp>

#include <fstream>
#include <iterator>
#include <string>

#include "io/particle_cache.h"
#include "io/ply_reader.h"
#include "tests/support/ply_cache.h"
#include "tests/support/temp_dir.h"

using namespace shellmpm;
using shellmpm_test::TempDir;

TEST_CASE("particle cache: known points and velocities, turned for up_axis z",
          "[particles][axes]") {
  TempDir dir("particle_cache_axes");
  ParticleSet p;
  p.push_back(Vec3(Real(0.25), Real(1.5), Real(-0.75)), Vec3(Real(1), Real(-2), Real(3)),
              Real(1e-6), 0, Real(0));
  p.push_back(Vec3(Real(-0.1), Real(0.2), Real(0.3)), Vec3(Real(0), Real(-9.5), Real(0.5)),
              Real(1e-6), 0, Real(0));
  const std::string y = dir.file("y.ply"), z = dir.file("z.ply");
  write_particle_ply(y, p);
  write_particle_ply(z, p, UpAxis::Z);
  const shellmpm_test::ParticleFrame fy = shellmpm_test::read_particle_ply(y);
  const shellmpm_test::ParticleFrame fz = shellmpm_test::read_particle_ply(z);
  REQUIRE(fy.x.size() == 2);
  REQUIRE(fz.x.size() == 2);
  // Y up: as simulated. Z up: (x, y, z) -> (x, -z, y), for positions and velocities.
  CHECK(fy.x[0] == Eigen::Vector3d(0.25, 1.5, -0.75));
  CHECK(fz.x[0] == Eigen::Vector3d(0.25, 0.75, 1.5));
  CHECK(fy.v[0] == Eigen::Vector3d(1, -2, 3));
  CHECK(fz.v[0] == Eigen::Vector3d(1, -3, -2));
  for (int i = 0; i < 2; ++i) {
    CHECK(fz.x[i] == Eigen::Vector3d(fy.x[i].x(), -fy.x[i].z(), fy.x[i].y()));
    CHECK(fz.v[i] == Eigen::Vector3d(fy.v[i].x(), -fy.v[i].z(), fy.v[i].y()));
    CHECK(fz.id[i] == fy.id[i]);
  }
  // The project's reader (the preview renderer's) reads both.
  CHECK(read_ply(z).positions[1] == Vec3f(-0.1f, -0.3f, 0.2f));
  std::ifstream in(z, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(bytes.find("comment up_axis z\n") < bytes.find("end_header"));
}
