// The ray traced preview path (Embree 3): primary rays with stratified anti-aliasing, a
// shadow ray to the key light, ambient-occlusion rays, and the density volume ray-marched
// with single scattering. See render/renderer.h for how it divides work with the raster
// path.
#pragma once
#include "render/renderer.h"

struct RTCDeviceTy;

namespace shellmpm {

class RayTracer : public Renderer {
 public:
  /// @param threads Embree build threads (0 = all cores); the pixel loop runs on TBB, which
  ///        the caller limits (ThreadLimit).
  explicit RayTracer(int threads);
  ~RayTracer() override;
  RayTracer(const RayTracer&) = delete;
  RayTracer& operator=(const RayTracer&) = delete;

  Image render(const PreviewScene& scene, const Camera& camera) override;
  const char* name() const override { return "raytrace"; }

 private:
  RTCDeviceTy* device_ = nullptr;
};

}  // namespace shellmpm
