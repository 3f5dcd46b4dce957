#include "io/checkpoint.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include "io/atomic_file.h"
#include "io/checksum.h"
#include "io/frame_number.h"
#include "sim/contact/friction_return_map.h"
#include "sim/solver/solver.h"

namespace shellmpm {
namespace {

constexpr char kMagic[8] = {'S', 'H', 'M', 'P', 'M', 'C', 'K', '5'};
constexpr char kEndMagic[8] = {'S', 'H', 'M', 'P', 'M', 'E', 'N', 'D'};
constexpr std::size_t kHeaderBytes = 8 + 4 + 8;  // magic, sizeof(Real), payload size
constexpr std::size_t kTrailerBytes = 4 + 8;     // CRC-32, end magic

// ---- writing: one serializer, run once to count the payload and once to write it ----

struct CountingSink {
  std::uint64_t bytes = 0;
  void put(const void*, std::size_t n) { bytes += n; }
};

struct FileSink {
  CheckedFile& out;
  Crc32 crc;
  void put(const void* p, std::size_t n) {
    out.write(p, n);
    crc.update(p, n);
  }
};

template <class T, class Sink>
void put(Sink& s, const T& v) {
  s.put(&v, sizeof(T));
}
template <class T, class Sink>
void put_vec(Sink& s, const std::vector<T>& v) {
  put<std::uint64_t>(s, v.size());
  s.put(v.data(), v.size() * sizeof(T));
}

template <class Sink>
void put_payload(Sink& s, const Checkpoint& c) {
  put(s, c.scene_fingerprint);
  put<std::int32_t>(s, c.frame);
  put(s, c.time);
  const ParticleSet& p = c.particles;
  put<std::uint64_t>(s, p.size());
  put<std::uint32_t>(s, p.next_id);
  put<std::uint8_t>(s, p.keep_plastic ? 1 : 0);
  put_vec(s, p.x);
  put_vec(s, p.v);
  put_vec(s, p.C);
  put_vec(s, p.F);
  put_vec(s, p.kind_material);
  put_vec(s, p.kind_volume);
  put_vec(s, p.kind);
  put_vec(s, p.id);
  put_vec(s, p.plastic);
  put<std::uint64_t>(s, c.stats_json.size());
  s.put(c.stats_json.data(), c.stats_json.size());
  put<std::uint64_t>(s, c.shells.size());
  put(s, c.shell_plastic_work);
  put(s, c.friction_work);
  for (const auto& sh : c.shells) {
    put_vec(s, sh.x);
    put_vec(s, sh.v);
    put_vec(s, sh.plastic);
    put_vec(s, sh.C);
    put_vec(s, sh.a3e);
    put_vec(s, sh.contact_state);
  }
}

// ---- reading: a cursor over the payload that checks every length it is given ----

struct Cursor {
  const char* p;
  const char* end;
  const std::string& path;

  [[noreturn]] void fail(const std::string& what) const { throw CheckpointDamaged(path, what); }
  std::size_t left() const { return static_cast<std::size_t>(end - p); }
  void take(void* dst, std::size_t n, const std::string& what) {
    if (n > left()) fail(what + " runs past the end of the payload");
    if (n == 0) return;  // an empty array: its data() may be null, which memcpy must not see
    std::memcpy(dst, p, n);
    p += n;
  }
  template <class T>
  T get(const std::string& what) {
    T v;
    take(&v, sizeof(T), what);
    return v;
  }
  /// A length-prefixed array; `expect` (if not ~0) is the length it must have.
  template <class T>
  void get_vec(std::vector<T>& v, const std::string& what, std::uint64_t expect = ~0ull) {
    const auto n = get<std::uint64_t>(what + " length");
    if (expect != ~0ull && n != expect)
      fail(what + " has " + std::to_string(n) + " entries, expected " + std::to_string(expect));
    if (n > left() / sizeof(T))
      fail(what + " claims " + std::to_string(n) + " entries, more than the file holds");
    v.resize(n);
    take(v.data(), n * sizeof(T), what);
  }
};

bool finite(Real x) {
  return std::isfinite(x);
}
template <class M>
bool finite(const M& m) {
  return m.allFinite();
}
template <class T>
void require_finite(const Cursor& in, const std::vector<T>& v, const std::string& what) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!finite(v[i])) in.fail(what + "[" + std::to_string(i) + "] is not finite");
}

std::string read_whole_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw CheckpointDamaged(path, "cannot open it");
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw CheckpointDamaged(path, "cannot read its size: " + ec.message());
  std::string bytes(size, '\0');
  f.read(bytes.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(f.gcount()) != size)
    throw CheckpointDamaged(path, "cannot read it");
  return bytes;
}

void parse_payload(Cursor& in, Checkpoint& c) {
  c.scene_fingerprint = in.get<std::uint64_t>("scene fingerprint");
  c.frame = in.get<std::int32_t>("frame");
  if (c.frame < 1 || c.frame > kMaxFrameNumber)
    in.fail("frame " + std::to_string(c.frame) + " is out of range");
  c.time = in.get<double>("time");
  if (!std::isfinite(c.time) || c.time < 0) in.fail("time is negative or not finite");
  const auto n = in.get<std::uint64_t>("particle count");
  ParticleSet& p = c.particles;
  p.next_id = in.get<std::uint32_t>("next particle id");
  const auto keep = in.get<std::uint8_t>("plastic flag");
  if (keep > 1) in.fail("plastic flag is " + std::to_string(keep));
  p.keep_plastic = keep == 1;
  in.get_vec(p.x, "particle positions", n);
  in.get_vec(p.v, "particle velocities", n);
  in.get_vec(p.C, "particle APIC matrices", n);
  in.get_vec(p.F, "particle deformation gradients", n);
  in.get_vec(p.kind_material, "particle kind materials");
  const std::size_t nk = p.kind_material.size();
  if (nk > 65536) in.fail("particle kind count " + std::to_string(nk) + " is above 65536");
  in.get_vec(p.kind_volume, "particle kind volumes", nk);
  in.get_vec(p.kind, "particle kinds", n);
  in.get_vec(p.id, "particle ids", n);
  in.get_vec(p.plastic, "particle plastic state", p.keep_plastic ? n : 0);
  require_finite(in, p.x, "particle position");
  require_finite(in, p.v, "particle velocity");
  require_finite(in, p.C, "particle APIC matrix");
  require_finite(in, p.F, "particle deformation gradient");
  require_finite(in, p.plastic, "particle plastic state");
  for (std::size_t k = 0; k < nk; ++k)
    if (!(p.kind_volume[k] > 0) || !std::isfinite(p.kind_volume[k]))
      in.fail("particle kind volume[" + std::to_string(k) + "] is not positive and finite");
  for (std::size_t i = 0; i < n; ++i) {
    if (p.kind[i] >= nk)
      in.fail("particle kind[" + std::to_string(i) + "] is " + std::to_string(p.kind[i]) +
              ", not below the kind count " + std::to_string(nk));
    if (p.id[i] >= p.next_id)
      in.fail("particle id[" + std::to_string(i) + "] is not below next id " +
              std::to_string(p.next_id));
    // A deformation gradient no step can produce: inverted or collapsed.
    const double det = static_cast<double>(p.F[i].determinant());
    if (!(det > 0))
      in.fail("particle " + std::to_string(i) + " (id " + std::to_string(p.id[i]) +
              ") has a deformation gradient of determinant " + std::to_string(det) +
              " (not positive)");
  }
  {
    // Ids are unique: every particle is given the next one when it is made.
    std::vector<std::uint32_t> ids(p.id);
    std::sort(ids.begin(), ids.end());
    const auto twin = std::adjacent_find(ids.begin(), ids.end());
    if (twin != ids.end()) in.fail("two particles have id " + std::to_string(*twin));
  }
  const auto len = in.get<std::uint64_t>("statistics length");
  if (len > in.left()) in.fail("statistics claim more bytes than the file holds");
  c.stats_json.resize(len);
  in.take(c.stats_json.data(), len, "statistics");
  const auto stats = nlohmann::json::parse(c.stats_json, nullptr, /*allow_exceptions=*/false);
  if (!stats.is_array()) in.fail("statistics are not a JSON array");
  const auto nshells = in.get<std::uint64_t>("shell count");
  // Each shell holds five length prefixes at least.
  if (nshells > in.left() / (5 * sizeof(std::uint64_t)))
    in.fail("shell count is larger than the file holds");
  c.shell_plastic_work = in.get<double>("shell plastic work");
  c.friction_work = in.get<double>("friction work");
  if (!std::isfinite(c.shell_plastic_work) || !std::isfinite(c.friction_work))
    in.fail("accumulated work is not finite");
  c.shells.resize(nshells);
  for (std::size_t i = 0; i < nshells; ++i) {
    auto& sh = c.shells[i];
    const std::string name = "shell " + std::to_string(i);
    in.get_vec(sh.x, name + " positions");
    in.get_vec(sh.v, name + " velocities", sh.x.size());
    in.get_vec(sh.plastic, name + " plastic state");
    in.get_vec(sh.C, name + " APIC matrices");
    in.get_vec(sh.a3e, name + " contact normals");
    in.get_vec(sh.contact_state, name + " contact states", sh.a3e.size());
    for (const std::uint8_t st : sh.contact_state)
      if (st > static_cast<std::uint8_t>(ContactState::Sliding))
        in.fail(name + " has a contact state out of range");
    require_finite(in, sh.x, name + " position");
    require_finite(in, sh.v, name + " velocity");
    require_finite(in, sh.plastic, name + " plastic state");
    require_finite(in, sh.C, name + " APIC matrix");
    require_finite(in, sh.a3e, name + " contact normal");
    for (std::size_t k = 0; k < sh.a3e.size(); ++k)
      if (!(sh.a3e[k].squaredNorm() > 0))
        in.fail(name + " contact particle " + std::to_string(k) + " has a zero normal column");
  }
  if (in.left() != 0) in.fail(std::to_string(in.left()) + " unexpected bytes after the shells");
}

}  // namespace

std::uint64_t fingerprint(const std::string& text) {
  std::uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  return h;
}

void write_checkpoint(const std::string& path, const Checkpoint& c) {
  CountingSink count;
  put_payload(count, c);
  write_stream_atomic(path, [&](CheckedFile& out) {
    FileSink s{out, {}};
    s.put(kMagic, 8);
    put<std::uint32_t>(s, sizeof(Real));
    put<std::uint64_t>(s, count.bytes);
    put_payload(s, c);
    const std::uint32_t crc = s.crc.value();
    out.write(&crc, sizeof crc);
    out.write(kEndMagic, 8);
  });
}

Checkpoint read_checkpoint(const std::string& path) {
  const std::string bytes = read_whole_file(path);
  auto damaged = [&](const std::string& what) { return CheckpointDamaged(path, what); };
  if (bytes.size() < 8 || std::memcmp(bytes.data(), kMagic, 8) != 0) {
    if (bytes.size() >= 8 && std::memcmp(bytes.data(), kMagic, 7) == 0)
      throw damaged("written in another checkpoint format (" + bytes.substr(0, 8) +
                    "); resume needs a checkpoint written by this version");
    throw damaged("not a shellmpm checkpoint (bad magic)");
  }
  if (bytes.size() < kHeaderBytes + kTrailerBytes)
    throw damaged("truncated: the header is incomplete");
  std::uint32_t real_size;
  std::uint64_t payload;
  std::memcpy(&real_size, bytes.data() + 8, 4);
  std::memcpy(&payload, bytes.data() + 12, 8);
  if (payload != bytes.size() - kHeaderBytes - kTrailerBytes)
    throw damaged("the file has " + std::to_string(bytes.size()) + " bytes, its header says " +
                  (payload > bytes.size()
                       ? std::string("more")
                       : std::to_string(payload + kHeaderBytes + kTrailerBytes)) +
                  " (truncated, extended or damaged)");
  const char* trailer = bytes.data() + kHeaderBytes + payload;
  if (std::memcmp(trailer + 4, kEndMagic, 8) != 0) throw damaged("missing end marker");
  std::uint32_t stored;
  std::memcpy(&stored, trailer, 4);
  const std::uint32_t actual = crc32(bytes.data(), kHeaderBytes + payload);
  if (stored != actual) {
    std::ostringstream os;
    os << "checksum mismatch (stored " << std::hex << stored << ", computed " << actual
       << "): the file was changed after it was written";
    throw damaged(os.str());
  }
  if (real_size != sizeof(Real))
    throw UserError(path, 0, "",
                    "checkpoint written by a build with " + std::to_string(real_size * 8) +
                        "-bit floats; this build uses " + std::to_string(sizeof(Real) * 8) +
                        " (SHELLMPM_DOUBLE): resume with the build that wrote it");
  Checkpoint c;
  Cursor in{bytes.data() + kHeaderBytes, trailer, path};
  parse_payload(in, c);
  return c;
}

void save_shells(const Solver& solver, Checkpoint& c) {
  c.shells.clear();
  for (const auto& sh : solver.shells()) {
    Checkpoint::ShellState st;
    st.x = sh->x;
    st.v = sh->v;
    st.plastic = sh->kl().plastic_state();
    if (const ShellContact* ct = solver.contact(c.shells.size())) {
      st.C = ct->C;
      st.a3e = ct->a3e;
      st.contact_state = ct->state;
    }
    c.shells.push_back(std::move(st));
  }
  c.shell_plastic_work = solver.shell_plastic_work();
  c.friction_work = solver.friction_work();
}

void restore_checkpoint(Solver& solver, Checkpoint&& c, const std::string& path) {
  auto refuse = [&](const std::string& what) {
    return UserError(path, 0, "", "checkpoint does not fit the scene: " + what);
  };
  const Scene& scene = solver.scene();
  const ParticleSet& p = c.particles;
  const std::size_t nmat = scene.materials.size();
  for (std::size_t k = 0; k < p.kind_material.size(); ++k)
    if (p.kind_material[k] >= nmat)
      throw refuse("particle kind " + std::to_string(k) + " has material index " +
                   std::to_string(p.kind_material[k]) + ", the scene has " + std::to_string(nmat) +
                   " materials");
  if (p.keep_plastic != solver.particles().keep_plastic)
    throw refuse(p.keep_plastic ? "it has plastic state the scene's materials do not use"
                                : "it has no plastic state, the scene's materials need one");
  // Where no run could have left anything: bulk particles are kept inside the domain, and
  // a shell farther out than the domain's own size from it has left it long ago.
  const Vec3d lo = scene.shot.domain_min, hi = scene.shot.domain_max;
  const auto where = [](const Vec3& x) {
    std::ostringstream os;
    os << "(" << x.x() << ", " << x.y() << ", " << x.z() << ")";
    return os.str();
  };
  const auto outside = [](const Vec3& x, const Vec3d& a, const Vec3d& b) {
    for (int k = 0; k < 3; ++k)
      if (!(double(x[k]) >= a[k] && double(x[k]) <= b[k])) return true;
    return false;
  };
  const double pad = scene.shot.dx;
  for (std::size_t i = 0; i < p.x.size(); ++i)
    if (outside(p.x[i], lo - Vec3d::Constant(pad), hi + Vec3d::Constant(pad)))
      throw CheckpointDamaged(path, "particle " + std::to_string(i) + " (id " +
                                        std::to_string(p.id[i]) + ") is at " + where(p.x[i]) +
                                        ", outside the scene's domain");
  for (std::size_t s = 0; s < c.shells.size(); ++s)
    for (std::size_t j = 0; j < c.shells[s].x.size(); ++j)
      if (outside(c.shells[s].x[j], lo - (hi - lo), hi + (hi - lo)))
        throw CheckpointDamaged(path, "shell " + std::to_string(s) + " point " + std::to_string(j) +
                                          " is at " + where(c.shells[s].x[j]) +
                                          ", far outside the scene's domain");
  const double expected = frame_time(c.frame, scene.shot.fps);
  if (!(std::abs(c.time - expected) <= 0.5 / scene.shot.fps))
    throw refuse("its time " + std::to_string(c.time) + " s is not that of frame " +
                 std::to_string(c.frame) + " (" + std::to_string(expected) + " s)");
  auto& shells = solver.shells();
  if (c.shells.size() != shells.size())
    throw refuse("it has " + std::to_string(c.shells.size()) + " shells, the scene " +
                 std::to_string(shells.size()));
  for (std::size_t i = 0; i < shells.size(); ++i) {
    const auto& st = c.shells[i];
    const std::string name = "shell '" + shells[i]->name() + "'";
    if (st.x.size() != shells[i]->size() ||
        st.plastic.size() != shells[i]->kl().plastic_state().size())
      throw refuse(name + " has another size (did its mesh file change?)");
    const ShellContact* ct = solver.contact(i);
    const std::size_t nC = ct ? ct->C.size() : 0, na = ct ? ct->a3e.size() : 0;
    if (st.C.size() != nC || st.a3e.size() != na) throw refuse(name + " has other contact data");
  }
  for (std::size_t i = 0; i < shells.size(); ++i) {
    shells[i]->x = c.shells[i].x;
    shells[i]->v = c.shells[i].v;
    shells[i]->kl().set_plastic_state(c.shells[i].plastic);
    if (ShellContact* ct = solver.contact(i)) {
      ct->C = c.shells[i].C;
      ct->a3e = c.shells[i].a3e;
      ct->state = c.shells[i].contact_state;
    }
  }
  solver.set_shell_plastic_work(c.shell_plastic_work);
  solver.set_friction_work(c.friction_work);
  solver.particles() = std::move(c.particles);
  solver.set_time(c.time);
}

std::vector<CheckpointFile> list_checkpoints(const std::string& dir, int max_frame,
                                             std::vector<std::string>* warnings) {
  namespace fs = std::filesystem;
  std::vector<CheckpointFile> found;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return found;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    constexpr std::size_t kPrefix = 11, kSuffix = 4;  // "checkpoint." and ".bin"
    if (name.size() <= kPrefix + kSuffix || name.compare(0, kPrefix, "checkpoint.") != 0 ||
        name.compare(name.size() - kSuffix, kSuffix, ".bin") != 0)
      continue;
    const std::string digits = name.substr(kPrefix, name.size() - kPrefix - kSuffix);
    if (!std::all_of(digits.begin(), digits.end(), [](char ch) { return ch >= '0' && ch <= '9'; }))
      continue;  // not one of ours ("checkpoint.old.bin")
    // Up to 9 digits always fit an int; more only with leading zeros.
    const auto nz = digits.find_first_not_of('0');
    const std::string significant = nz == std::string::npos ? "0" : digits.substr(nz);
    const long long f = significant.size() <= 9 ? std::stoll(significant) : -1;
    if (f < 1 || f > kMaxFrameNumber) {
      if (warnings)
        warnings->push_back("ignoring '" + e.path().string() + "': " + digits +
                            " is not a frame number (1 to " + std::to_string(kMaxFrameNumber) +
                            ")");
      continue;
    }
    if (f <= max_frame) found.push_back({e.path().string(), static_cast<int>(f)});
  }
  std::sort(found.begin(), found.end(), [](const CheckpointFile& a, const CheckpointFile& b) {
    return a.frame != b.frame ? a.frame > b.frame : a.path < b.path;
  });
  return found;
}

std::string latest_checkpoint(const std::string& dir, int max_frame) {
  const auto all = list_checkpoints(dir, max_frame);
  return all.empty() ? "" : all.front().path;
}

}  // namespace shellmpm
