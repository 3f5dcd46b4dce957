// Writing the study's results: results.json (everything, for tools/plot_study.py),
// results.csv (one row per run) and summary.md (the tables docs/accuracy.md quotes).
#pragma once
#include <nlohmann/json.hpp>
#include <string>

#include "study/study_runner.h"

namespace shellmpm {

/// The results as JSON (the layout results.json has).
nlohmann::json study_json(const StudyResults& r);

/// Writes OUTPUT/results.json, results.csv and summary.md (each atomically).
/// @throws std::runtime_error naming the file when a write fails.
void write_study_report(const StudyResults& r, const std::string& output);

}  // namespace shellmpm
