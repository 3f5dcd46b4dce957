#include "render/renderer.h"

#include <stdexcept>

#include "render/raster_renderer.h"
#include "render/ray_tracer.h"

namespace shellmpm {

std::unique_ptr<Renderer> make_renderer(const std::string& kind, int threads) {
  if (kind == "raster") return std::make_unique<RasterRenderer>(threads);
  if (kind == "raytrace") return std::make_unique<RayTracer>(threads);
  throw std::invalid_argument("unknown renderer '" + kind + "' (expected raster or raytrace)");
}

}  // namespace shellmpm
