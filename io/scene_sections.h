// The scene reader's sections, one function per top-level block, shared between the files
// that read them (scene_reader.cpp: shot, output, preroll, render and the whole scene;
// scene_bulk_reader.cpp: materials, sources, colliders; scene_shell_reader.cpp: shell
// materials and shells). Each reads its block with MapReader: fill() for the keys the
// schema binds, by hand for names, references and rules across keys.
#pragma once
#include <string>
#include <vector>

#include "io/scene_map_reader.h"
#include "sim/scene/scene.h"

namespace shellmpm::scenefile {

void read_materials(MapReader& top, Scene& scene);
void read_sources(MapReader& top, Scene& scene);
void read_colliders(MapReader& top, Scene& scene);
void read_shell_materials(MapReader& top, Scene& scene);
void read_shells(MapReader& top, Scene& scene);

/// Reads the keyframe list at `key` of r's mapping; frame N is at time (N - 1) / fps.
/// Times must strictly increase.
std::vector<Keyframe> read_keyframes(MapReader& r, const std::string& key,
                                     const ShotSettings& shot);

}  // namespace shellmpm::scenefile
