// The sand column's run-out (study/reference_problems.cpp) holds for a deposit at rest:
// a run whose front still moves is reported as doubtful, with how far it moved.
#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "io/particle_cache.h"
#include "io/scene_reader.h"
#include "study/reference_problem.h"
#include "study/run_folder.h"
#include "tests/support/temp_dir.h"

using namespace shellmpm;
using shellmpm_test::TempDir;

namespace {

const ReferenceProblem& sand_problem() {
  static const std::vector<ReferenceProblem> all = reference_problems();
  for (const ReferenceProblem& p : all)
    if (p.name == "sand_column") return p;
  FAIL("no sand_column problem");
  return all.front();
}

// A fake run: frames 1..5 at 24 fps, one grain at front(frame) metres along x.
void write_run(const std::string& dir, double (*front)(int)) {
  std::ofstream st(dir + "/stats.json");
  st << R"({"frames": [)";
  for (int f = 1; f <= 5; ++f) {
    st << (f > 1 ? "," : "") << R"({"frame": )" << f << R"(, "time": )" << (f - 1) / 24.0 << "}";
    ParticleSet p;
    p.push_back(Vec3(0, 0.01f, 0), Vec3::Zero(), Real(1e-6), 0, 0);
    p.push_back(Vec3(Real(front(f)), 0.01f, 0), Vec3::Zero(), Real(1e-6), 0, 0);
    char name[64];
    std::snprintf(name, sizeof name, "/particles.%04d.ply", f);
    write_particle_ply(dir + name, p);
  }
  st << "]}";
}

}  // namespace

TEST_CASE("a sand front that still moves is doubtful, one at rest is not", "[study]") {
  const Scene s = read_scene(std::string(SHELLMPM_SOURCE_DIR) + "/scenes/study/sand_column.yaml");
  const ReferenceProblem& p = sand_problem();
  REQUIRE(p.doubt);
  TempDir d("sand_doubt");
  std::filesystem::create_directories(d.file("rest"));
  std::filesystem::create_directories(d.file("creep"));
  // L0 = 0.1 m: 1% is 1 mm over the last 0.1 s (frames 2..5 span 0.125 s).
  write_run(d.file("rest"), [](int f) { return 0.2 + 0.0002 * f; });
  write_run(d.file("creep"), [](int f) { return 0.2 + 0.004 * f; });
  const RunFolder rest(d.file("rest")), creep(d.file("creep"));
  CHECK(p.measure(rest, s) == Approx(0.201).epsilon(1e-5));
  CHECK(p.doubt(rest, s).empty());
  const std::string why = p.doubt(creep, s);
  INFO(why);
  CHECK(why.find("has not stopped") != std::string::npos);
  CHECK(why.find("12.0 mm in the last 0.125 s") != std::string::npos);  // 3 frames x 4 mm
}
