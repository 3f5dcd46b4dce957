// Crash-safe output (io/atomic_file): every writer checks its writes, and a failed write
// (here: past RLIMIT_FSIZE, which fails like a full disk) leaves the previous file
// intact under its name and no temporary behind.
#include <catch2/catch.hpp>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "io/atomic_file.h"
#include "io/checkpoint.h"
#include "io/density_vdb.h"
#include "io/particle_cache.h"
#include "io/shell_mesh_writer.h"
#include "io/stats_file.h"
#include "render/image.h"
#include "tests/support/file_size_limit.h"
#include "tests/support/temp_dir.h"

using namespace shellmpm;
using shellmpm_test::FileSizeLimit;
using shellmpm_test::read_text;
using shellmpm_test::TempDir;

namespace {

/// `n` particles in a random cloud of width `size` [m], so that every cache grows with n.
ParticleSet cloud(std::size_t n, double size = 1.0) {
  ParticleSet p;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.5 * size, 0.5 * size);
  for (std::size_t i = 0; i < n; ++i)
    p.push_back(Vec3(Real(u(rng)), Real(u(rng)), Real(u(rng))), Vec3(Real(u(rng)), 0, 0),
                Real(1e-6), 0, 0);
  return p;
}

/// A regular n x n grid of vertices, two triangles per cell.
struct GridMesh {
  std::vector<Vec3> x;
  std::vector<Eigen::Vector3i> tri;
  explicit GridMesh(int n) {
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) x.emplace_back(Real(i) / n, 0, Real(j) / n);
    for (int j = 0; j + 1 < n; ++j)
      for (int i = 0; i + 1 < n; ++i) {
        const int a = j * n + i;
        tri.emplace_back(a, a + n, a + 1);
        tri.emplace_back(a + 1, a + n, a + n + 1);
      }
  }
  MeshFrame frame() const {
    MeshFrame m;
    m.positions = x.data();
    m.num_vertices = x.size();
    m.triangles = tri.data();
    m.num_triangles = tri.size();
    m.name = "sheet";
    return m;
  }
};

/// One writer of the tool, with a small and a large output (several times the limit).
struct Writer {
  std::string name;
  std::string file;
  std::function<void(const std::string& path, bool large)> write;
};

std::vector<Writer> all_writers() {
  std::vector<Writer> w;
  w.push_back({"bytes", "b.bin", [](const std::string& path, bool large) {
                 const std::string bytes(large ? 1 << 20 : 10, 'x');
                 write_bytes_atomic(path, bytes.data(), bytes.size());
               }});
  // A writer that never looks at the stream state (as OpenVDB's does): close() must
  // still see the failed writes.
  w.push_back({"careless stream", "s.txt", [](const std::string& path, bool large) {
                 write_stream_atomic(path, [&](CheckedFile& out) {
                   for (int i = 0; i < (large ? 100000 : 2); ++i)
                     out.stream() << "line " << i << "\n";
                 });
               }});
  w.push_back({"density VDB", "density.0006.vdb", [](const std::string& path, bool large) {
                 const ParticleSet p = large ? cloud(20000) : cloud(10, 0.02);
                 VdbOptions o;
                 o.voxel_size = 0.01;
                 o.velocity = true;
                 write_density_vdb(path,
                                   DensityInput{p.x.data(), p.v.data(), p.kind_volume.data(),
                                                p.size(), p.kind.data()},
                                   o);
               }});
  for (MeshFormat f : {MeshFormat::Ply, MeshFormat::Obj, MeshFormat::Glb})
    w.push_back({std::string("shell mesh ") + mesh_format_extension(f),
                 std::string("cloth.0006.") + mesh_format_extension(f),
                 [f](const std::string& path, bool large) {
                   const GridMesh m(large ? 120 : 3);
                   write_shell_mesh(path, m.frame(), f);
                 }});
  w.push_back({"particle cache", "particles.0006.ply", [](const std::string& path, bool large) {
                 write_particle_ply(path, cloud(large ? 20000 : 10));
               }});
  w.push_back({"checkpoint", "checkpoint.0006.bin", [](const std::string& path, bool large) {
                 Checkpoint c;
                 c.frame = 6;
                 c.particles = cloud(large ? 20000 : 10);
                 c.stats_json = "[]";
                 write_checkpoint(path, c);
               }});
  w.push_back({"statistics", "stats.json", [](const std::string& path, bool large) {
                 StatsFile s(path, nlohmann::json::object());
                 for (int f = 1; f <= (large ? 2000 : 1); ++f) {
                   FrameStats fs;
                   fs.frame = f;
                   s.add(fs);
                 }
                 s.write();
               }});
  w.push_back({"preview PNG", "preview.0006.png", [](const std::string& path, bool large) {
                 Image im(large ? 512 : 4, large ? 512 : 4);
                 std::mt19937 rng(3);
                 for (auto& c : im.rgba) c = static_cast<std::uint8_t>(rng());  // incompressible
                 write_png(path, im);
               }});
  return w;
}

}  // namespace

TEST_CASE("CheckedFile writes through write() and a seekable stream", "[atomic]") {
  TempDir dir("checked_file");
  const std::string path = dir.file("a.bin");
  {
    CheckedFile f(path);
    f.write("hello", 5);
    f.stream() << " world";
    const auto end = f.stream().tellp();
    CHECK(end == std::streampos(11));
    f.stream().seekp(0);
    f.stream() << 'J';
    f.stream().seekp(end);
    f.write("!", 1);
    f.close();
  }
  CHECK(read_text(path) == "Jello world!");
  CHECK_THROWS_AS(CheckedFile(dir.file("missing/a.bin")), std::system_error);
}

TEST_CASE("CheckedFile takes empty writes from an empty vector's null data()", "[atomic]") {
  // Checkpoints write empty sections (no particles, no plastic state) with data() null;
  // the sanitizer build caught them reaching memcpy, which must not see a null pointer.
  TempDir dir("checked_file_empty");
  const std::string path = dir.file("e.bin");
  const std::vector<float> empty;
  {
    CheckedFile f(path);
    f.write("a", 1);
    f.stream().write(reinterpret_cast<const char*>(empty.data()), 0);
    f.write(empty.data(), 0);
    f.write("b", 1);
    f.close();
  }
  CHECK(read_text(path) == "ab");
}

TEST_CASE(
    "every writer, past the file size limit: an error naming the file, the old file intact, no "
    "temporary",
    "[atomic]") {
  for (const Writer& w : all_writers()) {
    DYNAMIC_SECTION(w.name) {
      TempDir dir("atomic_limit");
      const std::string path = dir.file(w.file);
      w.write(path, false);
      const std::string before = read_text(path);
      REQUIRE(!before.empty());
      // The large output really is larger than the limit (so the failure below can only
      // come from the limit), and writes fine without it.
      const std::string big = dir.file("unlimited_" + w.file);
      w.write(big, true);
      constexpr std::size_t kLimit = 256 * 1024;
      REQUIRE(std::filesystem::file_size(big) > 2 * kLimit);
      REQUIRE(before.size() < kLimit);

      std::string error;
      {
        FileSizeLimit limit(kLimit);
        REQUIRE(limit.ok());
        try {
          w.write(path, true);
        } catch (const std::exception& e) {
          error = e.what();
        }
      }
      INFO(error);
      CHECK(!error.empty());
      CHECK(error.find(w.file) != std::string::npos);
      CHECK(read_text(path) == before);
      CHECK(dir.temp_files() == 0);
    }
  }
}

TEST_CASE("a density VDB that fails half-way leaves the previous frame readable", "[atomic][vdb]") {
  TempDir dir("atomic_vdb");
  const std::string path = dir.file("density.0006.vdb");
  const ParticleSet small = cloud(50, 0.05), large = cloud(40000);
  VdbOptions o;
  o.voxel_size = 0.01;
  write_density_vdb(path,
                    DensityInput{small.x.data(), nullptr, small.kind_volume.data(), small.size(),
                                 small.kind.data()},
                    o);
  const DensityStats before = read_density_vdb(path);
  constexpr std::size_t kLimit = 512 * 1024;
  write_density_vdb(dir.file("unlimited.vdb"),
                    DensityInput{large.x.data(), nullptr, large.kind_volume.data(), large.size(),
                                 large.kind.data()},
                    o);
  REQUIRE(std::filesystem::file_size(path) < kLimit);
  REQUIRE(std::filesystem::file_size(dir.file("unlimited.vdb")) > 2 * kLimit);
  {
    FileSizeLimit limit(kLimit);
    REQUIRE(limit.ok());
    CHECK_THROWS_AS(
        write_density_vdb(path,
                          DensityInput{large.x.data(), nullptr, large.kind_volume.data(),
                                       large.size(), large.kind.data()},
                          o),
        std::system_error);
  }
  const DensityStats after = read_density_vdb(path);
  CHECK(after.active_voxels == before.active_voxels);
  CHECK(after.integral == before.integral);
  CHECK(dir.temp_files() == 0);
}

TEST_CASE("leftover temporaries are recognised and removed", "[atomic]") {
  CHECK(is_atomic_temp_name("density.0006.vdb.tmp.1234"));
  CHECK(is_atomic_temp_name("preview.mp4.tmp.99.mp4"));
  CHECK(is_atomic_temp_name(atomic_temp_path("stats.json")));
  CHECK_FALSE(is_atomic_temp_name("density.0006.vdb"));
  CHECK_FALSE(is_atomic_temp_name("notes.tmp.txt"));
  CHECK_FALSE(is_atomic_temp_name("a.tmp."));
  CHECK_FALSE(is_atomic_temp_name(".tmp.12"));
  CHECK_FALSE(is_atomic_temp_name("a.tmp.12.tar.gz"));

  TempDir dir("atomic_leftovers");
  dir.write("density.0006.vdb.tmp.1234", "half");
  dir.write("preview.mp4.tmp.99.mp4", "half");
  dir.write("density.0005.vdb", "whole");
  dir.write("notes.tmp.txt", "mine");
  std::filesystem::create_directories(dir.file("sub"));
  dir.write("sub/x.tmp.5", "not looked at");
  CHECK(remove_atomic_temps(dir.path.string()) == 2);
  CHECK(std::filesystem::exists(dir.file("density.0005.vdb")));
  CHECK(std::filesystem::exists(dir.file("notes.tmp.txt")));
  CHECK(std::filesystem::exists(dir.file("sub/x.tmp.5")));
  CHECK_FALSE(std::filesystem::exists(dir.file("density.0006.vdb.tmp.1234")));
  CHECK(remove_atomic_temps(dir.file("missing")) == 0);
}
