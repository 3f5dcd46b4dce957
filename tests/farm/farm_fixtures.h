// Tiny batches for the farm tests: a jelly scene of a few frames and batch files over it.
#pragma once
#include <cctype>
#include <string>

#include "tests/support/jelly_scene.h"
#include "tests/support/temp_dir.h"

namespace shellmpm_test {

/// Writes the tiny jelly scene (240 fps, `frames` frames, a checkpoint every frame, particle
/// caches beside the density VDBs) as DIR/jelly.yaml and returns its path.
inline std::string write_jelly(const TempDir& d, int frames) {
  return d.write("jelly.yaml", tiny_jelly_scene(frames, d.file("scene_default_out"),
                                                "  checkpoint_every: 1\n  particles: true\n"));
}

/// The bytes of a cache file, with an OpenVDB file's random UUID (36 characters in its
/// header, different in every file written) blanked: what must match between two runs.
inline std::string cache_bytes(const std::string& path) {
  std::string s = read_text(path);
  const std::string head = s.substr(0, 256);
  for (std::size_t i = 0; i + 36 <= head.size(); ++i) {
    bool uuid = true;
    for (std::size_t k = 0; k < 36 && uuid; ++k) {
      const char c = head[i + k];
      uuid = (k == 8 || k == 13 || k == 18 || k == 23)
                 ? c == '-'
                 : std::isxdigit(static_cast<unsigned char>(c)) != 0;
    }
    if (uuid) return s.replace(i, 36, 36, '0');
  }
  return s;
}

/// A batch of 2 shots x 2 wedge members over DIR/jelly.yaml (write_jelly first), output
/// DIR/out; `extra_shot` lines go into each shot, `extra` at the end.
inline std::string two_by_two_batch(int frames, const std::string& extra_shot = "",
                                    const std::string& extra = "") {
  const std::string f = "    frames: [1, " + std::to_string(frames) + "]\n";
  return "version: 1\nname: tiny\noutput: out\nshots:\n"
         "  - name: soft\n    scene: jelly.yaml\n" +
         f + "    set:\n      materials[0].youngs_modulus: 5000\n    wedge: drop\n" + extra_shot +
         "  - name: stiff\n    scene: jelly.yaml\n" + f +
         "    set:\n      materials[0].youngs_modulus: 20000\n    wedge: drop\n" + extra_shot +
         "wedges:\n  - name: drop\n    product:\n      sources[0].velocity: [[0, 0, 0], [0, -1, "
         "0]]\n" +
         extra;
}

}  // namespace shellmpm_test
