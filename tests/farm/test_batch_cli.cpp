// The batch commands through the binary, with the local engine: plan, run (two at a time,
// skipping finished tasks), task, status and collect on a 2 x 2 batch of tiny jelly shots;
// a batch whose scene fails check refused before anything is written; a failing task that
// does not stop the others; SIGTERM to a running batch, and the batch run again finishing
// byte-identical to an uninterrupted one.
#include <signal.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/app/cli_harness.h"
#include "tests/app/cli_process.h"
#include "tests/farm/farm_fixtures.h"

namespace fs = std::filesystem;
using namespace shellmpm_test;

namespace {

const char* const kIds[] = {"soft/velocity-0_0_0", "soft/velocity-0_-1_0", "stiff/velocity-0_0_0",
                            "stiff/velocity-0_-1_0"};

int count(const std::string& s, const std::string& what) {
  int n = 0;
  for (std::size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

std::string frame_file(const std::string& dir, const char* stem, int frame, const char* ext) {
  char name[64];
  std::snprintf(name, sizeof name, "/%s.%04d.%s", stem, frame, ext);
  return dir + name;
}

/// Every particle cache and density frame (but for the VDB file's random UUID) and the
/// physics of stats.json (no wall times) of two task folders are byte-identical.
void check_same_caches(const std::string& a, const std::string& b, int frames) {
  for (int f = 1; f <= frames; ++f) {
    INFO(a << " frame " << f);
    const std::string p = read_text(frame_file(a, "particles", f, "ply"));
    REQUIRE(p.size() > 1000);
    CHECK(p == read_text(frame_file(b, "particles", f, "ply")));
    const std::string x = cache_bytes(frame_file(a, "density", f, "vdb"));
    REQUIRE(x.size() > 100);
    CHECK(x == cache_bytes(frame_file(b, "density", f, "vdb")));
  }
  auto physics = [](const std::string& dir) {
    nlohmann::json j = nlohmann::json::parse(read_text(dir + "/stats.json"));
    for (auto& f : j["frames"]) f.erase("wall");
    return j["frames"].dump();
  };
  CHECK(physics(a) == physics(b));
}

}  // namespace

TEST_CASE("batch: plan, run two at a time, skip what is done, task, status and collect",
          "[farm][batch]") {
  TempDir d("farm_cli");
  write_jelly(d, 3);
  const std::string batch = d.write("b.yaml", two_by_two_batch(3));

  const CmdResult plan = run_shellmpm("batch plan " + batch + " --slots 2");
  INFO(plan.output);
  REQUIRE(plan.code == 0);
  for (const char* id : kIds) CHECK(plan.output.find(id) != std::string::npos);
  CHECK(plan.output.find("sources[0].velocity=[0, -1, 0]") != std::string::npos);
  CHECK(plan.output.find("MiB") != std::string::npos);
  CHECK_FALSE(fs::exists(d.file("out")));  // plan writes nothing

  const CmdResult run = run_shellmpm("batch run " + batch + " --slots 2");
  INFO(run.output);
  REQUIRE(run.code == 0);
  CHECK(run.output.find("4 tasks, 4 to run, 2 at a time with 1 thread each") != std::string::npos);
  CHECK(run.output.find("4 done, 0 previews, 0 skipped (done before), 0 failed") !=
        std::string::npos);
  for (const char* id : kIds) {
    const std::string out = d.file("out/") + id;
    CHECK(fs::exists(frame_file(out, "density", 3, "vdb")));
    const nlohmann::json m = nlohmann::json::parse(read_text(out + "/run.json"));
    REQUIRE(m.contains("wedge"));
    CHECK(m["wedge"]["shot"].get<std::string>() + "/" + m["wedge"]["wedge"].get<std::string>() ==
          id);
    CHECK(m["wedge"]["values"].contains("sources[0].velocity"));
  }
  // The two wedge members differ, and so do the shots.
  CHECK(read_text(d.file("out/soft/velocity-0_0_0/particles.0003.ply")) !=
        read_text(d.file("out/soft/velocity-0_-1_0/particles.0003.ply")));

  const CmdResult again = run_shellmpm("batch run " + batch);
  INFO(again.output);
  CHECK(again.code == 0);
  CHECK(again.output.find("nothing to do: all 4 tasks of batch tiny are done") !=
        std::string::npos);
  const CmdResult one = run_shellmpm("batch task " + batch + " 2");
  CHECK(one.code == 0);
  CHECK(one.output.find("task 2 (stiff/velocity-0_0_0): already done (3 frames") !=
        std::string::npos);
  const CmdResult bad_index = run_shellmpm("batch task " + batch + " 4");
  CHECK(bad_index.code == 2);
  CHECK(bad_index.output.find("no task 4: the batch has 4 (0-3)") != std::string::npos);

  const CmdResult status = run_shellmpm("batch status " + batch);
  INFO(status.output);
  REQUIRE(status.code == 0);
  CHECK(count(status.output, " done ") == 4);
  CHECK(count(status.output, "3/3") == 4);
  CHECK(status.output.find("batch tiny: 4 tasks, 4 done") != std::string::npos);
  const nlohmann::json sj =
      nlohmann::json::parse(run_shellmpm("batch status --json " + batch).output);
  REQUIRE(sj["tasks"].size() == 4);
  for (const auto& t : sj["tasks"]) {
    CHECK(t["state"] == "done");
    CHECK(t["restarts"] == 0);
    CHECK(t["last_exit"] == 0);
    CHECK(t["wall_seconds"].get<double>() > 0);
  }

  const CmdResult col = run_shellmpm("batch collect -q " + batch);
  INFO(col.output);
  REQUIRE(col.code == 0);
  const std::string csv = read_text(d.file("out/wedge_table.csv"));
  CHECK(count(csv, "\n") == 5);
  CHECK(csv.rfind("task,shot,wedge,sources[0].velocity,state,frames,restarts,wall_seconds,", 0) ==
        0);
  CHECK(csv.find("\n1,soft,velocity-0_-1_0,\"[0, -1, 0]\",done,3/3,0,") != std::string::npos);
  const std::string md = read_text(d.file("out/wedge_table.md"));
  CHECK(count(md, "\n") == 6);
  const nlohmann::json wj = nlohmann::json::parse(read_text(d.file("out/wedge_table.json")));
  REQUIRE(wj["tasks"].size() == 4);
  for (const auto& t : wj["tasks"]) {
    CHECK(t["state"] == "done");
    CHECK(t["stats"]["max_speed"].get<double>() > 0);
    CHECK(t["integrity"].is_string());
  }
  // The falling block is faster with the extra 1 m/s.
  CHECK(wj["tasks"][1]["stats"]["max_speed"].get<double>() >
        wj["tasks"][0]["stats"]["max_speed"].get<double>() + 0.5);
  const std::string html = read_text(d.file("out/review.html"));
  CHECK(count(html, "<tbody class=\"task\"") == 4);
}

TEST_CASE("batch: a batch whose scenes fail check is refused and nothing is written",
          "[farm][batch]") {
  TempDir d("farm_refuse");
  write_jelly(d, 2);
  const std::string batch =
      d.write("b.yaml",
              "version: 1\noutput: out\nshots:\n  - name: a\n    scene: jelly.yaml\n"
              "  - name: b\n    scene: jelly.yaml\n    set:\n      shot.dx: -0.1\n");
  for (const char* cmd : {"plan", "run", "submit --dry-run"}) {
    const CmdResult r = run_shellmpm(std::string("batch ") + cmd + " " + batch);
    INFO(cmd << ": " << r.output);
    CHECK(r.code == 2);
    CHECK(r.output.find(batch + ":9: shots[1].set.shot.dx: ") != std::string::npos);
    CHECK(r.output.find("(task 1, b/base)") != std::string::npos);
  }
  CHECK_FALSE(fs::exists(d.file("out")));
  const CmdResult unknown =
      run_shellmpm("batch plan " + d.write("u.yaml", "version: 1\nshot: 1\n"));
  CHECK(unknown.code == 2);
  CHECK(unknown.output.find(d.file("u.yaml") + ":2: shot: unknown key 'shot'") !=
        std::string::npos);
}

TEST_CASE("batch: a failing task does not stop the others and is reported with its log",
          "[farm][batch]") {
  TempDir d("farm_fail");
  write_jelly(d, 2);
  const std::string batch = d.write("b.yaml", two_by_two_batch(2));
  // A file where task 1's output folder goes: its run cannot write there.
  fs::create_directories(d.file("out/soft"));
  d.write("out/soft/velocity-0_-1_0", "not a folder\n");
  const CmdResult r = run_shellmpm("batch run " + batch + " --slots 2");
  INFO(r.output);
  CHECK(r.code == 1);
  CHECK(r.output.find("3 done, 0 previews, 0 skipped (done before), 1 failed") !=
        std::string::npos);
  CHECK(r.output.find("error: task 1 (soft/velocity-0_-1_0) failed with exit") !=
        std::string::npos);
  CHECK(r.output.find(d.file("out/_farm/logs/task.0001.log")) != std::string::npos);
  CHECK(r.output.find("    | == task 1 (soft/velocity-0_-1_0) attempt 1") != std::string::npos);
  const CmdResult st = run_shellmpm("batch status " + batch);
  INFO(st.output);
  CHECK(st.output.find("batch tiny: 4 tasks, 3 done, 1 failed") != std::string::npos);
}

TEST_CASE(
    "batch: SIGTERM stops a running batch with checkpoints; run again, every task finishes "
    "byte-identical to an uninterrupted batch",
    "[farm][batch][signals]") {
  TempDir d("farm_term");
  write_jelly(d, 24);
  const std::string batch = d.write("b.yaml", two_by_two_batch(24));
  const Child c = spawn_shellmpm({"batch", "run", batch, "--slots", "2"}, d.file("run.log"));
  REQUIRE(c.pid > 0);
  const bool started = wait_for_file(d.file("out/soft/velocity-0_0_0/checkpoint.0003.bin"), 120);
  kill(c.pid, SIGTERM);
  const CmdResult stopped = wait_child(c);
  INFO(stopped.output);
  REQUIRE(started);
  CHECK(stopped.code == 143);
  CHECK(count(stopped.output, ": stopped with a checkpoint") == 2);
  CHECK(stopped.output.find("2 not started") != std::string::npos);
  CHECK_FALSE(fs::exists(d.file("out/soft/velocity-0_0_0/density.0024.vdb")));
  const CmdResult mid = run_shellmpm("batch status " + batch);
  CHECK(mid.output.find("batch tiny: 4 tasks, 2 pending, 2 stopped") != std::string::npos);

  const CmdResult resumed = run_shellmpm("batch run " + batch + " --slots 2");
  INFO(resumed.output);
  REQUIRE(resumed.code == 0);
  // (A task stopped before its first frame was written has no checkpoint: it starts anew.)
  CHECK(count(resumed.output, ": resume from " + d.file("out/soft/")) >= 1);
  const nlohmann::json sj =
      nlohmann::json::parse(run_shellmpm("batch status --json " + batch).output);
  CHECK(sj["tasks"][0]["restarts"] == 1);
  CHECK(sj["tasks"][1]["restarts"] == 1);
  CHECK(sj["tasks"][2]["restarts"] == 0);

  // The same batch, uninterrupted, into another folder.
  std::string ref_text = two_by_two_batch(24);
  ref_text.replace(ref_text.find("output: out"), 11, "output: ref");
  const std::string ref = d.write("ref.yaml", ref_text);
  REQUIRE(run_shellmpm("batch run -q " + ref + " --slots 2").code == 0);
  for (const char* id : kIds) check_same_caches(d.file("out/") + id, d.file("ref/") + id, 24);
}
