// io/output_folders: the folders a run writes into, from the output names, and their
// creation (a file in the way is an error at the key).
#include <catch2/catch.hpp>

#include <filesystem>

#include "io/output_folders.h"
#include "io/scene_reader.h"
#include "io/user_error.h"
#include "tests/support/temp_dir.h"

using namespace shellmpm;

TEST_CASE("output folders: every sub-folder of the written names is made", "[output_folders]") {
  shellmpm_test::TempDir d("output_folders");
  const std::string out = d.file("out");
  const std::string text =
      "version: 1\n"
      "shot: {dx: 0.1, domain: {min: [-1, -1, -1], max: [1, 1, 1]}}\n"
      "shell_materials: [{name: cloth}]\n"
      "shells:\n"
      "  - {name: a, material: cloth, geometry: {type: sheet}}\n"
      "  - {name: b, material: cloth, geometry: {type: sheet}, translate: [0, 0.5, 0]}\n"
      "  - {name: c, material: cloth, geometry: {type: sheet}, write_mesh: false}\n"
      "output:\n"
      "  directory: " +
      out +
      "\n"
      "  stats: logs/run/stats.json\n"
      "  density_pattern: vdb/density.####.vdb\n"
      "  particles_pattern: pts/p.####.ply\n"
      "  shell_pattern: \"meshes/{name}/{name}.####.ply\"\n"
      "render: {pattern: png/preview.####.png}\n";
  const Scene s = parse_scene(text, d.file("scene.yaml"));
  std::vector<std::string> keys, paths;
  for (const OutputFolder& f : output_folders(s, false)) {
    keys.push_back(f.key);
    paths.push_back(f.path);
  }
  // No particles (output.particles is off) and no previews; shell c writes no mesh.
  CHECK(keys == std::vector<std::string>{"output.directory", "output.stats",
                                         "output.density_pattern", "output.shell_pattern",
                                         "output.shell_pattern"});
  CHECK(paths[1] == out + "/logs/run");
  CHECK(paths[3] == out + "/meshes/a");
  CHECK(paths[4] == out + "/meshes/b");
  CHECK(output_folders(s, true).back().key == "render.pattern");
  create_output_folders(s, true);
  for (const char* sub : {"logs/run", "vdb", "meshes/a", "meshes/b", "png"})
    CHECK(std::filesystem::is_directory(out + "/" + sub));
  CHECK(!std::filesystem::exists(out + "/meshes/c"));
  CHECK(!std::filesystem::exists(out + "/pts"));
  // A file where a folder should be.
  std::filesystem::remove_all(out + "/vdb");
  d.write("out/vdb", "not a folder");
  try {
    create_output_folders(s, false);
    FAIL("expected a UserError");
  } catch (const UserError& e) {
    CHECK(e.key == "output.density_pattern");
    CHECK(std::string(e.what()).find("cannot create the output folder") != std::string::npos);
  }
}
