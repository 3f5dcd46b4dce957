// A batch file: shots (a scene, a frame range, --set overrides), wedges (override sets,
// listed or the product of several keys' value lists) and an optional preview step per
// shot, plus the farm settings an engine reads (slots, threads, Slurm resources). It is
// YAML, read through the scene reader's document (io/scene_document.h) so that every
// error names the file, line and key; unknown keys are errors. docs/farm.md is its
// reference.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "io/scene_document.h"

namespace shellmpm {

/// One `--set KEY=VALUE`; `value` is YAML text (a plain scalar, or flow YAML for a list).
struct Override {
  std::string key;
  std::string value;
  scenefile::Origin origin;  ///< where the batch file states it
  std::string where_key;     ///< its key path in the batch file ("shots[0].set.shot.dx")
  /// "KEY=VALUE", what `shellmpm run --set` takes.
  std::string arg() const { return key + "=" + value; }
};

/// One member of a wedge: a name (its folder) and the overrides it applies.
struct WedgeMember {
  std::string name;
  std::vector<Override> values;
};

/// A named wedge, expanded: members in their deterministic order (a `sets` list in file
/// order; a `product` with its first key varying slowest).
struct WedgeSpec {
  std::string name;
  scenefile::Origin origin;
  std::vector<std::string> keys;  ///< the keys it varies, in file order
  std::vector<WedgeMember> members;
};

/// The preview step of a shot: `shellmpm render` on each of its tasks' output.
struct PreviewSpec {
  bool enabled = false;
  std::string size;      ///< "WxH"; empty: the scene's
  std::string camera;    ///< empty: the scene's
  std::string renderer;  ///< raster | raytrace; empty: the scene's
};

struct ShotSpec {
  std::string name;
  std::string scene;  ///< absolute path
  std::optional<int> frame_start, frame_end;
  std::vector<Override> overrides;  ///< shot-wide `set`, before the wedge's
  std::string wedge;                ///< a WedgeSpec's name; empty: one task, "base"
  PreviewSpec preview;
  scenefile::Origin origin;
};

/// Resources of a Slurm submission (`batch submit --engine slurm`); flags override them.
struct SlurmSettings {
  std::string partition;          ///< empty: the cluster's default
  std::string time;               ///< --time (e.g. "02:00:00"); empty: the partition's
  std::string mem;                ///< --mem (e.g. "4G"); empty: from the memory estimate
  int cpus = 0;                   ///< --cpus-per-task; 0: 1
  int throttle = 0;               ///< %K of --array; 0: no throttle
  int signal_seconds = 0;         ///< S of --signal=B:TERM@S; 0: from the estimate
  std::string account, qos;       ///< optional
  std::string preview_partition;  ///< the preview job's; empty: `partition`
};

struct FarmSettings {
  int slots = 0;    ///< tasks at once on the local engine; 0: as many as the cores allow
  int threads = 0;  ///< threads per task; 0: the cores split between the slots
  SlurmSettings slurm;
};

struct BatchSpec {
  std::string path;    ///< the batch file, absolute
  std::string name;    ///< `name`, or the file's stem
  std::string output;  ///< output root, absolute: tasks write to OUTPUT/<shot>/<wedge>/
  std::vector<ShotSpec> shots;
  std::vector<WedgeSpec> wedges;
  FarmSettings farm;
};

/// Reads and validates a batch file. Relative paths (scenes, output) are relative to the
/// batch file's folder. Nothing is written.
/// @throws UserError "file:line: key: message" for a bad or unknown key or value, a scene
///   file that does not exist, or duplicate shot or wedge member names.
BatchSpec read_batch_file(const std::string& path);

/// As read_batch_file, from text; `path` names it in messages and anchors relative paths.
BatchSpec parse_batch(const std::string& text, const std::string& path);

/// The YAML text of a value, as `--set` parses it (flow style for lists and mappings;
/// quoted strings stay quoted).
std::string yaml_value_text(const scenefile::DocNode& n);

}  // namespace shellmpm
