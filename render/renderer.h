// The two preview render paths behind one interface.
//
// How they share work, and why: both draw the same PreviewScene (built once per frame by
// render/scene_assembler from the caches) through the same Camera, with the shading rules
// of render/shading.h. Beyond that they are independent, on purpose:
// - raster (OSMesa, OpenGL 3.3 core on llvmpipe) is the fast path for dailies. It draws
//   everything in OpenGL, the key light's shadow from a shadow map, particles as shaded
//   point sprites and the bulk material as its iso-surface. It builds no Embree BVH and
//   traces no rays: Embree shadows for a raster frame would mean reading the depth buffer
//   back, building the BVH over every particle and tracing a shadow ray per pixel, i.e.
//   most of the ray tracer's cost (bench/render_throughput: 1.3 s per 1280x720 raster
//   frame against 3.2 s ray traced), for a shadow a 2048^2 shadow map already gives.
// - raytrace (Embree) is the quality path: primary rays, shadow rays, ambient occlusion
//   and the density volume ray-marched. It needs no GL context, so it also runs where
//   OSMesa is unavailable or misbehaves, and its silhouettes are an independent check
//   of the raster path (tests/render compares the two).
#pragma once
#include <memory>
#include <string>

#include "render/camera.h"
#include "render/image.h"
#include "render/preview_scene.h"
#include "sim/scene/scene.h"

namespace shellmpm {

class Renderer {
 public:
  virtual ~Renderer() = default;
  /// Renders `scene` seen through `camera` into a camera.width x camera.height image
  /// (rows from the top; alpha = coverage by content). Deterministic: the same inputs give
  /// the same pixels, whatever the thread count.
  virtual Image render(const PreviewScene& scene, const Camera& camera) = 0;
  virtual const char* name() const = 0;
};

/// "raster" or "raytrace". `threads` (0 = all cores) limits llvmpipe's rasterizer threads
/// (LP_NUM_THREADS, read once per process when the first GL context is made) and Embree's
/// build threads ("threads=N"); the caller limits TBB (ThreadLimit) for the pixel loops.
/// @throws std::invalid_argument for another name; std::runtime_error when the GL context
///         or Embree device cannot be created.
std::unique_ptr<Renderer> make_renderer(RendererKind kind, int threads);

}  // namespace shellmpm
