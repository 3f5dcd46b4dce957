// A real single-node Slurm (tools/farm/slurm-local.sh: Debian's munged, slurmctld and
// slurmd as root, state in a temporary folder, stopped by their PIDs): a 2 shots x 2 wedges
// batch submitted as a job array with a dependent preview array; one running task requeued
// with `scontrol requeue`, another preempted by a job in the higher-priority partition.
// Every cache must be byte-identical to the same batch run by the local engine without
// faults, the previews must have run after the whole array, and status and collect must
// report every task. Skipped, with a message, where Slurm or root is missing.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "tests/app/cli_harness.h"
#include "tests/farm/farm_fixtures.h"

namespace fs = std::filesystem;
using namespace shellmpm_test;

namespace {

const std::string kScript = std::string(SHELLMPM_SOURCE_DIR) + "/tools/farm/slurm-local.sh";

/// Why a real Slurm cannot run here ("" when it can).
std::string slurm_missing() {
  if (getuid() != 0) return "not root (the single-node Slurm runs its daemons as root)";
  for (const char* p : {"/usr/sbin/slurmctld", "/usr/sbin/slurmd", "/usr/sbin/munged",
                        "/usr/bin/sbatch", "/usr/bin/scontrol", "/usr/bin/squeue"})
    if (!fs::exists(p)) return std::string(p) + " is missing (sh tools/install-deps.sh)";
  return "";
}

/// The daemons under ROOT, stopped (by their PIDs) when it goes out of scope.
struct LocalSlurm {
  std::string root;
  bool up = false;
  std::string log;
  explicit LocalSlurm(const std::string& r) : root(r) {
    // Ports of their own (two test runs at once), from the process id.
    const int port = 20000 + 2 * (static_cast<int>(getpid()) % 10000);
    const CmdResult c =
        run_command("sh " + kScript + " start " + root + " 2 " + std::to_string(port));
    log = c.output;
    up = c.code == 0;
    if (up) setenv("SLURM_CONF", (root + "/slurm.conf").c_str(), 1);
  }
  ~LocalSlurm() {
    run_command("sh " + kScript + " stop " + root);
    unsetenv("SLURM_CONF");
  }
};

nlohmann::json status_of(const std::string& batch) {
  const CmdResult r = run_shellmpm("batch status --json " + batch);
  const nlohmann::json j = nlohmann::json::parse(r.output, nullptr, false);
  return j.is_discarded() ? nlohmann::json() : j;
}

/// Polls until `pred()` holds (every 50 ms) or `seconds` pass.
template <class Pred>
bool wait_until(double seconds, Pred pred) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

/// Task `i` (folder OUT/ID) is running (its status file says so) and has written frame
/// `frame`'s checkpoint.
bool running_past(const TempDir& d, int i, const std::string& id, int frame) {
  char st[64], ck[64];
  std::snprintf(st, sizeof st, "out/_farm/status/%04d.json", i);
  std::snprintf(ck, sizeof ck, "/checkpoint.%04d.bin", frame);
  const nlohmann::json s = nlohmann::json::parse(read_text(d.file(st)), nullptr, false);
  return !s.is_discarded() && s.contains("sim") && s["sim"]["state"] == "running" &&
         fs::exists(d.file("out/" + id + ck));
}

}  // namespace

TEST_CASE(
    "batch on a real single-node Slurm: a requeued and a preempted task finish "
    "byte-identical to a local batch; previews after the array; status and collect",
    "[farm][slurm]") {
  const std::string missing = slurm_missing();
  if (!missing.empty()) {
    WARN("skipped: no single-node Slurm here: " << missing);
    return;
  }
  TempDir d("farm_slurm");
  constexpr int kFrames = 80;  // about 3 s a task here: time to requeue and preempt
  write_jelly(d, kFrames);
  const std::string preview = "    preview: {size: 96x64, renderer: raster}\n";
  const std::string batch = d.write("b.yaml", two_by_two_batch(kFrames, preview));
  fs::create_directories(d.file("slurm"));
  LocalSlurm slurm(d.file("slurm"));
  INFO(slurm.log);
  REQUIRE(slurm.up);

  const CmdResult sub = run_shellmpm("batch submit --engine slurm " + batch +
                                     " --partition low --cpus 1 --mem 300M --throttle 2");
  INFO(sub.output);
  REQUIRE(sub.code == 0);
  CHECK(sub.output.find("submitted job array") != std::string::npos);
  CHECK(sub.output.find("submitted preview array") != std::string::npos);
  const nlohmann::json rec =
      nlohmann::json::parse(read_text(d.file("out/_farm/slurm/submit.json")));
  const std::string job = rec["array_job"];
  const std::string out = d.file("out");

  // Requeue task 0 once it is running past its third frame.
  REQUIRE(wait_until(120, [&] { return running_past(d, 0, "soft/velocity-0_0_0", 3); }));
  const CmdResult requeue = run_command("scontrol requeue " + job + "_0");
  INFO(requeue.output);
  CHECK(requeue.code == 0);
  // Preempt another running task: a job in "high" wants both cores.
  const char* const ids[] = {"soft/velocity-0_0_0", "soft/velocity-0_-1_0", "stiff/velocity-0_0_0",
                             "stiff/velocity-0_-1_0"};
  int preempted = -1;
  REQUIRE(wait_until(120, [&] {
    for (int i = 1; i < 4 && preempted < 0; ++i)
      if (running_past(d, i, ids[i], 3)) preempted = i;
    return preempted > 0;
  }));
  const CmdResult high =
      run_command("sbatch --parsable -p high -c 2 --mem 10M -o /dev/null --wrap 'sleep 2'");
  INFO(high.output);
  CHECK(high.code == 0);

  const bool finished = wait_until(300, [&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));  // status runs squeue
    const nlohmann::json s = status_of(batch);
    if (s.is_null()) return false;
    for (const auto& t : s["tasks"])
      if (t["state"] != "done" || t["preview"] != "done") return false;
    return true;
  });
  const nlohmann::json s = status_of(batch);
  INFO(s.dump(1));
  INFO(read_text(d.file("out/_farm/logs/task.0000.log")));
  INFO(read_text(d.file("out/_farm/logs/task.0001.log")));
  INFO("preempted task " << preempted);
  REQUIRE(finished);
  CHECK(s["tasks"][0]["restarts"].get<int>() >= 1);
  CHECK(s["tasks"][preempted]["restarts"].get<int>() >= 1);
  const std::string log0 = read_text(d.file("out/_farm/logs/task.0000.log"));
  CHECK(log0.find("attempt 2 on") != std::string::npos);  // appended, not truncated
  CHECK(log0.find("attempt 1 on") != std::string::npos);
  // The requeue's SIGTERM reached the run directly and through `batch task`, and it still
  // stopped once, after its frame, with a checkpoint; the second attempt resumed from it.
  CHECK(log0.find("stopped by SIG") != std::string::npos);
  CHECK(log0.find("resuming after frame") != std::string::npos);

  // The previews ran after every task of the array had finished.
  double last_sim = 0, first_preview = 1e300;
  for (int i = 0; i < 4; ++i) {
    char name[64];
    std::snprintf(name, sizeof name, "out/_farm/status/%04d.json", i);
    const nlohmann::json st = nlohmann::json::parse(read_text(d.file(name)));
    last_sim = std::max(last_sim, st["sim"]["finished"].get<double>());
    first_preview = std::min(first_preview, st["preview"]["started"].get<double>());
    CHECK(fs::exists(out + "/" + st["id"].get<std::string>() + "/contact_sheet.png"));
  }
  CHECK(first_preview >= last_sim);

  // Status and collect report every task.
  const CmdResult table = run_shellmpm("batch status " + batch);
  CHECK(table.output.find("batch tiny: 4 tasks, 4 done") != std::string::npos);
  REQUIRE(run_shellmpm("batch collect -q " + batch).code == 0);
  const nlohmann::json wj = nlohmann::json::parse(read_text(d.file("out/wedge_table.json")));
  REQUIRE(wj["tasks"].size() == 4);
  for (const auto& t : wj["tasks"]) CHECK(t["frames_done"] == kFrames);

  // The same batch by the local engine, without faults: every cache byte-identical.
  std::string ref_text = two_by_two_batch(kFrames);
  ref_text.replace(ref_text.find("output: out"), 11, "output: ref");
  REQUIRE(run_shellmpm("batch run -q " + d.write("ref.yaml", ref_text)).code == 0);
  for (const auto& t : s["tasks"]) {
    const std::string id = t["id"];
    for (int f = 1; f <= kFrames; ++f) {
      char ply[64], vdb[64];
      std::snprintf(ply, sizeof ply, "/particles.%04d.ply", f);
      std::snprintf(vdb, sizeof vdb, "/density.%04d.vdb", f);
      INFO(id << " frame " << f);
      const std::string a = read_text(out + "/" + id + ply);
      REQUIRE(a.size() > 1000);
      CHECK(a == read_text(d.file("ref/") + id + ply));
      const std::string v = cache_bytes(out + "/" + id + vdb);
      REQUIRE(v.size() > 100);
      CHECK(v == cache_bytes(d.file("ref/") + id + vdb));
    }
  }
}
