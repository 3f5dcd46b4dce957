// The raster preview path: OpenGL 3.3 core through OSMesa (llvmpipe), off-screen, no
// display and no GPU. See render/renderer.h for how it divides work with the ray tracer.
#pragma once
#include <memory>

#include "render/renderer.h"

namespace shellmpm {

class RasterRenderer : public Renderer {
 public:
  /// Creates the OSMesa context (one per renderer, reused for every frame).
  /// @param threads llvmpipe rasterizer threads (0 = Mesa's default, all cores); applied
  ///        through LP_NUM_THREADS, which Mesa reads once per process.
  explicit RasterRenderer(int threads);
  ~RasterRenderer() override;
  RasterRenderer(const RasterRenderer&) = delete;
  RasterRenderer& operator=(const RasterRenderer&) = delete;

  Image render(const PreviewScene& scene, const Camera& camera) override;
  const char* name() const override { return "raster"; }

  /// The multisample count used for anti-aliasing (4, or fewer if the driver has fewer).
  int samples() const;

 private:
  struct Gl;
  std::unique_ptr<Gl> gl_;
};

}  // namespace shellmpm
