// bench/svd_bench: nanoseconds per call of the 3x3 SVD (sim/math/svd3.h) and of the
// per-particle constitutive calls (sim/mpm/constitutive.h), single thread. Inputs are
// typical MPM deformation gradients, F = R (I + 0.2 N) with N uniform in [-1, 1].
// Each figure is the best of several repetitions over the same array of matrices,
// so it is throughput on independent particles (what the solver's loops see). The batch
// calls in the simulation precision are timed at each instruction-set level the machine
// has (sim/mpm/stress_batch.h).
//
//   svd_bench [--n N] [--reps R]
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "sim/math/svd3.h"
#include "sim/mpm/constitutive.h"
#include "sim/mpm/stress_batch.h"

using namespace shellmpm;

namespace {

template <class T>
std::vector<Eigen::Matrix<T, 3, 3>> make_inputs(std::size_t n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> g;
  std::vector<Eigen::Matrix<T, 3, 3>> out(n);
  for (auto& F : out) {
    Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
    q.normalize();
    const Eigen::Matrix3d N = Eigen::Matrix3d::NullaryExpr([&]() { return u(rng); });
    F = (q.toRotationMatrix() * (Eigen::Matrix3d::Identity() + 0.2 * N)).cast<T>();
  }
  return out;
}

/// Best-of-reps nanoseconds per item of body(), which processes n items.
template <class Body>
double ns_per_item(std::size_t n, int reps, Body&& body) {
  double best = 1e300;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    body();
    const auto t1 = std::chrono::steady_clock::now();
    best = std::min(best, std::chrono::duration<double, std::nano>(t1 - t0).count() / double(n));
  }
  return best;
}

volatile double g_sink = 0;  // keeps results observable

constexpr bool kOtherIsFloat = !std::is_same_v<Real, float>;
constexpr const char* kRealName = std::is_same_v<Real, float> ? "float" : "double";
constexpr const char* kOtherName = kOtherIsFloat ? "float (library code)" : "double (library code)";

template <class T>
void bench_svd(const char* name, std::size_t n, int reps) {
  using M = Eigen::Matrix<T, 3, 3>;
  using V = Eigen::Matrix<T, 3, 1>;
  const auto A = make_inputs<T>(n);
  std::vector<M> U(n), W(n);
  std::vector<V> s(n);
  const double t_scalar = ns_per_item(n, reps, [&]() {
    for (std::size_t i = 0; i < n; ++i) svd3(A[i], U[i], s[i], W[i]);
  });
  g_sink = g_sink + s[n / 2](0);
  const double t_batch =
      ns_per_item(n, reps, [&]() { svd3_batch(A.data(), n, U.data(), s.data(), W.data()); });
  g_sink = g_sink + s[n / 2](0);
  const double t_polar = ns_per_item(n, reps, [&]() {
    for (std::size_t i = 0; i < n; ++i) U[i] = polar3(A[i]);
  });
  g_sink = g_sink + U[n / 2](0, 0);
  std::printf("%-7s svd3 %7.1f ns   svd3_batch (%2d lanes) %6.1f ns/matrix   polar3 %7.1f ns\n",
              name, t_scalar, svd3_batch_width<T>(), t_batch, t_polar);
}

template <class T>
void bench_models(const char* name, std::size_t n, int reps) {
  using Model = ConstitutiveModelT<T>;
  using M = typename Model::Mat3T;
  const auto F0 = make_inputs<T>(n);
  struct Entry {
    const char* label;
    MaterialDesc desc;
  };
  MaterialDesc fcr, nh, sand, snow;
  fcr.kind = MaterialKind::Elastic;
  nh.kind = MaterialKind::Elastic;
  nh.model = ElasticModel::NeoHookean;
  sand.kind = MaterialKind::Sand;
  snow.kind = MaterialKind::Snow;
  const Entry entries[] = {
      {"fixed corotated", fcr}, {"neo-Hookean", nh}, {"sand", sand}, {"snow", snow}};
  std::printf("%s, ns per particle (per call | batch call)\n", name);
  std::printf("  %-16s %18s %18s %26s\n", "model", "kirchhoff", "project", "project_and_kirchhoff");
  for (const Entry& e : entries) {
    const Model m = Model::from_desc(e.desc);
    std::vector<M> F = F0, tau(n);
    std::vector<T> plastic(n, m.initial_plastic());
    const double k1 = ns_per_item(n, reps, [&]() {
      for (std::size_t i = 0; i < n; ++i) tau[i] = m.kirchhoff(F0[i], plastic[i]);
    });
    const double kb = ns_per_item(
        n, reps, [&]() { m.kirchhoff_batch(F0.data(), plastic.data(), tau.data(), n); });
    // project changes F and plastic: restore them before each pass (cost included; it is
    // a copy of 40 bytes per particle).
    const double p1 = ns_per_item(n, reps, [&]() {
      for (std::size_t i = 0; i < n; ++i) {
        F[i] = F0[i];
        plastic[i] = m.initial_plastic();
        m.project(F[i], plastic[i]);
      }
    });
    const double pb = ns_per_item(n, reps, [&]() {
      std::copy(F0.begin(), F0.end(), F.begin());
      std::fill(plastic.begin(), plastic.end(), m.initial_plastic());
      m.project_batch(F.data(), plastic.data(), n);
    });
    const double c1 = ns_per_item(n, reps, [&]() {
      for (std::size_t i = 0; i < n; ++i) {
        F[i] = F0[i];
        plastic[i] = m.initial_plastic();
        tau[i] = m.project_and_kirchhoff(F[i], plastic[i]);
      }
    });
    const double cb = ns_per_item(n, reps, [&]() {
      std::copy(F0.begin(), F0.end(), F.begin());
      std::fill(plastic.begin(), plastic.end(), m.initial_plastic());
      m.project_and_kirchhoff_batch(F.data(), plastic.data(), tau.data(), n);
    });
    g_sink = g_sink + tau[n / 2](0, 0) + F[n / 2](0, 0);
    std::printf("  %-16s %8.1f | %7.1f %8.1f | %7.1f %12.1f | %7.1f\n", e.label, k1, kb, p1, pb, c1,
                cb);
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t n = 4096;
  int reps = 200;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--n" && i + 1 < argc) {
      n = std::strtoul(argv[++i], nullptr, 10);
    } else if (a == "--reps" && i + 1 < argc) {
      reps = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: svd_bench [--n N] [--reps R]\n");
      return 2;
    }
  }
  if (n == 0 || reps <= 0) {
    std::fprintf(stderr, "svd_bench: --n and --reps must be positive\n");
    return 2;
  }
  std::printf("svd_bench: %zu matrices F = R (I + 0.2 N), best of %d repetitions, 1 thread\n", n,
              reps);
  bench_svd<float>("float", n, reps);
  bench_svd<double>("double", n, reps);
  // The batch calls in the simulation precision run on the machine's widest vector unit
  // (sim/mpm/stress_batch.h): each level it has, widest first.
  for (int level = static_cast<int>(simd_supported()); level >= 0; --level) {
    set_simd_level(static_cast<SimdLevel>(level));
    const std::string label = std::string(kRealName) + ", " + simd_name(simd_level());
    bench_models<Real>(label.c_str(), n, reps);
  }
  bench_models<std::conditional_t<kOtherIsFloat, float, double>>(kOtherName, n, reps);
  return 0;
}
