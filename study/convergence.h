// `shellmpm converge`: a user's own shot at several settings of one knob (or several keys
// moved together), a quantity of interest measured in each run, its observed order, a
// Richardson-extrapolated value with its error, and what each setting cost. It answers "is
// my shot converged, and what would the next refinement cost" where no reference exists.
#pragma once
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "study/quantity.h"
#include "study/richardson.h"

namespace shellmpm {

/// One --vary: a key and its values, as written.
struct VarySpec {
  std::string key;
  std::vector<std::string> values;
};

/// Parses "KEY=V1,V2,V3"; commas inside [] or {} belong to one value ("[10,10],[20,20]").
/// @throws UserError naming the flag for a missing '=', an empty key or fewer than 2 values.
VarySpec parse_vary(const std::string& text);

/// The spacing a value stands for: a real number is itself (dx, cfl, a time step); an
/// integer, or a list whose first entry is an integer, is 1 / that integer (a resolution,
/// a count of samples). Nothing when the value is not numeric.
std::optional<double> spacing_of_value(const std::string& value);

struct ConvergeOptions {
  std::string binary;  ///< the shellmpm executable
  std::string scene;
  std::vector<std::string> overrides;  ///< --set, applied to every setting first
  std::vector<VarySpec> vary;          ///< all with the same number of values
  std::string measure;                 ///< a quantity (study/quantity.h)
  std::string frames;                  ///< --frames for every run; empty: the scene's
  int at_frame = 0;                    ///< the frame measured; 0: each run's last
  std::vector<double> spacing;         ///< --h: explicit spacings, one per setting
  std::string output;                  ///< runs go to OUTPUT/setting<i>
  int threads = 0;
  bool keep_runs = true;
  std::function<void(const std::string&)> log;
};

struct ConvergeSetting {
  std::string label;                   ///< "shot.dx=0.02"
  std::vector<std::string> overrides;  ///< the vary values
  double h = 0;
  double value = 0;
  double wall_seconds = 0, peak_rss_bytes = 0;
  long substeps = 0;
};

struct ConvergeResult {
  std::string quantity;
  std::vector<ConvergeSetting> settings;  ///< in the order given
  std::optional<Extrapolation> extrapolation;
  /// The cost of the next setting, one more refinement by the last ratio of spacings, from
  /// the growth of the wall time between the two finest settings [s]; nothing with fewer
  /// than two settings or no spacing.
  std::optional<double> next_cost_seconds;
  std::optional<double> next_spacing;
};

/// Reads the scene at every setting (UserError for a bad key or value, naming it), checks
/// the quantity against it, runs every setting and measures it.
/// @throws UserError for bad input; SimulationError-like std::runtime_error when a run
///         fails (with its exit status and the end of its output).
ConvergeResult run_convergence(const ConvergeOptions& opt);

/// The result as JSON (converge.json).
std::string convergence_json(const ConvergeResult& r);

}  // namespace shellmpm
