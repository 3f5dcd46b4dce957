#include "render/ray_tracer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/shading.h"
#include "sim/core/parallel.h"

namespace shellmpm {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

/// A hash of four integers to [0, 1): the only source of "randomness" (deterministic).
float hash01(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
  std::uint32_t h = a * 0x9E3779B1u ^ (b + 0x7F4A7C15u) * 0x85EBCA77u;
  h ^= (c + 0x165667B1u) * 0xC2B2AE3Du;
  h ^= (d + 0x27D4EB2Fu) * 0x9E3779B1u;
  h ^= h >> 16;
  h *= 0x7FEB352Du;
  h ^= h >> 15;
  h *= 0x846CA68Bu;
  h ^= h >> 16;
  return static_cast<float>(h >> 8) * (1.0f / 16777216.0f);
}

/// Slab test of a ray against an axis-aligned box: [t0, t1], empty when t0 > t1.
bool ray_box(const Vec3f& o, const Vec3f& d, const Vec3f& lo, const Vec3f& hi, float& t0,
             float& t1) {
  t0 = 0.0f;
  t1 = kInf;
  for (int a = 0; a < 3; ++a) {
    const float inv = 1.0f / d[a];
    float ta = (lo[a] - o[a]) * inv, tb = (hi[a] - o[a]) * inv;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1;
}

/// The volume with what the march needs: the density and the light it scatters towards
/// the camera (precomputed per voxel, so the march only interpolates).
struct VolumeField {
  const RenderVolume* v = nullptr;
  std::vector<Vec3f> radiance;     ///< per voxel: albedo * incident light (key, fill, sky)
  Vec3f lo{0, 0, 0}, hi{0, 0, 0};  ///< box of the samples

  bool empty() const { return v == nullptr || v->empty(); }

  /// Trilinear weights at world p; false outside.
  bool cell(const Vec3f& p, int idx[3], float w[3]) const {
    for (int a = 0; a < 3; ++a) {
      const float g = (p[a] - v->origin[a]) / v->voxel;
      const int i = static_cast<int>(std::floor(g));
      if (i < 0 || i >= v->dims[a] - 1) return false;
      idx[a] = i;
      w[a] = g - static_cast<float>(i);
    }
    return true;
  }
  std::size_t at(int i, int j, int k) const {
    return (static_cast<std::size_t>(k) * v->dims.y() + j) * v->dims.x() + i;
  }
  float density(const Vec3f& p) const {
    int c[3];
    float w[3];
    if (!cell(p, c, w)) return 0.0f;
    float s = 0.0f;
    for (int n = 0; n < 8; ++n) {
      const int dx = n & 1, dy = (n >> 1) & 1, dz = (n >> 2) & 1;
      const float ww = (dx ? w[0] : 1 - w[0]) * (dy ? w[1] : 1 - w[1]) * (dz ? w[2] : 1 - w[2]);
      s += ww * v->density[at(c[0] + dx, c[1] + dy, c[2] + dz)];
    }
    return s;
  }
  /// Density and radiance at p.
  float sample(const Vec3f& p, Vec3f& rad) const {
    int c[3];
    float w[3];
    rad.setZero();
    if (!cell(p, c, w)) return 0.0f;
    float s = 0.0f;
    for (int n = 0; n < 8; ++n) {
      const int dx = n & 1, dy = (n >> 1) & 1, dz = (n >> 2) & 1;
      const float ww = (dx ? w[0] : 1 - w[0]) * (dy ? w[1] : 1 - w[1]) * (dz ? w[2] : 1 - w[2]);
      const std::size_t i = at(c[0] + dx, c[1] + dy, c[2] + dz);
      s += ww * v->density[i];
      rad += ww * radiance[i];
    }
    return s;
  }
  /// Transmittance from p along unit direction d to the volume's edge (step: one voxel).
  float transmittance(const Vec3f& p, const Vec3f& d) const {
    float t0, t1;
    if (empty() || !ray_box(p, d, lo, hi, t0, t1)) return 1.0f;
    float tau = 0.0f;
    const float h = v->voxel;
    for (float t = t0 + 0.5f * h; t < t1; t += h) tau += density(p + t * d);
    return std::exp(-tau * h * v->extinction);
  }
};

struct Tracer {
  Tracer(const PreviewScene& s, const Camera& c) : scene(s), cam(c) {}
  const PreviewScene& scene;
  const Camera& cam;
  RTCScene rtc = nullptr;
  std::vector<int> mesh_of_geom;  ///< geomID -> index in scene.meshes, -1 = particles
  VolumeField vol;
  float eps = 1e-4f;
  Vec3f key_dir, fill_dir;

  bool occluded(const Vec3f& o, const Vec3f& d, float tfar) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay r{};
    r.org_x = o.x();
    r.org_y = o.y();
    r.org_z = o.z();
    r.dir_x = d.x();
    r.dir_y = d.y();
    r.dir_z = d.z();
    r.tnear = 0.0f;
    r.tfar = tfar;
    r.mask = 0xFFFFFFFFu;
    r.flags = 0;
    rtcOccluded1(rtc, &ctx, &r);
    return r.tfar < 0.0f;
  }

  /// Precomputes the light each voxel scatters (key with shadows from surfaces and the
  /// volume itself, fill, and sky through the material above).
  void prepare_volume() {
    const RenderVolume& v = scene.volume;
    vol.v = &v;
    if (v.empty()) return;
    vol.lo = v.origin;
    vol.hi = v.origin + (v.dims.cast<float>() - Vec3f::Ones()) * v.voxel;
    const int nx = v.dims.x(), ny = v.dims.y(), nz = v.dims.z();
    vol.radiance.assign(v.density.size(), Vec3f::Zero());
    const float h = v.voxel, ext = v.extinction;
    const RenderLights& L = scene.lights;
    parallel_for(static_cast<std::size_t>(nz), 1, [&](std::size_t kb, std::size_t ke) {
      for (int k = static_cast<int>(kb); k < static_cast<int>(ke); ++k)
        for (int i = 0; i < nx; ++i) {
          float above = 0.0f;  // optical depth of the column above, towards the sky
          for (int j = ny - 1; j >= 0; --j) {
            const float d = v.at(i, j, k);
            const std::size_t idx = vol.at(i, j, k);
            // Only where the march can see something: a voxel or a neighbour with material.
            bool near = d > 0.0f;
            for (int n = 0; n < 6 && !near; ++n) {
              const int a = n / 2, s = n % 2 ? 1 : -1;
              int c[3] = {i, j, k};
              c[a] += s;
              if (c[0] >= 0 && c[1] >= 0 && c[2] >= 0 && c[0] < nx && c[1] < ny && c[2] < nz)
                near = v.at(c[0], c[1], c[2]) > 0.0f;
            }
            const float sky = std::exp(-(above + 0.5f * d) * h * ext);
            above += d;
            if (!near) continue;
            const Vec3f p =
                v.origin +
                Vec3f(static_cast<float>(i), static_cast<float>(j), static_cast<float>(k)) * h;
            auto dens = [&](int a, int b, int c) {
              a = std::clamp(a, 0, nx - 1);
              b = std::clamp(b, 0, ny - 1);
              c = std::clamp(c, 0, nz - 1);
              return v.at(a, b, c);
            };
            const Vec3f grad(dens(i + 1, j, k) - dens(i - 1, j, k),
                             dens(i, j + 1, k) - dens(i, j - 1, k),
                             dens(i, j, k + 1) - dens(i, j, k - 1));
            const float g = grad.norm();
            const Vec3f n = g > 0.0f ? Vec3f(-grad / g) : Vec3f(0, 1, 0);
            const float wgt = std::clamp(g, 0.0f, 1.0f);  // surface-like where density changes
            auto lambert = [&](const Vec3f& l) {
              return (1.0f - wgt) * 0.5f + wgt * std::max(0.0f, n.dot(l));
            };
            float t_key =
                vol.transmittance(p + 0.5f * h * key_dir, key_dir) * std::exp(-0.5f * d * h * ext);
            if (t_key > 0.0f && occluded(p, key_dir, kInf)) t_key = 0.0f;
            const float light =
                L.key * t_key * lambert(key_dir) + L.fill * lambert(fill_dir) +
                L.ambient * sky * (0.55f + 0.45f * ((1.0f - wgt) * 0.5f + wgt * n.y()));
            vol.radiance[idx] = v.color * light;
          }
        }
    });
  }

  /// Shades a surface hit; returns linear colour.
  Vec3f shade_hit(const RTCRayHit& rh, const Vec3f& org, const Vec3f& dir, float y01,
                  std::uint32_t px, std::uint32_t py, std::uint32_t s) const {
    const Vec3f p = org + rh.ray.tfar * dir;
    const int mi = mesh_of_geom[rh.hit.geomID];
    Vec3f albedo, n, ng;
    SurfaceKind kind = SurfaceKind::Collider;
    if (mi < 0) {
      ng = Vec3f(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z).normalized();
      n = ng;
      albedo = scene.particles.color;
      if (n.dot(dir) > 0.0f) n = -n;
      ng = n;
    } else {
      const RenderMesh& m = scene.meshes[static_cast<std::size_t>(mi)];
      kind = m.kind;
      const Eigen::Vector3i& t = m.triangles[rh.hit.primID];
      const Vec3f &a = m.positions[t[0]], &b = m.positions[t[1]], &c = m.positions[t[2]];
      ng = (b - a).cross(c - a).normalized();
      const bool front = ng.dot(dir) < 0.0f;
      albedo = front ? m.front : m.back;
      const float u = rh.hit.u, w = rh.hit.v;
      n = m.normals.empty()
              ? ng
              : Vec3f((1 - u - w) * m.normals[t[0]] + u * m.normals[t[1]] + w * m.normals[t[2]])
                    .normalized();
      if (n.dot(dir) > 0.0f) n = -n;
      if (!front) ng = -ng;
      if (kind == SurfaceKind::Ground) albedo = ground_albedo(scene.ground, albedo, p);
    }
    const Vec3f o = p + eps * ng;
    float shadow = 0.0f;
    if (ng.dot(key_dir) > 0.0f && !occluded(o, key_dir, kInf))
      shadow = vol.transmittance(o, key_dir);
    float ao = 1.0f;
    if (scene.ao_samples > 0) {
      // Cosine-weighted directions around n, from the hash.
      const Vec3f t1 =
          (std::abs(n.x()) > 0.9f ? Vec3f(0, 1, 0) : Vec3f(1, 0, 0)).cross(n).normalized();
      const Vec3f t2 = n.cross(t1);
      int hits = 0;
      for (int k = 0; k < scene.ao_samples; ++k) {
        const float r1 = hash01(px, py, s, 2u * k + 11u), r2 = hash01(px, py, s, 2u * k + 12u);
        const float r = std::sqrt(r1), phi = 6.2831853f * r2;
        const Vec3f d = (r * std::cos(phi) * t1 + r * std::sin(phi) * t2 +
                         std::sqrt(std::max(0.0f, 1.0f - r1)) * n)
                            .normalized();
        if (d.dot(ng) <= 0.0f || occluded(o, d, scene.ao_distance)) ++hits;
      }
      ao = 1.0f - static_cast<float>(hits) / static_cast<float>(scene.ao_samples);
    }
    Vec3f c = shade_surface(scene.lights, albedo, n, shadow, ao);
    if (kind == SurfaceKind::Ground) {
      const float f = ground_fade(scene.ground, p);
      c = (1.0f - f) * c + f * background(scene, y01);
    }
    return c;
  }

  /// One camera sample: gamma-encoded colour (0..1 floats) and coverage.
  void trace(double sx, double sy, std::uint32_t px, std::uint32_t py, std::uint32_t s, Vec3f& out,
             float& alpha) const {
    const Vec3f org = cam.eye.cast<float>();
    const Vec3f dir = cam.ray_direction(sx, sy).cast<float>();
    const float y01 = 1.0f - static_cast<float>(sy / cam.height);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh{};
    rh.ray.org_x = org.x();
    rh.ray.org_y = org.y();
    rh.ray.org_z = org.z();
    rh.ray.dir_x = dir.x();
    rh.ray.dir_y = dir.y();
    rh.ray.dir_z = dir.z();
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = kInf;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(rtc, &ctx, &rh);
    const bool hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    Vec3f behind = hit ? shade_hit(rh, org, dir, y01, px, py, s) : background(scene, y01);
    float cover = hit ? 1.0f : 0.0f;
    if (!vol.empty()) {
      float t0, t1;
      if (ray_box(org, dir, vol.lo, vol.hi, t0, t1)) {
        t1 = std::min(t1, hit ? rh.ray.tfar : kInf);
        const float h = 0.5f * scene.volume.voxel, ext = scene.volume.extinction;
        float T = 1.0f;
        Vec3f L = Vec3f::Zero(), rad;
        for (float t = t0 + h * hash01(px, py, s, 7u); t < t1 && T > 1e-3f; t += h) {
          const float d = vol.sample(org + t * dir, rad);
          if (d <= 0.0f) continue;
          const float a = 1.0f - std::exp(-d * ext * h);
          L += T * a * rad;
          T *= 1.0f - a;
        }
        if (T <= 1e-3f) T = 0.0f;
        behind = L + T * behind;
        cover = 1.0f - T * (1.0f - cover);
      }
    }
    for (int c = 0; c < 3; ++c) out[c] = std::pow(std::clamp(behind[c], 0.0f, 1.0f), 1.0f / 2.2f);
    alpha = cover;
  }
};

void embree_error(void* user, RTCError, const char* msg) {
  auto* last = static_cast<std::string*>(user);
  *last = msg ? msg : "unknown Embree error";
}

std::string& device_error_text() {
  static thread_local std::string text;
  return text;
}

}  // namespace

RayTracer::RayTracer(int threads) {
  const std::string config = threads > 0 ? "threads=" + std::to_string(threads) : std::string();
  device_ = rtcNewDevice(config.c_str());
  if (!device_)
    throw std::runtime_error("ray tracer: cannot create the Embree device (" +
                             std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))) + ")");
  rtcSetDeviceErrorFunction(device_, embree_error, &device_error_text());
}

RayTracer::~RayTracer() {
  if (device_) rtcReleaseDevice(device_);
}

namespace {

/// Attaches every non-empty mesh of the scene to tr.rtc as triangles.
void attach_meshes(RTCDevice device, Tracer& tr, const PreviewScene& scene) {
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    const RenderMesh& m = scene.meshes[i];
    if (m.triangles.empty()) continue;
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m.positions.size()));
    auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), m.triangles.size()));
    if (!vb || !ib) {
      rtcReleaseGeometry(g);
      rtcReleaseScene(tr.rtc);
      throw std::runtime_error("ray tracer: out of memory for mesh '" + m.name + "'");
    }
    for (std::size_t v = 0; v < m.positions.size(); ++v)
      for (int a = 0; a < 3; ++a) vb[3 * v + a] = m.positions[v][a];
    for (std::size_t t = 0; t < m.triangles.size(); ++t)
      for (int a = 0; a < 3; ++a) ib[3 * t + a] = static_cast<unsigned>(m.triangles[t][a]);
    rtcCommitGeometry(g);
    const unsigned id = rtcAttachGeometry(tr.rtc, g);
    rtcReleaseGeometry(g);
    if (tr.mesh_of_geom.size() <= id) tr.mesh_of_geom.resize(id + 1, -1);
    tr.mesh_of_geom[id] = static_cast<int>(i);
  }
}

/// Attaches the particles to tr.rtc as spheres of their radius.
void attach_particles(RTCDevice device, Tracer& tr, const PreviewScene& scene) {
  if (scene.particles.positions.empty()) return;
  const RenderParticles& p = scene.particles;
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
      g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), p.positions.size()));
  if (!vb) {
    rtcReleaseGeometry(g);
    rtcReleaseScene(tr.rtc);
    throw std::runtime_error("ray tracer: out of memory for the particles");
  }
  for (std::size_t v = 0; v < p.positions.size(); ++v) {
    vb[4 * v] = p.positions[v].x();
    vb[4 * v + 1] = p.positions[v].y();
    vb[4 * v + 2] = p.positions[v].z();
    vb[4 * v + 3] = p.radius;
  }
  rtcCommitGeometry(g);
  const unsigned id = rtcAttachGeometry(tr.rtc, g);
  rtcReleaseGeometry(g);
  if (tr.mesh_of_geom.size() <= id) tr.mesh_of_geom.resize(id + 1, -1);
  tr.mesh_of_geom[id] = -1;
}

/// Traces every pixel, 16x16 tiles in parallel; each pixel averages its stratified,
/// jittered samples (the jitter hashes the pixel and sample: the same on any thread count).
Image trace_image(Tracer& tr, const PreviewScene& scene, const Camera& cam) {
  Image out(cam.width, cam.height);
  const int spp = std::max(1, scene.samples);
  const int m = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(spp))));
  constexpr int kTile = 16;
  const int tx = (cam.width + kTile - 1) / kTile, ty = (cam.height + kTile - 1) / kTile;
  parallel_for(static_cast<std::size_t>(tx) * ty, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t tile = b; tile < e; ++tile) {
      const int x0 = static_cast<int>(tile % tx) * kTile, y0 = static_cast<int>(tile / tx) * kTile;
      for (int y = y0; y < std::min(y0 + kTile, cam.height); ++y)
        for (int x = x0; x < std::min(x0 + kTile, cam.width); ++x) {
          Vec3f sum = Vec3f::Zero(), c;
          float asum = 0.0f, a;
          for (int s = 0; s < spp; ++s) {
            double sx = x + 0.5, sy = y + 0.5;
            if (spp > 1) {  // stratified: cell (s % m, s / m) of an m x m grid, jittered
              const auto ux = static_cast<std::uint32_t>(x), uy = static_cast<std::uint32_t>(y);
              const auto us = static_cast<std::uint32_t>(s);
              sx = x + ((s % m) + hash01(ux, uy, us, 1u)) / m;
              sy = y + ((s / m) % m + hash01(ux, uy, us, 2u)) / m;
            }
            tr.trace(sx, sy, static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y),
                     static_cast<std::uint32_t>(s), c, a);
            sum += c;
            asum += a;
          }
          std::uint8_t* px = out.pixel(x, y);
          for (int k = 0; k < 3; ++k)
            px[k] = static_cast<std::uint8_t>(
                std::lround(std::clamp(sum[k] / spp, 0.0f, 1.0f) * 255.0f));
          px[3] =
              static_cast<std::uint8_t>(std::lround(std::clamp(asum / spp, 0.0f, 1.0f) * 255.0f));
        }
    }
  });
  return out;
}

}  // namespace

Image RayTracer::render(const PreviewScene& scene, const Camera& cam) {
  Tracer tr(scene, cam);
  device_error_text().clear();
  tr.rtc = rtcNewScene(device_);
  rtcSetSceneFlags(tr.rtc, RTC_SCENE_FLAG_ROBUST);
  attach_meshes(device_, tr, scene);
  attach_particles(device_, tr, scene);
  rtcCommitScene(tr.rtc);
  if (!device_error_text().empty()) {
    rtcReleaseScene(tr.rtc);
    throw std::runtime_error("ray tracer: Embree: " + device_error_text());
  }
  const float size = std::max((scene.bounds_hi - scene.bounds_lo).norm(), 1e-3f);
  tr.eps = 2e-5f * (size + static_cast<float>(cam.eye.norm()));
  tr.key_dir = scene.lights.key_dir.normalized();
  tr.fill_dir = scene.lights.fill_dir.normalized();
  tr.prepare_volume();

  Image out = trace_image(tr, scene, cam);
  rtcReleaseScene(tr.rtc);
  return out;
}

}  // namespace shellmpm
