#include "io/output_folders.h"

#include <filesystem>
#include <system_error>

#include "io/user_error.h"

namespace shellmpm {
namespace {

/// output.directory joined with the folder part of `file` ("" when it has none).
std::string folder_of(const std::string& directory, const std::string& file) {
  const std::size_t slash = file.rfind('/');
  if (slash == std::string::npos) return "";
  return (std::filesystem::path(directory) / file.substr(0, slash)).lexically_normal().string();
}

}  // namespace

std::vector<OutputFolder> output_folders(const Scene& scene, bool previews) {
  const OutputSettings& o = scene.output;
  std::vector<OutputFolder> out{{o.directory, "output.directory"}};
  auto add = [&](const std::string& file, const std::string& key) {
    const std::string f = folder_of(o.directory, file);
    if (f.empty()) return;
    for (const OutputFolder& e : out)
      if (e.path == f) return;
    out.push_back({f, key});
  };
  add(o.stats_file, "output.stats");
  if (o.density) add(o.density_pattern, "output.density_pattern");
  if (o.particles) add(o.particles_pattern, "output.particles_pattern");
  for (const ShellDesc& sh : scene.shells) {
    if (!sh.write_mesh) continue;
    std::string pattern = o.shell_pattern;
    const std::size_t at = pattern.find("{name}");  // the first, as the writer does
    if (at != std::string::npos) pattern.replace(at, 6, sh.name);
    add(pattern, "output.shell_pattern");
  }
  if (previews) add(scene.render.pattern, "render.pattern");
  return out;
}

void create_output_folders(const Scene& scene, bool previews) {
  for (const OutputFolder& f : output_folders(scene, previews)) {
    std::error_code ec;
    std::filesystem::create_directories(f.path, ec);
    if (!std::filesystem::is_directory(f.path)) {
      throw UserError(scene.path, 0, f.key,
                      "cannot create the output folder '" + f.path + "': " +
                          (ec ? ec.message() : std::string("a file of that name is in the way")));
    }
  }
}

}  // namespace shellmpm
