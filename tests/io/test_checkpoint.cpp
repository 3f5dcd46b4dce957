// Checkpoint files (io/checkpoint): a bit-exact round trip; every damaged byte,
// truncation or extension is refused naming the file; values no run writes (NaN,
// volumes <= 0, ids past next_id, frames < 1) are refused even with a valid checksum;
// a checkpoint that does not fit its scene (material index past the table, ...) is
// refused before the solver reads it; stray file names are skipped with a warning.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "io/checkpoint.h"
#include "io/checksum.h"
#include "io/scene_reader.h"
#include "sim/solver/solver.h"
#include "tests/support/jelly_scene.h"
#include "tests/support/temp_dir.h"

using namespace shellmpm;
using shellmpm_test::read_text;
using shellmpm_test::TempDir;

namespace {

/// A small checkpoint with every section filled: 3 plastic particles, one shell with
/// plastic state and contact data.
Checkpoint small_checkpoint() {
  Checkpoint c;
  c.scene_fingerprint = 0x0123456789abcdefULL;
  c.frame = 3;
  c.time = 2.0 / 24;
  c.particles.keep_plastic = true;
  for (int i = 0; i < 3; ++i) {
    c.particles.push_back(Vec3(Real(0.1 * i), Real(0.5), Real(-0.2 * i)),
                          Vec3(Real(i), Real(-1), 0), Real(1.5e-5), 0, Real(0.9 + 0.01 * i));
    c.particles.C.back() = Mat3::Constant(Real(0.01 * i));
    c.particles.F.back() = Mat3::Identity() * Real(1 + 0.001 * i);
  }
  c.stats_json = R"([{"frame":1},{"frame":2},{"frame":3}])";
  Checkpoint::ShellState sh;
  for (int i = 0; i < 4; ++i) {
    sh.x.emplace_back(Real(i), Real(0.3), Real(0));
    sh.v.emplace_back(Real(0), Real(-0.1 * i), Real(0));
    sh.C.push_back(Mat3::Identity() * Real(0.5 * i));
  }
  sh.plastic = {1, 0, 0, 1, 1, 0, 0, 1};
  sh.a3e = {Vec3(0, 1, 0), Vec3(0, 0.9f, 0.1f)};
  sh.contact_state = {0, 2};  // separated, sliding
  c.shells.push_back(sh);
  c.shell_plastic_work = 0.5;
  c.friction_work = 0.25;
  return c;
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

/// The message of the UserError (CheckpointDamaged, or another precision) that reading
/// `path` throws, or "" when it reads. Any other exception fails the test.
std::string damage_message(const std::string& path) {
  try {
    read_checkpoint(path);
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

/// Writes `c`, then expects reading it to be refused with a message naming the file and
/// containing `what`.
void expect_refused(const TempDir& dir, const Checkpoint& c, const std::string& what) {
  const std::string path = dir.file("checkpoint.0003.bin");
  write_checkpoint(path, c);
  const std::string m = damage_message(path);
  INFO(m);
  CHECK(m.find(path) != std::string::npos);
  CHECK(m.find(what) != std::string::npos);
}

const std::string kScene = shellmpm_test::jelly_scene(5, "  fps: 24\n", "");

/// A checkpoint of the solver's initial state, written as for frame 3.
Checkpoint of_solver(const Solver& s) {
  Checkpoint c;
  c.frame = 3;
  c.time = 2.0 / 24;
  c.particles = s.particles();
  save_shells(s, c);
  c.stats_json = "[]";
  return c;
}

std::string user_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("CRC-32 of the standard check string", "[checkpoint]") {
  CHECK(crc32("123456789", 9) == 0xCBF43926u);
  CHECK(crc32("", 0) == 0u);
  Crc32 c;
  c.update("1234", 4);
  c.update("56789", 5);
  CHECK(c.value() == 0xCBF43926u);
}

TEST_CASE("a checkpoint reads back bit for bit", "[checkpoint]") {
  TempDir dir("ck_roundtrip");
  const Checkpoint a = small_checkpoint();
  const std::string path = dir.file("checkpoint.0003.bin");
  write_checkpoint(path, a);
  const Checkpoint b = read_checkpoint(path);
  CHECK(b.scene_fingerprint == a.scene_fingerprint);
  CHECK(b.frame == a.frame);
  CHECK(b.time == a.time);
  CHECK(b.particles.next_id == a.particles.next_id);
  CHECK(b.particles.keep_plastic);
  CHECK(same_bits(b.particles.x, a.particles.x));
  CHECK(same_bits(b.particles.v, a.particles.v));
  CHECK(same_bits(b.particles.C, a.particles.C));
  CHECK(same_bits(b.particles.F, a.particles.F));
  CHECK(same_bits(b.particles.kind_volume, a.particles.kind_volume));
  CHECK(b.particles.kind_material == a.particles.kind_material);
  CHECK(b.particles.kind == a.particles.kind);
  CHECK(same_bits(b.particles.id, a.particles.id));
  CHECK(same_bits(b.particles.plastic, a.particles.plastic));
  CHECK(b.stats_json == a.stats_json);
  REQUIRE(b.shells.size() == 1);
  CHECK(same_bits(b.shells[0].x, a.shells[0].x));
  CHECK(same_bits(b.shells[0].v, a.shells[0].v));
  CHECK(same_bits(b.shells[0].plastic, a.shells[0].plastic));
  CHECK(same_bits(b.shells[0].C, a.shells[0].C));
  CHECK(same_bits(b.shells[0].a3e, a.shells[0].a3e));
  CHECK(b.shells[0].contact_state == a.shells[0].contact_state);
  CHECK(b.shell_plastic_work == a.shell_plastic_work);
  CHECK(b.friction_work == a.friction_work);
}

TEST_CASE("a checkpoint with empty sections reads back", "[checkpoint]") {
  // A shell-only run has no particles, and a shell without contact no a3e: every empty
  // array's data() may be null (the sanitizer build stopped resuming such runs at the
  // memcpy of a zero-length section; here the round trip itself is checked).
  TempDir dir("ck_empty");
  Checkpoint a = small_checkpoint();
  a.particles = ParticleSet();
  a.shells[0].a3e.clear();
  a.shells[0].contact_state.clear();
  a.shells[0].plastic.clear();
  const std::string path = dir.file("checkpoint.0003.bin");
  write_checkpoint(path, a);
  const Checkpoint b = read_checkpoint(path);
  CHECK(b.particles.size() == 0);
  REQUIRE(b.shells.size() == 1);
  CHECK(b.shells[0].a3e.empty());
  CHECK(b.shells[0].plastic.empty());
  CHECK(same_bits(b.shells[0].x, a.shells[0].x));
}

TEST_CASE("every damaged byte, truncation and extension of a checkpoint is refused naming the file",
          "[checkpoint]") {
  TempDir dir("ck_damage");
  const std::string good_path = dir.file("good.bin");
  write_checkpoint(good_path, small_checkpoint());
  const std::string good = read_text(good_path);
  REQUIRE(damage_message(good_path).empty());
  const std::string path = dir.file("checkpoint.0003.bin");
  auto refused = [&](const std::string& bytes) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
    const std::string m = damage_message(path);
    return !m.empty() && m.find(path) != std::string::npos;
  };
  std::vector<std::size_t> read_anyway;
  for (std::size_t i = 0; i < good.size(); ++i)
    for (unsigned char flip : {0x01, 0x80, 0xFF}) {
      std::string bad = good;
      bad[i] = static_cast<char>(bad[i] ^ flip);
      if (!refused(bad)) read_anyway.push_back(i);
    }
  for (std::size_t n = 0; n < good.size(); ++n)
    if (!refused(good.substr(0, n))) read_anyway.push_back(n);
  if (!refused(good + '\0')) read_anyway.push_back(good.size());
  INFO(good.size() << " bytes; " << read_anyway.size() << " damaged copies read anyway");
  CHECK(read_anyway.empty());
  // The old format and something else entirely.
  CHECK(refused("SHMPMCK2" + good.substr(8)));
  CHECK(refused("hello"));
}

TEST_CASE("values no run writes are refused even under a valid checksum", "[checkpoint]") {
  TempDir dir("ck_values");
  const Real nan = std::numeric_limits<Real>::quiet_NaN();
  const Real inf = std::numeric_limits<Real>::infinity();
  write_checkpoint(dir.file("checkpoint.0003.bin"), small_checkpoint());
  REQUIRE(damage_message(dir.file("checkpoint.0003.bin")).empty());  // unchanged, it reads
  {
    Checkpoint b = small_checkpoint();
    b.particles.x[1].y() = nan;
    expect_refused(dir, b, "particle position[1] is not finite");
  }
  {
    Checkpoint b = small_checkpoint();
    b.particles.v[2].x() = inf;
    expect_refused(dir, b, "particle velocity[2]");
  }
  {
    Checkpoint b = small_checkpoint();
    b.particles.F[0](1, 2) = nan;
    expect_refused(dir, b, "particle deformation gradient[0]");
  }
  {
    Checkpoint b = small_checkpoint();
    b.particles.kind_volume[0] = 0;
    expect_refused(dir, b, "particle kind volume[0]");
  }
  {
    Checkpoint b = small_checkpoint();
    b.particles.kind[1] = 1;  // one kind only
    expect_refused(dir, b, "particle kind[1] is 1, not below the kind count 1");
  }
  {
    Checkpoint b = small_checkpoint();
    b.particles.id[2] = b.particles.next_id;
    expect_refused(dir, b, "particle id[2]");
  }
  // Finite but impossible (a file crafted with a valid checksum, or one a farm node
  // damaged before its checksum was taken).
  {
    Checkpoint b = small_checkpoint();
    b.particles.F[1] = Mat3::Zero();
    expect_refused(dir, b, "particle 1 (id 1) has a deformation gradient of determinant 0");
  }
  {
    Checkpoint b = small_checkpoint();
    b.particles.F[2](0, 0) = -b.particles.F[2](0, 0);  // inverted
    expect_refused(dir, b, "particle 2 (id 2) has a deformation gradient of determinant -");
  }
  {
    Checkpoint b = small_checkpoint();
    b.particles.id[2] = b.particles.id[0];
    expect_refused(dir, b, "two particles have id 0");
  }
  {
    Checkpoint b = small_checkpoint();
    b.shells[0].a3e[1] = Vec3::Zero();
    expect_refused(dir, b, "shell 0 contact particle 1 has a zero normal column");
  }
  {
    Checkpoint b = small_checkpoint();
    b.particles.plastic.clear();  // a plastic set without its plastic state
    expect_refused(dir, b, "particle plastic state has 0 entries, expected 3");
  }
  for (int frame : {0, -5}) {
    Checkpoint b = small_checkpoint();
    b.frame = frame;
    expect_refused(dir, b, "frame " + std::to_string(frame) + " is out of range");
  }
  {
    Checkpoint b = small_checkpoint();
    b.time = -1;
    expect_refused(dir, b, "time");
  }
  {
    Checkpoint b = small_checkpoint();
    b.stats_json = "[{\"frame\":1}";
    expect_refused(dir, b, "statistics are not a JSON array");
  }
  {
    Checkpoint b = small_checkpoint();
    b.shells[0].x[3].z() = nan;
    expect_refused(dir, b, "shell 0 position[3]");
  }
  {
    Checkpoint b = small_checkpoint();
    b.shells[0].v.pop_back();
    expect_refused(dir, b, "shell 0 velocities has 3 entries, expected 4");
  }
  {
    Checkpoint b = small_checkpoint();
    b.friction_work = nan;
    expect_refused(dir, b, "work is not finite");
  }
  {
    Checkpoint b = small_checkpoint();
    b.shells[0].contact_state[1] = 3;  // no ContactState
    expect_refused(dir, b, "shell 0 has a contact state out of range");
  }
  {
    Checkpoint b = small_checkpoint();
    b.shells[0].contact_state.pop_back();
    expect_refused(dir, b, "shell 0 contact states has 1 entries, expected 2");
  }
}

TEST_CASE("a checkpoint that does not fit its scene is refused before the solver reads it",
          "[checkpoint]") {
  TempDir dir("ck_fit");
  const Scene scene = parse_scene(kScene, dir.file("scene.yaml"));
  const std::string path = dir.file("checkpoint.0003.bin");
  {
    Solver solver(scene);
    Checkpoint c = of_solver(solver);
    const std::size_t n = c.particles.size();
    REQUIRE(n > 0);
    c.particles.x[0].x() += Real(0.01);  // a state the solver does not have yet
    const Vec3 moved = c.particles.x[0];
    restore_checkpoint(solver, std::move(c), path);
    CHECK(solver.particles().size() == n);
    CHECK(solver.particles().x[0] == moved);
    CHECK(solver.time() == Approx(2.0 / 24));
  }
  auto refusal = [&](const std::function<void(Checkpoint&)>& damage) {
    Solver solver(scene);
    Checkpoint c = of_solver(solver);
    damage(c);
    return user_error([&] { restore_checkpoint(solver, std::move(c), path); });
  };
  const std::string material = refusal([](Checkpoint& c) { c.particles.kind_material.back() = 1; });
  CHECK(material.find(path) != std::string::npos);
  CHECK(material.find("particle kind 0 has material index 1, the scene has 1 materials") !=
        std::string::npos);
  CHECK(refusal([](Checkpoint& c) {
          c.particles.kind_material.back() = 65535;
        }).find("material index 65535") != std::string::npos);
  CHECK(refusal([](Checkpoint& c) {
          c.particles.keep_plastic = true;
          c.particles.plastic.assign(c.particles.size(), 1);
        }).find("plastic state the scene's materials do not use") != std::string::npos);
  // Positions no run leaves: a particle outside the domain (or at 1e30 m), a shell point
  // a million metres away; the message names the file and the value.
  const std::string far = refusal([](Checkpoint& c) { c.particles.x[0] = Vec3::Constant(1e30f); });
  CHECK(far.find(path) != std::string::npos);
  CHECK(far.find("particle 0 (id ") != std::string::npos);
  CHECK(far.find("is at (1e+30, 1e+30, 1e+30), outside the scene's domain") != std::string::npos);
  CHECK(refusal([](Checkpoint& c) {
          Checkpoint::ShellState sh;
          sh.x = {Vec3(Real(1e6), 0, 0)};
          c.shells.push_back(sh);
        }).find("shell 0 point 0 is at (1e+06, 0, 0), far outside the scene's domain") !=
        std::string::npos);
  CHECK(refusal([](Checkpoint& c) {
          c.particles.x[1].y() = -3;
        }).find("outside the scene's domain") != std::string::npos);
  // The frame field says 1000, the time is frame 3's: nothing would be simulated.
  CHECK(refusal([](Checkpoint& c) { c.frame = 1000; }).find("is not that of frame 1000") !=
        std::string::npos);
  CHECK(refusal([](Checkpoint& c) { c.shells.resize(1); }).find("it has 1 shells, the scene 0") !=
        std::string::npos);
}

TEST_CASE(
    "checkpoints are listed newest first and names that are not a frame are skipped with a warning",
    "[checkpoint]") {
  TempDir dir("ck_list");
  for (const char* name :
       {"checkpoint.0002.bin", "checkpoint.0010.bin", "checkpoint.0004.bin",
        "checkpoint.99999999999.bin", "checkpoint.0000.bin", "checkpoint.000000000007.bin",
        "checkpoint.old.bin", "checkpoint..bin", "checkpoint.0003.bin.tmp.12", "density.0001.vdb"})
    dir.write(name, "x");
  std::vector<std::string> warnings;
  const auto all = list_checkpoints(dir.path.string(), 8, &warnings);
  REQUIRE(all.size() == 3);
  CHECK(all[0].frame == 7);
  CHECK(all[1].frame == 4);
  CHECK(all[2].frame == 2);
  CHECK(all[1].path == dir.file("checkpoint.0004.bin"));
  REQUIRE(warnings.size() == 2);
  std::string joined = warnings[0] + "\n" + warnings[1];
  CHECK(joined.find("checkpoint.99999999999.bin") != std::string::npos);
  CHECK(joined.find("checkpoint.0000.bin") != std::string::npos);
  CHECK(latest_checkpoint(dir.path.string(), 100) == dir.file("checkpoint.0010.bin"));
  CHECK(list_checkpoints(dir.file("missing"), 8).empty());
}
