// What a preview frame shows, in world space, independent of how it is drawn: the
// triangle meshes (shells, colliders, ground, the bulk surface), the particles, the
// density volume and the lights. render/scene_assembler builds it from a run's caches;
// the raster (render/raster_renderer) and ray traced (render/ray_tracer) paths both draw
// exactly this, with the shading rules of render/shading.h, so their images agree.
#pragma once
#include <Eigen/Core>
#include <string>
#include <vector>

namespace shellmpm {

using Vec3f = Eigen::Vector3f;

/// Which rules a surface is shaded with.
enum class SurfaceKind {
  Shell,     ///< two-sided: front colour on the normal's side, back colour on the other
  Collider,  ///< one colour
  Ground,    ///< checkered, fades into the background towards its rim
  Bulk,      ///< the iso-surface of the density (orientation not relied on)
};

/// An indexed triangle mesh in world space [m].
struct RenderMesh {
  std::string name;
  SurfaceKind kind = SurfaceKind::Collider;
  std::vector<Vec3f> positions;
  std::vector<Vec3f> normals;              ///< per vertex, unit, on the front side
  std::vector<Eigen::Vector3i> triangles;  ///< counter-clockwise seen from the front
  Vec3f front{0.5f, 0.5f, 0.5f};           ///< linear RGB albedo of the front side
  Vec3f back{0.5f, 0.5f, 0.5f};            ///< ... and of the back side
};

/// Particles drawn as spheres of one radius.
struct RenderParticles {
  std::vector<Vec3f> positions;  ///< [m]
  float radius = 0.01f;          ///< [m]
  Vec3f color{0.5f, 0.5f, 0.5f};
};

/// A dense density grid (the run's fog volume, made dense over its active bounds).
struct RenderVolume {
  Vec3f origin{0, 0, 0};          ///< world position of sample (0, 0, 0) (a voxel center) [m]
  float voxel = 0.0f;             ///< sample spacing [m]
  Eigen::Vector3i dims{0, 0, 0};  ///< samples per axis
  std::vector<float> density;     ///< x fastest: density[(k * dims.y + j) * dims.x + i]
  float extinction = 60.0f;       ///< extinction of density 1 [1/m]
  Vec3f color{0.5f, 0.5f, 0.5f};  ///< single-scattering albedo (linear RGB)
  bool empty() const { return density.empty(); }
  float at(int i, int j, int k) const {
    return density[(static_cast<std::size_t>(k) * dims.y() + j) * dims.x() + i];
  }
};

/// A directional key light (casts shadows), a directional fill light and a sky ambient.
struct RenderLights {
  Vec3f key_dir{0.3f, 0.9f, 0.3f};    ///< unit, towards the key light
  float key = 1.0f;                   ///< key intensity
  Vec3f fill_dir{-0.5f, 0.3f, 0.8f};  ///< unit, towards the fill light
  float fill = 0.3f;
  float ambient = 0.35f;  ///< sky light from +Y, scaled by occlusion
};

/// The ground's checker and its fade into the background.
struct RenderGround {
  Vec3f center{0, 0, 0};  ///< where the fade is centered (on the plane) [m]
  float radius = 1.0f;    ///< the ground is fully faded out at this distance [m]
  float tile = 0.1f;      ///< checker square size [m]
};

struct PreviewScene {
  std::vector<RenderMesh> meshes;
  RenderParticles particles;
  RenderVolume volume;
  RenderLights lights;
  RenderGround ground;
  Vec3f bg_top{0.62f, 0.68f, 0.76f};     ///< background at the top of the image (linear RGB)
  Vec3f bg_bottom{0.30f, 0.32f, 0.36f};  ///< ... at the bottom
  Vec3f bounds_lo{-1, -1, -1};           ///< bounds of the content that casts shadows [m]
  Vec3f bounds_hi{1, 1, 1};
  float ao_distance = 0.2f;  ///< reach of ambient-occlusion rays [m]
  int samples = 4;           ///< ray traced: samples per pixel (raster: 4x multisampling)
  int ao_samples = 2;        ///< ray traced: ambient-occlusion rays per sample
};

}  // namespace shellmpm
