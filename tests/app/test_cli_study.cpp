// `shellmpm study --quick` and `shellmpm converge`: the study machinery end to end on small
// problems (the full study is `shellmpm study`, see docs/accuracy.md).
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "tests/app/cli_harness.h"

using namespace shellmpm_test;

namespace {

bool have_matplotlib() {
  return run_command("/usr/bin/python3 -c 'import matplotlib'").code == 0;
}

}  // namespace

TEST_CASE("CLI: study --quick runs two resolutions of the plate; the error falls, files written",
          "[study][cli]") {
  TempDir dir("study_quick");
  const std::string out = dir.file("study");
  const CmdResult r =
      run_shellmpm("study --suite plate_simply_supported --quick --threads 1 -o " + out);
  INFO(r.output);
  REQUIRE(r.code == 0);
  const nlohmann::json j = nlohmann::json::parse(read_text(out + "/results.json"));
  REQUIRE(j["problems"].size() == 1);
  const nlohmann::json& p = j["problems"][0];
  CHECK(p["name"] == "plate_simply_supported");
  REQUIRE(p["runs"].size() == 2);
  for (const nlohmann::json& run : p["runs"]) {
    CHECK(run["status"] == "ok");
    CHECK(run["wall_seconds"].get<double>() > 0);
    CHECK(run["peak_rss_bytes"].get<double>() > 1e6);
    CHECK(run["shell_points"].get<long>() > 0);
  }
  // The reference is the same for both (it depends on the plate, not the mesh).
  CHECK(p["runs"][0]["reference"].get<double>() == Approx(p["runs"][1]["reference"].get<double>()));
  const double e8 = std::abs(p["runs"][0]["error"].get<double>());
  const double e16 = std::abs(p["runs"][1]["error"].get<double>());
  INFO("n=8 error " << e8 << ", n=16 error " << e16);
  CHECK(e16 < 0.75 * e8);
  CHECK(e16 < 0.1);  // within 10% of Timoshenko's plate at 16 x 16
  const std::string csv = read_text(out + "/results.csv");
  CHECK(std::count(csv.begin(), csv.end(), '\n') == 3);  // header + 2 runs
  CHECK(read_text(out + "/summary.md").find("Timoshenko") != std::string::npos);
  if (have_matplotlib()) {
    CHECK(std::filesystem::file_size(out + "/pareto_plate_simply_supported.png") > 1000);
    CHECK(std::filesystem::file_size(out + "/convergence_plate_simply_supported.png") > 1000);
    CHECK(std::filesystem::exists(out + "/study_overview.png"));
  } else {
    WARN("matplotlib missing: plots not checked");
    CHECK(r.output.find("plots skipped") != std::string::npos);
  }
  // Runs that succeeded leave nothing behind unless --keep-runs.
  CHECK_FALSE(std::filesystem::exists(out + "/runs/plate_simply_supported/run0/stats.json"));
}

TEST_CASE("CLI: study without Python's matplotlib still writes results and says why",
          "[study][cli]") {
  TempDir dir("study_noplot");
  const std::string out = dir.file("study");
  const CmdResult r =
      run_shellmpm("study --suite plate_simply_supported --quick --threads 1 -o " + out,
                   "SHELLMPM_PYTHON=/nonexistent PATH=/nowhere");
  INFO(r.output);
  // /usr/bin/python3 is tried by path even without PATH; the message or the plots appear.
  REQUIRE(r.code == 0);
  CHECK(std::filesystem::exists(out + "/results.json"));
  CHECK((r.output.find("plots skipped") != std::string::npos ||
         r.output.find("wrote") != std::string::npos));
}

TEST_CASE("CLI: study and converge refuse bad input with the flag or key named", "[study][cli]") {
  TempDir dir("study_bad");
  const CmdResult a = run_shellmpm("study --suite nope -o " + dir.file("s"));
  CHECK(a.code == 2);
  CHECK(a.output.find("--suite nope") != std::string::npos);
  CHECK(a.output.find("plate_simply_supported") != std::string::npos);
  const std::string scene = dir.write("jelly.yaml", tiny_jelly_scene(3, dir.file("o")));
  const CmdResult b = run_shellmpm(
      "converge " + scene + " --vary shot.nope=1,2 --measure bulk.centroid.y -o " + dir.file("c"));
  CHECK(b.code == 2);
  CHECK(b.output.find("shot.nope") != std::string::npos);
  const CmdResult c =
      run_shellmpm("converge " + scene +
                   " --vary shot.dx=0.1,0.05 --measure shell.cloth.lowest -o " + dir.file("c"));
  CHECK(c.code == 2);
  CHECK(c.output.find("no shell 'cloth'") != std::string::npos);
  const CmdResult d =
      run_shellmpm("converge " + scene +
                   " --vary shot.dx=0.1,0.05,x --measure bulk.centroid.y -o " + dir.file("c"));
  CHECK(d.code == 2);
  CHECK(d.output.find("shot.dx") != std::string::npos);
}

TEST_CASE("CLI: converge measures a shot at three spacings and extrapolates", "[study][cli]") {
  TempDir dir("converge");
  const std::string scene = dir.write("jelly.yaml", tiny_jelly_scene(13, dir.file("o")));
  const std::string out = dir.file("conv");
  const CmdResult r = run_shellmpm("converge " + scene +
                                   " --vary shot.dx=0.1,0.05,0.025 --measure bulk.centroid.y "
                                   "--threads 1 -o " +
                                   out);
  INFO(r.output);
  REQUIRE(r.code == 0);
  const nlohmann::json j = nlohmann::json::parse(read_text(out + "/converge.json"));
  REQUIRE(j["settings"].size() == 3);
  // The jelly falls freely for 0.05 s (it starts 0.3 m up): its centroid is near
  // 0.4 - g t^2 / 2 = 0.3877 m in every setting.
  for (const nlohmann::json& s : j["settings"]) {
    CHECK(s["value"].get<double>() == Approx(0.4 - 0.5 * 9.81 * 0.05 * 0.05).margin(2e-3));
    CHECK(s["wall_seconds"].get<double>() > 0);
  }
  CHECK(j["settings"][2]["h"].get<double>() == Approx(0.025));
  CHECK(r.output.find("wrote") != std::string::npos);
}

TEST_CASE("CLI: the full study runs every problem within its budget; the converging ones converge",
          "[study][cli][slow]") {
  // The command docs/accuracy.md's figures come from (6.5 minutes on 2 quiet cores).
  TempDir dir("study_full");
  const std::string out = dir.file("study");
  const CmdResult r = run_shellmpm("study --threads 2 -o " + out);
  INFO(r.output.substr(r.output.size() > 4000 ? r.output.size() - 4000 : 0));
  REQUIRE(r.code == 0);
  const nlohmann::json j = nlohmann::json::parse(read_text(out + "/results.json"));
  CHECK(j["problems"].size() == 9);
  for (const nlohmann::json& p : j["problems"]) {
    const std::string name = p["name"];
    INFO(name);
    for (const nlohmann::json& run : p["runs"]) {
      INFO(run["label"].get<std::string>() << ": " << run.value("note", ""));
      CHECK(run["status"] != "failed");
      CHECK(run["status"] != "skipped");  // the default budget holds the whole study
    }
    // Problems with a smooth answer converge: the error falls at every refinement and the
    // Richardson limit lands within 0.5% of the reference. The bar's contact time falls at
    // every refinement too, to within 0.5% at the finest grid, but not at a steady order
    // (surface contact with the wall moves with the particle spacing), so it has no limit.
    const bool smooth = name == "plate_simply_supported" || name == "cantilever_gravity" ||
                        name == "cantilever_vibration";
    const bool falls = smooth || name == "bar_impact";
    if (!falls) continue;
    const nlohmann::json& sweep = p["sweeps"][0];
    REQUIRE(sweep["refinement"] == true);
    double previous = INFINITY;
    for (int i : sweep["runs"]) {
      const double e = std::abs(p["runs"][i]["error"].get<double>());
      CHECK(e < previous);
      previous = e;
    }
    if (!smooth) {
      CHECK(previous < 0.005);  // a relative error
      continue;
    }
    REQUIRE(sweep.contains("richardson"));
    const double ref = p["runs"][sweep["runs"][0].get<int>()]["reference"];
    CHECK(sweep["richardson"]["limit"].get<double>() == Approx(ref).epsilon(0.005));
    CHECK(sweep["fitted_order"].get<double>() > 0.6);
  }
  CHECK(std::filesystem::exists(out + "/results.csv"));
  CHECK(std::filesystem::exists(out + "/summary.md"));
}
