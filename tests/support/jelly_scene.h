// The tiny bulk scene many tests share (CLI, checkpoint, preview movie).
#pragma once
#include <string>

namespace shellmpm_test {

/// The tiny bulk scene the CLI, checkpoint and preview tests share: an elastic box
/// (dx 0.05) falling for frames [1, last_frame]. `shot_extra` (whole lines, e.g.
/// "  fps: 240\n") goes after the frames line; `out` is the output directory (empty: no
/// output section); `extra` is appended (output keys, or more top-level sections).
inline std::string jelly_scene(int last_frame, const std::string& shot_extra,
                               const std::string& out, const std::string& extra = "") {
  std::string s = "version: 1\nshot:\n  frames: [1, " + std::to_string(last_frame) + "]\n" +
                  shot_extra + R"(  dx: 0.05
  domain: {min: [-0.5, 0, -0.5], max: [0.5, 1, 0.5]}
materials:
  - {name: jelly, type: elastic, youngs_modulus: 1.0e4, poisson_ratio: 0.3, density: 1000}
sources:
  - {material: jelly, shape: {type: box, min: [-0.1, 0.3, -0.1], max: [0.1, 0.5, 0.1]}}
)";
  if (!out.empty()) s += "output:\n  directory: " + out + "\n";
  return s + extra;
}

/// jelly_scene at 240 fps with its output directory `out`, followed by `extra`.
inline std::string tiny_jelly_scene(int last_frame, const std::string& out,
                                    const std::string& extra = "") {
  return jelly_scene(last_frame, "  fps: 240\n", out, extra);
}

/// Two frames of jelly_scene at 240 fps; OUT stands for the output directory.
inline const std::string kTinyJellyScene = tiny_jelly_scene(2, "OUT");

}  // namespace shellmpm_test
