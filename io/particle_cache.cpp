#include "io/particle_cache.h"

#include <cstring>
#include <vector>

#include "io/atomic_file.h"
#include "sim/scene/output_axes.h"

namespace shellmpm {

void write_particle_ply(const std::string& path, const ParticleSet& p, UpAxis up) {
  const std::size_t n = p.size();
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment shellmpm particle cache\n";
  if (up == UpAxis::Z) header += "comment up_axis z\n";
  header += "element vertex " + std::to_string(n) + "\n";
  for (const char* a : {"x", "y", "z", "vx", "vy", "vz"})
    header += std::string("property float ") + a + "\n";
  header += "property uint id\nend_header\n";
  constexpr std::size_t kRecord = 6 * 4 + 4;
  std::vector<char> body(n * kRecord);
  for (std::size_t i = 0; i < n; ++i) {
    float r[6] = {float(p.x[i].x()), float(p.x[i].y()), float(p.x[i].z()),
                  float(p.v[i].x()), float(p.v[i].y()), float(p.v[i].z())};
    to_output_axes(r, 2, up);  // position and velocity
    std::memcpy(body.data() + i * kRecord, r, 24);
    std::memcpy(body.data() + i * kRecord + 24, &p.id[i], 4);
  }
  write_stream_atomic(path, [&](CheckedFile& out) {
    out.write(header.data(), header.size());
    out.write(body.data(), body.size());
  });
}

}  // namespace shellmpm
