// `shellmpm batch collect`: one row per task with its wedge values, its state, the figures
// of its stats.json (frames, substeps, smallest step, largest speed, final energies, contact
// figures when it has contact), its integrity report and its wall time; written as CSV,
// JSON and Markdown (and as the review page, farm/review_page.h).
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "farm/task_status.h"

namespace shellmpm {

struct WedgeRow {
  const BatchTask* task = nullptr;
  std::optional<TaskStatus> status;
  std::string state;  ///< the status file's, or "pending"
  int frames_done = 0;
  std::vector<std::string> values;  ///< per WedgeTable::value_keys ("" where not set)
  std::vector<double> figures;      ///< per WedgeTable::figure_names (NaN where absent)
  std::string integrity;            ///< "ok", "failed: 3 inside_collider (ball), ...", "-"
  nlohmann::json frames;            ///< stats.json's per-frame objects (for plots)
};

struct WedgeTable {
  std::vector<std::string> value_keys;    ///< every key any task's wedge sets, in order
  std::vector<std::string> figure_names;  ///< stats figures some task has
  std::vector<WedgeRow> rows;
};

/// Reads every task's status file and stats.json.
WedgeTable build_wedge_table(const BatchSpec& b, const std::vector<BatchTask>& tasks);

std::string wedge_csv(const WedgeTable& t);
std::string wedge_markdown(const WedgeTable& t);
nlohmann::json wedge_json(const BatchSpec& b, const WedgeTable& t);

/// A figure as text: "%.6g", or "" for NaN.
std::string figure_text(double x);

}  // namespace shellmpm
