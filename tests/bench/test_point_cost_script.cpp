// bench/point_cost.sh reads the two benchmarks' output and prints the point-cost ratio:
// checked on stand-in benchmarks with known figures, and on bad options.
#include <catch2/catch.hpp>
#include <filesystem>

#include "tests/app/cli_harness.h"

using namespace shellmpm_test;

namespace {

const std::string kScript = std::string(SHELLMPM_SOURCE_DIR) + "/bench/point_cost.sh";

/// A build folder whose bench/ programs print the given text.
std::string fake_build(const TempDir& d, const std::string& contact, const std::string& bulk) {
  std::filesystem::create_directories(d.file("b/bench"));
  for (const auto& [name, text] :
       {std::pair{"contact_throughput", contact}, {"mpm_throughput", bulk}}) {
    const std::string f =
        d.write(std::string("b/bench/") + name, "#!/bin/sh\ncat <<'X'\n" + text + "X\n");
    std::filesystem::permissions(f, std::filesystem::perms::owner_all);
  }
  return d.file("b");
}

}  // namespace

TEST_CASE("point_cost.sh: the ratio of a point's cost to a bulk particle-step", "[bench]") {
  TempDir d("point_cost");
  // 300 points at 60 ms per step: 200 us per point; the bulk at 10 M/s: 0.1 us -> 2000x.
  // At 2 threads: 30 ms -> 100 us against 0.05 us -> 2000x too, 1 and 2 differ in ms.
  const std::string build = fake_build(
      d,
      "contact_throughput: cloth 9x9 quads (100 control points, 200 contact particles), float\n"
      "threads 1: 60.0 ms per step, 937 steps per frame\n"
      "threads 2: 30.0 ms per step, 937 steps per frame\n",
      "threads 1: 512000 particles, 1.0 s, 10.00 M particle-steps/s (10.00 M per thread)\n"
      "threads 2: 512000 particles, 0.5 s, 20.00 M particle-steps/s (10.00 M per thread)\n");
  const CmdResult r = run_command("sh " + kScript + " --build " + build + " --rounds 2");
  INFO(r.output);
  REQUIRE(r.code == 0);
  CHECK(r.output.find("round 1, 1 thread(s): 60.0 ms per step, 200.000 us per point, bulk "
                      "0.1000 us per particle-step: 2000.00x") != std::string::npos);
  CHECK(r.output.find("round 2, 2 thread(s): 30.0 ms per step, 100.000 us per point, bulk "
                      "0.0500 us per particle-step: 2000.00x") != std::string::npos);
  CHECK(r.output.find("1 thread(s): 2000.00-2000.00x over 2 round(s)") != std::string::npos);
}

TEST_CASE("point_cost.sh: bad options and unreadable output are refused", "[bench]") {
  TempDir d("point_cost_bad");
  const std::string build = fake_build(d, "no figures here\n", "nor here\n");
  CmdResult r = run_command("sh " + kScript + " --build " + build + " --rounds 0");
  CHECK(r.code == 2);
  CHECK(r.output.find("--rounds must be a positive integer") != std::string::npos);
  r = run_command("sh " + kScript + " --build " + build + " --frames 3");
  CHECK(r.code == 2);
  CHECK(r.output.find("unknown option --frames") != std::string::npos);
  r = run_command("sh " + kScript + " --build " + d.file("nowhere"));
  CHECK(r.code == 2);
  CHECK(r.output.find("is not an executable") != std::string::npos);
  r = run_command("sh " + kScript + " --build " + build + " --rounds 1 --threads 1");
  CHECK(r.code != 0);
  CHECK(r.output.find("could not read the benchmarks' output") != std::string::npos);
}
