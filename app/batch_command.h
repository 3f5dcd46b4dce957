// `shellmpm batch plan|run|submit|status|collect|task BATCH ...`: batches of shots and
// wedges on this machine or on a farm (farm/; docs/farm.md).
#pragma once
#include <string>

namespace CLI {
class App;
}

namespace shellmpm {

struct BatchArgs {
  std::string batch;  ///< the batch file
  // run
  int slots = 0;
  int threads = 0;
  bool force = false;
  bool quiet = false;
  // plan, status
  bool json = false;
  // submit
  std::string engine = "slurm";
  bool dry_run = false;
  std::string partition, time, mem, account, qos, shellmpm;
  int cpus = 0, throttle = 0, signal_seconds = 0;
  // collect
  std::string output;  ///< folder of the tables and the page; default: the batch's output
  // task
  int index = -1;
  bool preview = false;
  std::string task_engine, job;
};

/// Adds the `batch` subcommand and its own subcommands to `app`; returns it.
CLI::App* add_batch_subcommand(CLI::App& app, BatchArgs& a);

/// Runs whichever of `batch`'s subcommands was given. Returns the exit code.
int batch_command(CLI::App& batch, const BatchArgs& a);

}  // namespace shellmpm
