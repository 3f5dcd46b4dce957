#include "farm/slurm_engine.h"

#include <cstdio>
#include <filesystem>

#include "farm/subprocess.h"
#include "farm/task_status.h"
#include "io/atomic_file.h"
#include "io/user_error.h"

namespace shellmpm {
namespace {

namespace fs = std::filesystem;

/// A word for a bash script, single-quoted when it needs it.
std::string sh_quote(const std::string& s) {
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                        "0123456789_-./=:,%@+") == std::string::npos)
    return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

/// The #SBATCH lines both arrays share: name, output, resources.
std::string common_directives(const BatchSpec& b, const SlurmSubmit& s, const std::string& name,
                              const std::string& partition) {
  const SlurmSettings& r = s.settings;
  std::string d = "#SBATCH --job-name=" + sh_quote(name) + "\n";
  d += "#SBATCH --open-mode=append\n";
  d += "#SBATCH --output=" + sh_quote(farm_dir(b) + "/logs/task.%4a.log") + "\n";
  d += "#SBATCH --cpus-per-task=" + std::to_string(r.cpus > 0 ? r.cpus : 1) + "\n";
  if (!s.mem.empty()) d += "#SBATCH --mem=" + sh_quote(s.mem) + "\n";
  if (!partition.empty()) d += "#SBATCH --partition=" + sh_quote(partition) + "\n";
  if (!r.time.empty()) d += "#SBATCH --time=" + sh_quote(r.time) + "\n";
  if (!r.account.empty()) d += "#SBATCH --account=" + sh_quote(r.account) + "\n";
  if (!r.qos.empty()) d += "#SBATCH --qos=" + sh_quote(r.qos) + "\n";
  return d;
}

/// The body that runs one task and passes the early signal on to it.
std::string task_body(const BatchSpec& b, const SlurmSubmit& s, bool preview) {
  std::string t = "set -u\n";
  t += "SHELLMPM=" + sh_quote(s.shellmpm) + "\n";
  t += "BATCH=" + sh_quote(b.path) + "\n";
  t += "task=\"${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}\"\n";
  t += "# In the background, so that the TERM Slurm sends the batch shell (--signal=B:...) is\n"
       "# passed on at once: the run finishes its frame, writes a checkpoint and exits 143.\n";
  t += "\"$SHELLMPM\" batch task \"$BATCH\" \"$SLURM_ARRAY_TASK_ID\" --threads "
       "\"${SLURM_CPUS_PER_TASK:-1}\" --engine slurm --job \"$task\"" +
       std::string(preview ? " --preview" : "") + " &\n";
  t += "child=$!\n";
  t += "trap 'kill -TERM \"$child\" 2>/dev/null' TERM\n";
  t += "trap 'kill -INT \"$child\" 2>/dev/null' INT\n";
  t += "wait \"$child\"; rc=$?\n";
  t += "# wait returns early when a trap ran; wait again for the task's own exit code.\n";
  t += "while kill -0 \"$child\" 2>/dev/null; do wait \"$child\"; rc=$?; done\n";
  if (!preview) {
    t += "if [ \"$rc\" -eq 143 ] || [ \"$rc\" -eq 130 ]; then\n";
    t += "  # Stopped with a checkpoint (preempted, out of time, scontrol requeue): requeue this\n"
         "  # array task (never $SLURM_JOB_ID: for the array's first task that is the whole "
         "array).\n";
    t += "  echo \"== task $SLURM_ARRAY_TASK_ID: stopped with a checkpoint; requeueing $task\"\n";
    t += "  scontrol requeue \"$task\"\n";
    t += "fi\n";
  }
  t += "exit \"$rc\"\n";
  return t;
}

}  // namespace

std::string array_spec(const std::vector<int>& indices, int throttle) {
  std::string s;
  for (std::size_t i = 0; i < indices.size();) {
    std::size_t j = i;
    while (j + 1 < indices.size() && indices[j + 1] == indices[j] + 1) ++j;
    s += (s.empty() ? "" : ",") + std::to_string(indices[i]);
    if (j > i) s += "-" + std::to_string(indices[j]);
    i = j + 1;
  }
  if (throttle > 0) s += "%" + std::to_string(throttle);
  return s;
}

SlurmScripts slurm_scripts(const BatchSpec& b, const std::vector<BatchTask>& tasks,
                           const SlurmSubmit& s) {
  SlurmScripts out;
  std::vector<int> all, previews;
  for (const BatchTask& t : tasks) {
    all.push_back(t.index);
    if (t.preview.enabled) previews.push_back(t.index);
  }
  out.array = array_spec(all, s.settings.throttle);
  const std::string header = "#!/bin/bash\n# shellmpm batch " + b.name + " (" + b.path +
                             "): written by `shellmpm batch submit`; submit it again with that "
                             "command.\n";
  out.job = header + "#SBATCH --array=" + out.array + "\n" + "#SBATCH --requeue\n" +
            "#SBATCH --signal=B:TERM@" + std::to_string(s.signal_seconds) + "\n" +
            common_directives(b, s, "shellmpm-" + b.name, s.settings.partition) +
            task_body(b, s, false);
  if (previews.empty()) return out;
  out.preview_array = array_spec(previews, s.settings.throttle);
  const std::string part =
      s.settings.preview_partition.empty() ? s.settings.partition : s.settings.preview_partition;
  out.preview = header +
                "# The preview step: submitted with --dependency=afterok:<the task "
                "array> --kill-on-invalid-dep=yes.\n" +
                "#SBATCH --array=" + out.preview_array + "\n" +
                common_directives(b, s, "shellmpm-" + b.name + "-preview", part) +
                task_body(b, s, true);
  return out;
}

void slurm_preflight(const SlurmSettings& s) {
  for (const char* tool : {"sbatch", "scontrol", "sinfo"})
    if (find_program(tool).empty())
      throw UserError("--engine slurm", 0, "",
                      std::string(tool) +
                          " is not on PATH: is this a Slurm submit host? (Debian: "
                          "slurm-client); or run the batch here with `shellmpm batch run`");
  const CommandOutput ping = run_capture({"scontrol", "ping"}, 30);
  if (ping.code != 0 || ping.output.find("is UP") == std::string::npos)
    throw UserError("--engine slurm", 0, "",
                    "the Slurm controller does not answer (scontrol ping: " + ping.output +
                        "); check SLURM_CONF and that slurmctld runs");
  for (const std::string& p : {s.partition, s.preview_partition}) {
    if (p.empty()) continue;
    const CommandOutput q = run_capture({"sinfo", "-h", "-p", p, "-o", "%P"}, 30);
    if (q.code == 0 && q.output.find_first_not_of(" \n") != std::string::npos) continue;
    const CommandOutput all = run_capture({"sinfo", "-h", "-o", "%P"}, 30);
    std::string names;
    for (char c : all.output) names += c == '\n' ? ' ' : c;
    throw UserError("--partition", 0, "",
                    "no Slurm partition '" + p + "' (partitions: " + names + ")");
  }
}

int submit_slurm(const BatchSpec& b, const std::vector<BatchTask>& tasks, const SlurmSubmit& s) {
  if (!s.dry_run) slurm_preflight(s.settings);
  const SlurmScripts scripts = slurm_scripts(b, tasks, s);
  const std::string dir = farm_dir(b) + "/slurm";
  fs::create_directories(dir);
  fs::create_directories(farm_dir(b) + "/logs");
  write_task_table(b, tasks);
  write_text_atomic(dir + "/job.sh", scripts.job);
  if (!scripts.preview.empty()) write_text_atomic(dir + "/preview.sh", scripts.preview);
  const std::vector<std::string> job_cmd = {"sbatch", "--parsable", dir + "/job.sh"};
  std::printf("task table: %s/tasks.json (%zu tasks)\njob script: %s/job.sh\n", farm_dir(b).c_str(),
              tasks.size(), dir.c_str());
  if (s.dry_run) {
    std::printf("----- job.sh\n%s", scripts.job.c_str());
    if (!scripts.preview.empty()) std::printf("----- preview.sh\n%s", scripts.preview.c_str());
    std::printf("-----\nwould run: sbatch --parsable %s/job.sh\n", dir.c_str());
    if (!scripts.preview.empty())
      std::printf(
          "would run: sbatch --parsable --dependency=afterok:<job id> "
          "--kill-on-invalid-dep=yes %s/preview.sh\n",
          dir.c_str());
    std::printf("dry run: nothing submitted\n");
    return 0;
  }
  const CommandOutput job = run_capture(job_cmd, 60);
  const std::string job_id = job.output.substr(0, job.output.find_first_of(";\n"));
  if (job.code != 0 || job_id.empty() ||
      job_id.find_first_not_of("0123456789") != std::string::npos) {
    std::fprintf(stderr, "error: sbatch refused the task array: %s\n", job.output.c_str());
    return 1;
  }
  nlohmann::json rec;
  rec["array_job"] = job_id;
  rec["array"] = scripts.array;
  rec["submitted"] = unix_now();
  std::printf("submitted job array %s (--array=%s)\n", job_id.c_str(), scripts.array.c_str());
  if (!scripts.preview.empty()) {
    const CommandOutput pv = run_capture({"sbatch", "--parsable", "--dependency=afterok:" + job_id,
                                          "--kill-on-invalid-dep=yes", dir + "/preview.sh"},
                                         60);
    const std::string pv_id = pv.output.substr(0, pv.output.find_first_of(";\n"));
    if (pv.code != 0 || pv_id.empty()) {
      write_text_atomic(dir + "/submit.json", rec.dump(2) + "\n");
      std::fprintf(stderr, "error: sbatch refused the preview array: %s\n", pv.output.c_str());
      return 1;
    }
    rec["preview_job"] = pv_id;
    std::printf("submitted preview array %s (--array=%s, after job %s succeeds)\n", pv_id.c_str(),
                scripts.preview_array.c_str(), job_id.c_str());
  }
  write_text_atomic(dir + "/submit.json", rec.dump(2) + "\n");
  std::printf("`shellmpm batch status %s` follows it\n", b.path.c_str());
  return 0;
}

}  // namespace shellmpm
