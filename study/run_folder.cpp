#include "study/run_folder.h"

#include <fstream>
#include <stdexcept>

#include "io/atomic_file.h"
#include "io/ply_reader.h"

namespace shellmpm {

std::vector<std::string> run_outputs_overrides(bool particles) {
  std::vector<std::string> o = {
      "output.density=false",      "output.stats=stats.json",
      "output.shell_format=ply",   "output.shell_pattern='{name}.####.ply'",
      "output.checkpoint_every=0", "render.preview=false"};
  o.push_back(std::string("output.particles=") + (particles ? "true" : "false"));
  if (particles) o.push_back("output.particles_pattern='particles.####.ply'");
  return o;
}

RunFolder::RunFolder(std::string dir) : dir_(std::move(dir)) {
  const std::string path = dir_ + "/stats.json";
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read the run's statistics");
  try {
    stats_ = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": not valid JSON (" + e.what() + ")");
  }
  if (!stats_.contains("frames") || !stats_["frames"].is_array() || stats_["frames"].empty())
    throw std::runtime_error(path + ": holds no frames");
}

int RunFolder::first_frame() const {
  return frames().front().at("frame").get<int>();
}
int RunFolder::last_frame() const {
  return frames().back().at("frame").get<int>();
}

const nlohmann::json& RunFolder::frame_stats(int frame) const {
  for (const nlohmann::json& f : frames())
    if (f.at("frame").get<int>() == frame) return f;
  throw std::runtime_error(dir_ + "/stats.json: has no frame " + std::to_string(frame));
}

double RunFolder::time(int frame) const {
  return frame_stats(frame).at("time").get<double>();
}

namespace {

std::vector<Vec3d> positions_of(const std::string& path) {
  const PlyMesh m = read_ply(path);
  std::vector<Vec3d> out;
  out.reserve(m.positions.size());
  for (const Vec3f& p : m.positions) out.push_back(p.cast<double>());
  return out;
}

}  // namespace

std::vector<Vec3d> RunFolder::shell_vertices(const std::string& shell, int frame) const {
  return positions_of(frame_path(dir_, shell + ".####.ply", frame));
}

std::vector<Vec3d> RunFolder::particles(int frame) const {
  return positions_of(frame_path(dir_, "particles.####.ply", frame));
}

}  // namespace shellmpm
