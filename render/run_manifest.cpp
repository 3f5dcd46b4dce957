#include "render/run_manifest.h"

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "io/atomic_file.h"
#include "io/scene_reader.h"
#include "io/user_error.h"

namespace shellmpm {

namespace {
constexpr const char* kFormat = "shellmpm run manifest";
constexpr int kVersion = 1;
}  // namespace

std::string run_manifest_path(const std::string& outdir) {
  return outdir + "/run.json";
}

void write_run_manifest(const std::string& outdir, const RunManifest& m) {
  nlohmann::json j;
  j["format"] = kFormat;
  j["version"] = kVersion;
  j["scene_path"] = m.scene_path;
  j["scene_text"] = m.scene_text;
  j["overrides"] = m.overrides;
  j["frames"] = {m.frame_start, m.frame_end};
  write_text_atomic(run_manifest_path(outdir), j.dump(2) + "\n");
}

RunManifest read_run_manifest(const std::string& outdir) {
  const std::string path = run_manifest_path(outdir);
  std::error_code ec;
  if (!std::filesystem::is_directory(outdir, ec))
    throw UserError(outdir, 0, "",
                    "no such directory (give the output directory of a `shellmpm run`)");
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw UserError(path, 0, "",
                    "not found: `shellmpm run` writes it into its output directory; run the scene "
                    "first, or name it with --scene");
  std::stringstream ss;
  ss << in.rdbuf();
  RunManifest m;
  try {
    const nlohmann::json j = nlohmann::json::parse(ss.str());
    if (j.value("format", "") != kFormat || j.value("version", 0) != kVersion)
      throw UserError(path, 0, "", "not a shellmpm run manifest (version 1)");
    m.scene_path = j.at("scene_path").get<std::string>();
    m.scene_text = j.at("scene_text").get<std::string>();
    m.overrides = j.at("overrides").get<std::vector<std::string>>();
    m.frame_start = j.at("frames").at(0).get<int>();
    m.frame_end = j.at("frames").at(1).get<int>();
  } catch (const nlohmann::json::exception& e) {
    throw UserError(path, 0, "", std::string("corrupt run manifest: ") + e.what());
  }
  if (m.frame_start < 1 || m.frame_end < m.frame_start)
    throw UserError(path, 0, "frames", "corrupt run manifest: bad frame range");
  return m;
}

Scene scene_from_manifest(const RunManifest& m, const std::string& outdir,
                          const std::vector<std::string>& extra) {
  std::vector<std::string> ov = m.overrides;
  ov.insert(ov.end(), extra.begin(), extra.end());
  Scene s = parse_scene(m.scene_text, m.scene_path, ov);
  s.output.directory = outdir;
  s.shot.frame_start = m.frame_start;
  s.shot.frame_end = m.frame_end;
  return s;
}

}  // namespace shellmpm
