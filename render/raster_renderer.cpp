#include "render/raster_renderer.h"

#define GL_GLEXT_PROTOTYPES 1
// glext.h needs the types osmesa.h (through gl.h) declares first.
// clang-format off
#include <GL/osmesa.h>
#include <GL/glext.h>
// clang-format on

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

namespace shellmpm {
namespace {

// The shading of render/shading.h, in GLSL. Keep the two in step.
const char* kShadeGlsl = R"(
uniform vec3 u_key_dir, u_fill_dir;
uniform float u_key, u_fill, u_ambient;
uniform sampler2DShadow u_shadow;
uniform mat4 u_light_vp;
uniform float u_shadow_texel, u_normal_bias;
vec3 encode(vec3 c) { return pow(clamp(c, 0.0, 1.0), vec3(1.0 / 2.2)); }
float key_visibility(vec3 p, vec3 n) {
  vec4 q = u_light_vp * vec4(p + n * u_normal_bias, 1.0);
  vec3 c = q.xyz / q.w * 0.5 + 0.5;
  if (c.x < 0.0 || c.x > 1.0 || c.y < 0.0 || c.y > 1.0) return 1.0;
  float s = 0.0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      s += texture(u_shadow, vec3(c.xy + vec2(dx, dy) * u_shadow_texel, min(c.z, 1.0)));
  return s / 9.0;
}
// One bilinear tap, for particles (a few pixels each: the 3x3 filter would not show).
float key_visibility1(vec3 p, vec3 n) {
  vec4 q = u_light_vp * vec4(p + n * u_normal_bias, 1.0);
  vec3 c = q.xyz / q.w * 0.5 + 0.5;
  if (c.x < 0.0 || c.x > 1.0 || c.y < 0.0 || c.y > 1.0) return 1.0;
  return texture(u_shadow, vec3(c.xy, min(c.z, 1.0)));
}
vec3 shade_surface(vec3 albedo, vec3 n, float shadow) {
  float sky = u_ambient * (0.55 + 0.45 * n.y);
  return albedo * (sky + u_key * shadow * max(0.0, dot(n, u_key_dir)) +
                   u_fill * max(0.0, dot(n, u_fill_dir)));
}
)";

const char* kMeshVs = R"(#version 330 core
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_nrm;
uniform mat4 u_vp;
out vec3 v_pos;
out vec3 v_nrm;
void main() { v_pos = a_pos; v_nrm = a_nrm; gl_Position = u_vp * vec4(a_pos, 1.0); }
)";

const char* kMeshFs = R"(
in vec3 v_pos;
in vec3 v_nrm;
uniform vec3 u_eye, u_front, u_back;
uniform int u_kind;  // 0 shell, 1 collider, 2 ground, 3 bulk
uniform vec3 u_ground_center, u_bg_top, u_bg_bottom;
uniform float u_ground_radius, u_tile, u_height;
out vec4 o_color;
void main() {
  vec3 n = normalize(v_nrm);
  vec3 albedo = gl_FrontFacing ? u_front : u_back;
  if (dot(n, u_eye - v_pos) < 0.0) n = -n;
  if (u_kind == 2 && mod(floor(v_pos.x / u_tile) + floor(v_pos.z / u_tile), 2.0) >= 1.0)
    albedo *= 0.82;
  vec3 c = shade_surface(albedo, n, key_visibility(v_pos, n));
  if (u_kind == 2) {
    float x = clamp((length(v_pos - u_ground_center) / u_ground_radius - 0.55) / 0.45, 0.0, 1.0);
    c = mix(c, mix(u_bg_bottom, u_bg_top, gl_FragCoord.y / u_height), x * x * (3.0 - 2.0 * x));
  }
  o_color = vec4(encode(c), 1.0);
}
)";

const char* kPointVs = R"(#version 330 core
layout(location = 0) in vec3 a_pos;
uniform mat4 u_vp;
uniform float u_radius, u_px_scale;
out vec3 v_center;
void main() {
  vec4 c = u_vp * vec4(a_pos, 1.0);
  gl_Position = c;
  gl_PointSize = max(1.0, 2.0 * u_radius * u_px_scale / c.w);
  v_center = a_pos;
}
)";

const char* kPointFs = R"(
in vec3 v_center;
uniform vec3 u_eye, u_front, u_cam_right, u_cam_up;
uniform float u_radius;
out vec4 o_color;
void main() {
  vec2 q = gl_PointCoord * 2.0 - 1.0;
  q.y = -q.y;
  float r2 = dot(q, q);
  if (r2 > 1.0) discard;
  vec3 n = normalize(q.x * u_cam_right + q.y * u_cam_up +
                     sqrt(1.0 - r2) * normalize(u_eye - v_center));
  vec3 p = v_center + u_radius * n;
  o_color = vec4(encode(shade_surface(u_front, n, key_visibility1(p, n))), 1.0);
}
)";

const char* kDepthVs = R"(#version 330 core
layout(location = 0) in vec3 a_pos;
uniform mat4 u_vp;
uniform float u_point_px;
void main() { gl_Position = u_vp * vec4(a_pos, 1.0); gl_PointSize = max(1.0, u_point_px); }
)";

const char* kDepthFs = R"(#version 330 core
uniform int u_points;
void main() {
  if (u_points == 1 && dot(gl_PointCoord * 2.0 - 1.0, gl_PointCoord * 2.0 - 1.0) > 1.0) discard;
}
)";

const char* kBackgroundVs = R"(#version 330 core
void main() {
  vec2 p = vec2((gl_VertexID == 1) ? 3.0 : -1.0, (gl_VertexID == 2) ? 3.0 : -1.0);
  gl_Position = vec4(p, 0.0, 1.0);
}
)";

const char* kBackgroundFs = R"(#version 330 core
uniform vec3 u_bg_top, u_bg_bottom;
uniform float u_height;
out vec4 o_color;
void main() {
  vec3 c = mix(u_bg_bottom, u_bg_top, gl_FragCoord.y / u_height);
  o_color = vec4(pow(clamp(c, 0.0, 1.0), vec3(1.0 / 2.2)), 0.0);
}
)";

constexpr int kShadowSize = 2048;

/// Throws "GLSL <what> error" with the info log of shader or program obj when its
/// `status` is not set (deleting obj); get_iv, get_log and del are the shader or program
/// variants of glGet*iv, glGet*InfoLog and glDelete*.
template <class GetIv, class GetLog, class Delete>
void check_status(GLuint obj, GLenum status, GetIv get_iv, GetLog get_log, Delete del,
                  const char* what) {
  GLint ok = 0;
  get_iv(obj, status, &ok);
  if (ok) return;
  char log[4096] = {};
  get_log(obj, sizeof log, nullptr, log);
  del(obj);
  throw std::runtime_error(std::string("raster renderer: GLSL ") + what + " error: " + log);
}

GLuint compile(GLenum type, const std::string& src) {
  GLuint s = glCreateShader(type);
  const char* p = src.c_str();
  glShaderSource(s, 1, &p, nullptr);
  glCompileShader(s);
  check_status(s, GL_COMPILE_STATUS, glGetShaderiv, glGetShaderInfoLog, glDeleteShader, "compile");
  return s;
}

GLuint link(const std::string& vs, const std::string& fs) {
  GLuint v = compile(GL_VERTEX_SHADER, vs), f = compile(GL_FRAGMENT_SHADER, fs);
  GLuint p = glCreateProgram();
  glAttachShader(p, v);
  glAttachShader(p, f);
  glLinkProgram(p);
  glDeleteShader(v);
  glDeleteShader(f);
  check_status(p, GL_LINK_STATUS, glGetProgramiv, glGetProgramInfoLog, glDeleteProgram, "link");
  return p;
}

std::string fragment(const char* body) {
  return std::string("#version 330 core\n") + kShadeGlsl + body;
}

Eigen::Matrix4f look_at(const Eigen::Vector3f& eye, const Eigen::Vector3f& target,
                        const Eigen::Vector3f& up_hint) {
  const Eigen::Vector3f f = (target - eye).normalized();
  const Eigen::Vector3f r = f.cross(up_hint).normalized();
  const Eigen::Vector3f u = r.cross(f);
  return view_from_basis<float>(eye, r, u, f);
}

Eigen::Matrix4f ortho(float half_w, float half_h, float n, float f) {
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  m(0, 0) = 1.0f / half_w;
  m(1, 1) = 1.0f / half_h;
  m(2, 2) = -2.0f / (f - n);
  m(2, 3) = -(f + n) / (f - n);
  return m;
}

void check_gl(const char* where) {
  const GLenum e = glGetError();
  if (e != GL_NO_ERROR)
    throw std::runtime_error(std::string("raster renderer: OpenGL error 0x") + [&] {
      char b[16];
      std::snprintf(b, sizeof b, "%04x", e);
      return std::string(b);
    }() + " in " + where);
}

}  // namespace

struct RasterRenderer::Gl {
  OSMesaContext ctx = nullptr;
  std::vector<unsigned char> dummy = std::vector<unsigned char>(16 * 16 * 4);
  GLuint mesh_prog = 0, point_prog = 0, depth_prog = 0, bg_prog = 0;
  GLuint vao = 0;
  GLuint shadow_tex = 0, shadow_fbo = 0;
  GLuint ms_fbo = 0, ms_color = 0, ms_depth = 0, resolve_fbo = 0, resolve_color = 0;
  int width = 0, height = 0, samples = 4;

  void make_current() {
    if (!OSMesaMakeCurrent(ctx, dummy.data(), GL_UNSIGNED_BYTE, 16, 16))
      throw std::runtime_error("raster renderer: OSMesaMakeCurrent failed");
  }

  void resize(int w, int h) {
    if (w == width && h == height) return;
    if (ms_fbo) {
      glDeleteFramebuffers(1, &ms_fbo);
      glDeleteFramebuffers(1, &resolve_fbo);
      glDeleteRenderbuffers(1, &ms_color);
      glDeleteRenderbuffers(1, &ms_depth);
      glDeleteRenderbuffers(1, &resolve_color);
    }
    glGenFramebuffers(1, &ms_fbo);
    glGenRenderbuffers(1, &ms_color);
    glGenRenderbuffers(1, &ms_depth);
    glBindRenderbuffer(GL_RENDERBUFFER, ms_color);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, w, h);
    glBindRenderbuffer(GL_RENDERBUFFER, ms_depth);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, ms_fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, ms_color);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, ms_depth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("raster renderer: multisample framebuffer incomplete");
    glGenFramebuffers(1, &resolve_fbo);
    glGenRenderbuffers(1, &resolve_color);
    glBindRenderbuffer(GL_RENDERBUFFER, resolve_color);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolve_color);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("raster renderer: resolve framebuffer incomplete");
    width = w;
    height = h;
    check_gl("framebuffer setup");
  }
};

RasterRenderer::RasterRenderer(int threads) : gl_(std::make_unique<Gl>()) {
  // llvmpipe reads these when the first context of the process creates its screen.
  if (threads > 0) setenv("LP_NUM_THREADS", std::to_string(threads).c_str(), 1);
  setenv("GALLIUM_DRIVER", "llvmpipe", 0);
  const int attribs[] = {OSMESA_FORMAT,
                         OSMESA_RGBA,
                         OSMESA_DEPTH_BITS,
                         24,
                         OSMESA_STENCIL_BITS,
                         0,
                         OSMESA_ACCUM_BITS,
                         0,
                         OSMESA_PROFILE,
                         OSMESA_CORE_PROFILE,
                         OSMESA_CONTEXT_MAJOR_VERSION,
                         3,
                         OSMESA_CONTEXT_MINOR_VERSION,
                         3,
                         0};
  gl_->ctx = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!gl_->ctx)
    throw std::runtime_error(
        "raster renderer: cannot create an OpenGL 3.3 core context with OSMesa");
  try {
    gl_->make_current();
    GLint max_samples = 1;
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    gl_->samples = std::max(1, std::min(4, static_cast<int>(max_samples)));
    gl_->mesh_prog = link(kMeshVs, fragment(kMeshFs));
    gl_->point_prog = link(kPointVs, fragment(kPointFs));
    gl_->depth_prog = link(kDepthVs, kDepthFs);
    gl_->bg_prog = link(kBackgroundVs, kBackgroundFs);
    glGenVertexArrays(1, &gl_->vao);
    glGenTextures(1, &gl_->shadow_tex);
    glBindTexture(GL_TEXTURE_2D, gl_->shadow_tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, kShadowSize, kShadowSize, 0,
                 GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glGenFramebuffers(1, &gl_->shadow_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, gl_->shadow_fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, gl_->shadow_tex, 0);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("raster renderer: shadow framebuffer incomplete");
    check_gl("context setup");
  } catch (...) {
    OSMesaDestroyContext(gl_->ctx);
    throw;
  }
}

RasterRenderer::~RasterRenderer() {
  if (!gl_ || !gl_->ctx) return;
  Gl& g = *gl_;
  if (OSMesaMakeCurrent(g.ctx, g.dummy.data(), GL_UNSIGNED_BYTE, 16, 16)) {
    glDeleteProgram(g.mesh_prog);
    glDeleteProgram(g.point_prog);
    glDeleteProgram(g.depth_prog);
    glDeleteProgram(g.bg_prog);
    glDeleteVertexArrays(1, &g.vao);
    glDeleteTextures(1, &g.shadow_tex);
    glDeleteFramebuffers(1, &g.shadow_fbo);
    if (g.ms_fbo) {
      glDeleteFramebuffers(1, &g.ms_fbo);
      glDeleteFramebuffers(1, &g.resolve_fbo);
      glDeleteRenderbuffers(1, &g.ms_color);
      glDeleteRenderbuffers(1, &g.ms_depth);
      glDeleteRenderbuffers(1, &g.resolve_color);
    }
  }
  OSMesaDestroyContext(g.ctx);
}

int RasterRenderer::samples() const {
  return gl_->samples;
}

namespace {

/// The frame's vertex buffers (freed with it: nothing accumulates across frames).
class FrameBuffers {
 public:
  struct Mesh {
    GLuint pos, nrm, idx;
    GLsizei count;
  };
  explicit FrameBuffers(const PreviewScene& scene) {
    for (const RenderMesh& m : scene.meshes) {
      Mesh b{};
      b.pos = upload(GL_ARRAY_BUFFER, m.positions.data(), m.positions.size() * sizeof(Vec3f));
      b.nrm = upload(GL_ARRAY_BUFFER, m.normals.data(), m.normals.size() * sizeof(Vec3f));
      b.idx = upload(GL_ELEMENT_ARRAY_BUFFER, m.triangles.data(),
                     m.triangles.size() * sizeof(Eigen::Vector3i));
      b.count = static_cast<GLsizei>(m.triangles.size() * 3);
      meshes.push_back(b);
    }
    const RenderParticles& pts = scene.particles;
    num_points = static_cast<GLsizei>(pts.positions.size());
    points = pts.positions.empty() ? 0
                                   : upload(GL_ARRAY_BUFFER, pts.positions.data(),
                                            pts.positions.size() * sizeof(Vec3f));
  }
  ~FrameBuffers() { glDeleteBuffers(static_cast<GLsizei>(buffers_.size()), buffers_.data()); }
  FrameBuffers(const FrameBuffers&) = delete;
  FrameBuffers& operator=(const FrameBuffers&) = delete;

  void bind_mesh(std::size_t i, bool normals) const {
    const Mesh& b = meshes[i];
    glBindBuffer(GL_ARRAY_BUFFER, b.pos);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    if (normals) {
      glBindBuffer(GL_ARRAY_BUFFER, b.nrm);
      glEnableVertexAttribArray(1);
      glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    } else {
      glDisableVertexAttribArray(1);
    }
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, b.idx);
  }
  void draw_mesh(std::size_t i, bool normals) const {
    bind_mesh(i, normals);
    glDrawElements(GL_TRIANGLES, meshes[i].count, GL_UNSIGNED_INT, nullptr);
  }
  void draw_points() const {
    glBindBuffer(GL_ARRAY_BUFFER, points);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    glDisableVertexAttribArray(1);
    glDrawArrays(GL_POINTS, 0, num_points);
  }

  std::vector<Mesh> meshes;
  GLuint points = 0;  ///< 0 when there are no particles
  GLsizei num_points = 0;

 private:
  GLuint upload(GLenum target, const void* data, std::size_t bytes) {
    GLuint b = 0;
    glGenBuffers(1, &b);
    glBindBuffer(target, b);
    glBufferData(target, static_cast<GLsizeiptr>(bytes), data, GL_STATIC_DRAW);
    buffers_.push_back(b);
    return b;
  }
  std::vector<GLuint> buffers_;
};

/// The key light's orthographic view of the content bounds, for the shadow map.
struct ShadowView {
  Eigen::Matrix4f vp;
  float px_per_m;  ///< shadow-map pixels per metre
};

ShadowView shadow_view(const PreviewScene& scene) {
  const Vec3f lo = scene.bounds_lo, hi = scene.bounds_hi;
  const Vec3f center = 0.5f * (lo + hi);
  const float radius = std::max(0.5f * (hi - lo).norm(), 1e-3f);
  const Vec3f kd = scene.lights.key_dir.normalized();
  const Vec3f up_hint = std::abs(kd.y()) > 0.99f ? Vec3f(0, 0, 1) : Vec3f(0, 1, 0);
  return {ortho(radius, radius, radius, 3.0f * radius) *
              look_at(center + 2.0f * radius * kd, center, up_hint),
          kShadowSize / (2.0f * radius)};
}

/// Renders the shadow casters' depth from the key light into `fbo`.
void shadow_pass(GLuint fbo, GLuint depth_prog, const PreviewScene& scene, const FrameBuffers& fb,
                 const ShadowView& light) {
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, kShadowSize, kShadowSize);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glClear(GL_DEPTH_BUFFER_BIT);
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(2.0f, 4.0f);
  glEnable(GL_PROGRAM_POINT_SIZE);
  glUseProgram(depth_prog);
  glUniformMatrix4fv(glGetUniformLocation(depth_prog, "u_vp"), 1, GL_FALSE, light.vp.data());
  glUniform1i(glGetUniformLocation(depth_prog, "u_points"), 0);
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    if (scene.meshes[i].kind == SurfaceKind::Ground) continue;  // receives, never casts
    fb.draw_mesh(i, false);
  }
  if (fb.points) {
    glUniform1i(glGetUniformLocation(depth_prog, "u_points"), 1);
    glUniform1f(glGetUniformLocation(depth_prog, "u_point_px"),
                2.0f * scene.particles.radius * light.px_per_m);
    fb.draw_points();
  }
  glDisable(GL_POLYGON_OFFSET_FILL);
  check_gl("shadow pass");
}

/// The camera's view-projection, its depth range from the content and the ground around it.
Eigen::Matrix4f camera_view_projection(const PreviewScene& scene, const Camera& cam) {
  const Vec3f lo = scene.bounds_lo, hi = scene.bounds_hi;
  double z_far = 1e-3;
  const Vec3d eye = cam.eye;
  for (int c = 0; c < 8; ++c) {
    const Vec3d p((c & 1 ? hi : lo).x(), (c & 2 ? hi : lo).y(), (c & 4 ? hi : lo).z());
    z_far = std::max(z_far, (p - eye).norm());
  }
  z_far = std::max(z_far, (scene.ground.center.cast<double>() - eye).norm() + scene.ground.radius);
  z_far *= 1.05;
  const double z_near = z_far * 2e-4;
  return cam.projection_matrix(z_near, z_far) * cam.view_matrix();
}

/// Sets the uniforms every main-pass program shares: background, lights, shadow map.
void set_lights(GLuint p, const PreviewScene& scene, const Camera& cam, const Eigen::Matrix4f& vp,
                const ShadowView& light) {
  glUseProgram(p);
  auto loc = [&](const char* n) { return glGetUniformLocation(p, n); };
  glUniform3fv(loc("u_bg_top"), 1, scene.bg_top.data());
  glUniform3fv(loc("u_bg_bottom"), 1, scene.bg_bottom.data());
  glUniform1f(loc("u_height"), static_cast<float>(cam.height));
  const Vec3f eye_f = cam.eye.cast<float>();
  const Vec3f kd = scene.lights.key_dir.normalized();
  const Vec3f fill_d = scene.lights.fill_dir.normalized();
  glUniformMatrix4fv(loc("u_vp"), 1, GL_FALSE, vp.data());
  glUniformMatrix4fv(loc("u_light_vp"), 1, GL_FALSE, light.vp.data());
  glUniform3fv(loc("u_eye"), 1, eye_f.data());
  glUniform3fv(loc("u_key_dir"), 1, kd.data());
  glUniform3fv(loc("u_fill_dir"), 1, fill_d.data());
  glUniform1f(loc("u_key"), scene.lights.key);
  glUniform1f(loc("u_fill"), scene.lights.fill);
  glUniform1f(loc("u_ambient"), scene.lights.ambient);
  glUniform1f(loc("u_shadow_texel"), 1.0f / kShadowSize);
  glUniform1f(loc("u_normal_bias"), 1.5f / light.px_per_m);
  glUniform1i(loc("u_shadow"), 0);
}

/// Draws the meshes (mesh_prog) and the particles (point_prog), lit and shadowed.
void draw_lit(GLuint mesh_prog, GLuint point_prog, const PreviewScene& scene, const Camera& cam,
              const FrameBuffers& fb, const ShadowView& light) {
  const Eigen::Matrix4f vp = camera_view_projection(scene, cam);
  set_lights(mesh_prog, scene, cam, vp, light);
  auto loc = [&](const char* n) { return glGetUniformLocation(mesh_prog, n); };
  glUniform3fv(loc("u_ground_center"), 1, scene.ground.center.data());
  glUniform1f(loc("u_ground_radius"), scene.ground.radius);
  glUniform1f(loc("u_tile"), scene.ground.tile);
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    const RenderMesh& m = scene.meshes[i];
    glUniform1i(loc("u_kind"), static_cast<int>(m.kind));
    glUniform3fv(loc("u_front"), 1, m.front.data());
    glUniform3fv(loc("u_back"), 1, m.back.data());
    fb.draw_mesh(i, true);
  }
  if (!fb.points) return;
  const RenderParticles& pts = scene.particles;
  set_lights(point_prog, scene, cam, vp, light);
  auto ploc = [&](const char* n) { return glGetUniformLocation(point_prog, n); };
  const Vec3f right_f = cam.right().cast<float>(), up_f = cam.up().cast<float>();
  glUniform3fv(ploc("u_front"), 1, pts.color.data());
  glUniform3fv(ploc("u_cam_right"), 1, right_f.data());
  glUniform3fv(ploc("u_cam_up"), 1, up_f.data());
  glUniform1f(ploc("u_radius"), pts.radius);
  glUniform1f(ploc("u_px_scale"), static_cast<float>(0.5 * cam.height / cam.tan_half_fov()));
  fb.draw_points();
}

/// Resolves the multisampled buffer and reads it back top row first (OpenGL's rows are
/// bottom-up).
Image read_back(GLuint ms_fbo, GLuint resolve_fbo, int width, int height) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, ms_fbo);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo);
  glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, resolve_fbo);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  Image out(width, height);
  std::vector<std::uint8_t> rows(out.rgba.size());
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rows.data());
  check_gl("read back");
  const std::size_t stride = static_cast<std::size_t>(width) * 4;
  for (int y = 0; y < height; ++y)
    std::copy_n(rows.data() + static_cast<std::size_t>(height - 1 - y) * stride, stride,
                out.rgba.data() + static_cast<std::size_t>(y) * stride);
  return out;
}

}  // namespace

Image RasterRenderer::render(const PreviewScene& scene, const Camera& cam) {
  Gl& g = *gl_;
  g.make_current();
  g.resize(cam.width, cam.height);
  Image out;
  {
    const FrameBuffers fb(scene);
    glBindVertexArray(g.vao);
    const ShadowView light = shadow_view(scene);
    shadow_pass(g.shadow_fbo, g.depth_prog, scene, fb, light);
    // Main pass, multisampled: the background, then the lit content.
    glBindFramebuffer(GL_FRAMEBUFFER, g.ms_fbo);
    glViewport(0, 0, cam.width, cam.height);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glDisable(GL_DEPTH_TEST);
    glUseProgram(g.bg_prog);
    glUniform3fv(glGetUniformLocation(g.bg_prog, "u_bg_top"), 1, scene.bg_top.data());
    glUniform3fv(glGetUniformLocation(g.bg_prog, "u_bg_bottom"), 1, scene.bg_bottom.data());
    glUniform1f(glGetUniformLocation(g.bg_prog, "u_height"), static_cast<float>(cam.height));
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glEnable(GL_DEPTH_TEST);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, g.shadow_tex);
    draw_lit(g.mesh_prog, g.point_prog, scene, cam, fb, light);
    check_gl("main pass");
    out = read_back(g.ms_fbo, g.resolve_fbo, cam.width, cam.height);
    glBindVertexArray(0);
  }
  glFinish();
  return out;
}

}  // namespace shellmpm
