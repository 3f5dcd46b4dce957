#include "io/checkpoint.h"

#include <filesystem>
#include <fstream>
#include <regex>
#include <system_error>

#include "io/atomic_file.h"
#include "io/user_error.h"
#include "sim/solver/solver.h"

namespace shellmpm {
namespace {

constexpr char kMagic[8] = {'S', 'H', 'M', 'P', 'M', 'C', 'K', '2'};

template <class T>
void put(std::ofstream& f, const T& v) {
  f.write(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <class T>
void put_vec(std::ofstream& f, const std::vector<T>& v) {
  put<std::uint64_t>(f, v.size());
  f.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(T)));
}

struct Reader {
  std::ifstream f;
  std::string path;
  std::uint64_t file_size = 0;
  [[noreturn]] void fail(const std::string& what) {
    throw UserError(path, 0, "", "not a readable shellmpm checkpoint: " + what);
  }
  template <class T>
  T get() {
    T v;
    f.read(reinterpret_cast<char*>(&v), sizeof(T));
    if (!f) fail("file is truncated");
    return v;
  }
  template <class T>
  void get_vec(std::vector<T>& v, std::uint64_t expect) {
    const auto n = get<std::uint64_t>();
    if (n != expect) fail("inconsistent array length");
    if (n * sizeof(T) > file_size) fail("array longer than the file");
    v.resize(n);
    f.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T)));
    if (!f) fail("file is truncated");
  }
};

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
  write_file_atomic(path, [&](const std::string& tmp) {
    std::ofstream f(tmp, std::ios::binary);
    f.write(kMagic, 8);
    put<std::uint32_t>(f, sizeof(Real));
    put(f, c.scene_fingerprint);
    put<std::int32_t>(f, c.frame);
    put(f, c.time);
    const ParticleSet& p = c.particles;
    put<std::uint64_t>(f, p.size());
    put<std::uint32_t>(f, p.next_id);
    put<std::uint8_t>(f, p.keep_plastic ? 1 : 0);
    put_vec(f, p.x);
    put_vec(f, p.v);
    put_vec(f, p.C);
    put_vec(f, p.F);
    put_vec(f, p.volume);
    put_vec(f, p.material);
    put_vec(f, p.id);
    put_vec(f, p.plastic);
    put<std::uint64_t>(f, c.stats_json.size());
    f.write(c.stats_json.data(), static_cast<std::streamsize>(c.stats_json.size()));
    put<std::uint64_t>(f, c.shells.size());
    put(f, c.shell_plastic_work);
    put(f, c.friction_work);
    for (const auto& sh : c.shells) {
      put<std::uint64_t>(f, sh.x.size());
      put_vec(f, sh.x);
      put_vec(f, sh.v);
      put<std::uint64_t>(f, sh.plastic.size());
      put_vec(f, sh.plastic);
      put<std::uint64_t>(f, sh.C.size());
      put_vec(f, sh.C);
      put<std::uint64_t>(f, sh.a3e.size());
      put_vec(f, sh.a3e);
    }
    f.write(kMagic, 8);
    if (!f) throw std::system_error(errno, std::generic_category(), "writing " + tmp);
  });
}

Checkpoint read_checkpoint(const std::string& path) {
  Reader r;
  r.path = path;
  r.f.open(path, std::ios::binary);
  if (!r.f) throw UserError(path, 0, "", "cannot open checkpoint");
  std::error_code ec;
  r.file_size = std::filesystem::file_size(path, ec);
  char magic[8];
  r.f.read(magic, 8);
  if (!r.f || std::string(magic, 8) != std::string(kMagic, 8)) r.fail("bad magic");
  if (r.get<std::uint32_t>() != sizeof(Real))
    r.fail("written by a build with a different floating-point precision");
  Checkpoint c;
  c.scene_fingerprint = r.get<std::uint64_t>();
  c.frame = r.get<std::int32_t>();
  c.time = r.get<double>();
  const auto n = r.get<std::uint64_t>();
  ParticleSet& p = c.particles;
  p.next_id = r.get<std::uint32_t>();
  p.keep_plastic = r.get<std::uint8_t>() != 0;
  r.get_vec(p.x, n);
  r.get_vec(p.v, n);
  r.get_vec(p.C, n);
  r.get_vec(p.F, n);
  r.get_vec(p.volume, n);
  r.get_vec(p.material, n);
  r.get_vec(p.id, n);
  r.get_vec(p.plastic, p.keep_plastic ? n : 0);
  const auto len = r.get<std::uint64_t>();
  if (len > r.file_size) r.fail("statistics longer than the file");
  c.stats_json.resize(len);
  r.f.read(c.stats_json.data(), static_cast<std::streamsize>(len));
  const auto nshells = r.get<std::uint64_t>();
  if (nshells > 1000000) r.fail("bad shell count");
  c.shell_plastic_work = r.get<double>();
  c.friction_work = r.get<double>();
  c.shells.resize(nshells);
  for (auto& sh : c.shells) {
    const auto np = r.get<std::uint64_t>();
    r.get_vec(sh.x, np);
    r.get_vec(sh.v, np);
    const auto npl = r.get<std::uint64_t>();
    r.get_vec(sh.plastic, npl);
    const auto nC = r.get<std::uint64_t>();
    r.get_vec(sh.C, nC);
    const auto na = r.get<std::uint64_t>();
    r.get_vec(sh.a3e, na);
  }
  r.f.read(magic, 8);
  if (!r.f || std::string(magic, 8) != std::string(kMagic, 8)) r.fail("missing end marker");
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
    }
    c.shells.push_back(std::move(st));
  }
  c.shell_plastic_work = solver.shell_plastic_work();
  c.friction_work = solver.friction_work();
}

void restore_shells(Solver& solver, const Checkpoint& c) {
  auto& shells = solver.shells();
  if (c.shells.size() != shells.size())
    throw UserError("checkpoint", 0, "", "shell count differs from the scene");
  for (std::size_t i = 0; i < shells.size(); ++i) {
    if (c.shells[i].x.size() != shells[i]->size())
      throw UserError("checkpoint", 0, "", "shell '" + shells[i]->name() + "' has another size");
    shells[i]->x = c.shells[i].x;
    shells[i]->v = c.shells[i].v;
    shells[i]->kl().set_plastic_state(c.shells[i].plastic);
    if (ShellContact* ct = solver.contact(i)) {
      if (c.shells[i].C.size() != ct->C.size() || c.shells[i].a3e.size() != ct->a3e.size())
        throw UserError("checkpoint", 0, "", "shell '" + shells[i]->name() + "' has other contact data");
      ct->C = c.shells[i].C;
      ct->a3e = c.shells[i].a3e;
    }
  }
  solver.set_shell_plastic_work(c.shell_plastic_work);
  solver.set_friction_work(c.friction_work);
}

std::string latest_checkpoint(const std::string& dir, int max_frame) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return "";
  const std::regex re(R"(checkpoint\.(\d+)\.bin)");
  int best = -1;
  std::string best_path;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    std::smatch m;
    const std::string name = e.path().filename().string();
    if (!std::regex_match(name, m, re)) continue;
    const int f = std::stoi(m[1]);
    if (f <= max_frame && f > best) {
      best = f;
      best_path = e.path().string();
    }
  }
  return best_path;
}

}  // namespace shellmpm
