// The Slurm job scripts, golden (no daemons needed): the task array with its throttle,
// requeue, early signal, appended per-task logs and resources, the self-requeue by array
// task id on exit 143; the preview array; `submit --dry-run` writing them and the task table
// without submitting; the clear errors of a missing sbatch and an unreachable controller.
#include <catch2/catch.hpp>
#include <filesystem>
#include <string>

#include "farm/batch_tasks.h"
#include "farm/slurm_engine.h"
#include "tests/app/cli_harness.h"
#include "tests/farm/farm_fixtures.h"

namespace fs = std::filesystem;
using namespace shellmpm;
using namespace shellmpm_test;

namespace {

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t p = s.find(from); p != std::string::npos; p = s.find(from, p + to.size()))
    s.replace(p, from.size(), to);
  return s;
}

const char* const kBody = R"(set -u
SHELLMPM=/opt/shellmpm/bin/shellmpm
BATCH=TMP/b.yaml
task="${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}"
# In the background, so that the TERM Slurm sends the batch shell (--signal=B:...) is
# passed on at once: the run finishes its frame, writes a checkpoint and exits 143.
"$SHELLMPM" batch task "$BATCH" "$SLURM_ARRAY_TASK_ID" --threads "${SLURM_CPUS_PER_TASK:-1}" --engine slurm --job "$task"PREVIEW &
child=$!
trap 'kill -TERM "$child" 2>/dev/null' TERM
trap 'kill -INT "$child" 2>/dev/null' INT
wait "$child"; rc=$?
# wait returns early when a trap ran; wait again for the task's own exit code.
while kill -0 "$child" 2>/dev/null; do wait "$child"; rc=$?; done
)";

const char* const kRequeue = R"(if [ "$rc" -eq 143 ] || [ "$rc" -eq 130 ]; then
  # Stopped with a checkpoint (preempted, out of time, scontrol requeue): requeue this
  # array task (never $SLURM_JOB_ID: for the array's first task that is the whole array).
  echo "== task $SLURM_ARRAY_TASK_ID: stopped with a checkpoint; requeueing $task"
  scontrol requeue "$task"
fi
)";

}  // namespace

TEST_CASE("Slurm engine: array specs", "[farm][slurm_scripts]") {
  CHECK(array_spec({0, 1, 2, 3}, 0) == "0-3");
  CHECK(array_spec({0, 1, 2, 3}, 2) == "0-3%2");
  CHECK(array_spec({2, 3, 6, 8, 9}, 0) == "2-3,6,8-9");
  CHECK(array_spec({5}, 1) == "5%1");
}

TEST_CASE("Slurm engine: golden job scripts", "[farm][slurm_scripts]") {
  TempDir d("farm_golden");
  write_jelly(d, 3);
  const std::string tmp = d.path.string();
  const BatchSpec b = parse_batch(two_by_two_batch(3, "    preview: true\n"), d.file("b.yaml"));
  std::vector<BatchTask> tasks = expand_tasks(b);
  // Only the stiff shot previews.
  tasks[0].preview.enabled = tasks[1].preview.enabled = false;
  SlurmSubmit s;
  s.settings.partition = "low";
  s.settings.time = "00:30:00";
  s.settings.cpus = 2;
  s.settings.throttle = 2;
  s.settings.account = "fx dept";
  s.shellmpm = "/opt/shellmpm/bin/shellmpm";
  s.signal_seconds = 300;
  s.mem = "2G";
  const SlurmScripts sc = slurm_scripts(b, tasks, s);
  CHECK(sc.array == "0-3%2");
  CHECK(sc.preview_array == "2-3%2");
  const std::string header =
      "#!/bin/bash\n# shellmpm batch tiny (TMP/b.yaml): written by `shellmpm batch submit`; "
      "submit it again with that command.\n";
  const std::string resources =
      "#SBATCH --open-mode=append\n#SBATCH --output=TMP/out/_farm/logs/task.%4a.log\n"
      "#SBATCH --cpus-per-task=2\n#SBATCH --mem=2G\n#SBATCH --partition=low\n"
      "#SBATCH --time=00:30:00\n#SBATCH --account='fx dept'\n";
  const std::string job = header +
                          "#SBATCH --array=0-3%2\n#SBATCH --requeue\n#SBATCH "
                          "--signal=B:TERM@300\n#SBATCH --job-name=shellmpm-tiny\n" +
                          resources + replaced(kBody, "PREVIEW", "") + kRequeue + "exit \"$rc\"\n";
  CHECK(replaced(sc.job, tmp, "TMP") == job);
  const std::string preview =
      header +
      "# The preview step: submitted with --dependency=afterok:<the task array> "
      "--kill-on-invalid-dep=yes.\n#SBATCH --array=2-3%2\n#SBATCH "
      "--job-name=shellmpm-tiny-preview\n" +
      resources + replaced(kBody, "PREVIEW", " --preview") + "exit \"$rc\"\n";
  CHECK(replaced(sc.preview, tmp, "TMP") == preview);
}

TEST_CASE("batch submit: --dry-run writes the scripts and the task table, submits nothing",
          "[farm][slurm_scripts]") {
  TempDir d("farm_dry");
  write_jelly(d, 3);
  const std::string batch = d.write("b.yaml", two_by_two_batch(3));
  // No Slurm at all on PATH: a dry run does not need it.
  const CmdResult r = run_shellmpm(
      "batch submit --engine slurm --dry-run " + batch + " --throttle 3", "PATH=/nonexistent");
  INFO(r.output);
  REQUIRE(r.code == 0);
  CHECK(r.output.find("#SBATCH --array=0-3%3\n") != std::string::npos);
  CHECK(r.output.find("would run: sbatch --parsable " + d.file("out/_farm/slurm/job.sh")) !=
        std::string::npos);
  CHECK(r.output.find("dry run: nothing submitted") != std::string::npos);
  CHECK(read_text(d.file("out/_farm/slurm/job.sh")).find("#SBATCH --signal=B:TERM@") !=
        std::string::npos);
  CHECK(fs::exists(d.file("out/_farm/tasks.json")));
  CHECK_FALSE(fs::exists(d.file("out/_farm/slurm/submit.json")));
  CHECK_FALSE(fs::exists(d.file("out/_farm/slurm/preview.sh")));  // no preview steps
}

TEST_CASE(
    "batch submit: no sbatch, or a controller that does not answer, is a clear error "
    "before anything is written",
    "[farm][slurm_scripts]") {
  TempDir d("farm_noslurm");
  write_jelly(d, 3);
  const std::string batch = d.write("b.yaml", two_by_two_batch(3));
  const CmdResult none = run_shellmpm("batch submit --engine slurm " + batch, "PATH=/nonexistent");
  INFO(none.output);
  CHECK(none.code == 2);
  CHECK(none.output.find("sbatch is not on PATH") != std::string::npos);
  CHECK_FALSE(fs::exists(d.file("out")));
  if (fs::exists("/usr/bin/scontrol")) {
    // A configuration whose controller is not running.
    const std::string conf =
        d.write("slurm.conf",
                "ClusterName=nowhere\nSlurmctldHost=localhost\nSlurmctldPort=1\n"
                "AuthType=auth/none\nCredType=cred/none\n"
                "NodeName=n1 CPUs=1 State=UNKNOWN\nPartitionName=p Nodes=ALL\n");
    const CmdResult down =
        run_shellmpm("batch submit --engine slurm " + batch, "SLURM_CONF=" + conf);
    INFO(down.output);
    CHECK(down.code == 2);
    CHECK(down.output.find("the Slurm controller does not answer") != std::string::npos);
    CHECK_FALSE(fs::exists(d.file("out")));
  }
  const CmdResult engine = run_shellmpm("batch submit --engine deadline " + batch);
  CHECK(engine.code == 2);
  CHECK(engine.output.find("unknown engine 'deadline'") != std::string::npos);
}
