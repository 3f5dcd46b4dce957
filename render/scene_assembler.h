// Builds the PreviewScene of one frame from a run's caches and its scene: shell meshes,
// colliders posed at the frame's time, the ground, the bulk material (particles, the
// density volume or its iso-surface), lights and the camera.
#pragma once
#include <stdexcept>
#include <string>
#include <vector>

#include "render/camera.h"
#include "render/preview_scene.h"
#include "sim/scene/scene.h"

namespace shellmpm {

/// A cache file of one frame is missing or unreadable. what() starts with the file's path.
struct CacheError : std::runtime_error {
  CacheError(std::string file_, const std::string& message)
      : std::runtime_error(file_ + ": " + message), file(std::move(file_)) {}
  std::string file;
};

class SceneAssembler {
 public:
  /// @param scene         the run's scene (scene.render holds the resolved settings)
  /// @param outdir        the directory holding the caches
  /// @param framing_frame the frame whose shells the automatic camera frames (with the
  ///                      sources and colliders); when its files cannot be read, shells
  ///                      are left out of the framing
  /// @throws UserError for mesh collider files that cannot be read (naming them). Render
  ///         settings that ask for what the run did not write (bulk: particles without a
  ///         particle cache) or name an unknown camera are refused by the scene reader.
  SceneAssembler(const Scene& scene, std::string outdir, int framing_frame);

  /// The frame's scene. @throws CacheError naming the first file that is missing or corrupt.
  PreviewScene assemble(int frame) const;

  const Camera& camera() const { return camera_; }
  /// What the bulk material is drawn as: Volume, Surface, Particles or None (never Auto).
  BulkDraw bulk() const { return bulk_; }
  /// The cache files frame `frame` reads.
  std::vector<std::string> files(int frame) const;

 private:
  struct ColliderMesh {
    RenderMesh local;  ///< in the collider's own frame
    std::vector<Keyframe> keys;
  };
  const Scene& scene_;
  std::string outdir_;
  BulkDraw bulk_ = BulkDraw::None;
  Camera camera_;
  std::vector<ColliderMesh> colliders_;
  Vec3d frame_lo_, frame_hi_;  ///< the box the auto camera and the ground are laid out on
  bool has_ground_ = false;
  Vec3d ground_point_{0, 0, 0}, ground_normal_{0, 1, 0};
  int ground_collider_ = -1;  ///< index of the plane collider used as ground, -1: synthetic
  Vec3f bulk_color_{0.5f, 0.5f, 0.5f};
  float particle_radius_ = 0.01f;

  struct Bounds;

  // Construction steps, in order.
  /// bulk_ from render.bulk, the renderer and the caches written; bulk colour and radius.
  void choose_bulk();
  /// colliders_ tessellated in their own frame, the ground plane collider; grows box by
  /// the colliders' keyframed poses.
  void load_colliders(Bounds& box);
  /// frame_lo_, frame_hi_ from box (clamped to the domain, down to the ground) and the
  /// synthetic ground.
  void set_frame(Bounds box);
  /// camera_: render.camera, the first named camera, or framed on the box ("auto").
  void choose_camera();

  // Steps of assemble(); content grows by what they add (t: the frame's time, fc, fr: the
  // framing box's center and radius).
  static void add_mesh(PreviewScene& ps, Bounds& content, RenderMesh m);
  void add_bulk(int frame, PreviewScene& ps, Bounds& content) const;
  void add_colliders(double t, const Vec3d& fc, double fr, PreviewScene& ps, Bounds& content) const;
  void add_ground(double t, const Vec3d& fc, double fr, PreviewScene& ps) const;
  void add_lights(PreviewScene& ps) const;

  std::string shell_path(const ShellDesc& sh, int frame) const;
  RenderMesh read_shell(const ShellDesc& sh, int frame) const;
};

/// Default preview colour of a bulk material by kind (elastic green, sand tan, snow white).
Vec3d default_bulk_color(MaterialKind kind);

}  // namespace shellmpm
