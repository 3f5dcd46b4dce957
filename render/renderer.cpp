#include "render/renderer.h"

#include <stdexcept>

#include "render/raster_renderer.h"
#include "render/ray_tracer.h"

namespace shellmpm {

std::unique_ptr<Renderer> make_renderer(RendererKind kind, int threads) {
  if (kind == RendererKind::Raytrace) return std::make_unique<RayTracer>(threads);
  return std::make_unique<RasterRenderer>(threads);
}

}  // namespace shellmpm
