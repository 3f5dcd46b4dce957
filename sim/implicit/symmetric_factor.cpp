#include "sim/implicit/symmetric_factor.h"

#include <dlfcn.h>
#include <dmumps_c.h>

#include <cmath>
#include <mutex>

namespace shellmpm {
namespace {

/// OpenBLAS (MUMPS's BLAS) starts one thread per core; the factor's sums must not depend
/// on that, nor compete with the solver's own threads. Looked up at run time: any BLAS
/// without the call is sequential already.
void hold_blas_to_one_thread() {
  static std::once_flag once;
  std::call_once(once, [] {
    using SetThreads = void (*)(int);
    if (void* f = dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))
      reinterpret_cast<SetThreads>(f)(1);
  });
}

constexpr int kUseCommWorld = -987654;  // MUMPS's sequential library: no MPI communicator

}  // namespace

struct SymmetricFactor::Impl {
  DMUMPS_STRUC_C id{};
  bool initialised = false, analysed = false, factored = false;
  std::vector<MUMPS_INT> irn, jcn;  // 1-based lower-triangle pattern of the analysis
  std::vector<double> a;
  std::vector<double> rhs;

  void call(int job) {
    id.job = job;
    dmumps_c(&id);
  }
};

SymmetricFactor::SymmetricFactor() : impl_(std::make_unique<Impl>()) {
  hold_blas_to_one_thread();
  DMUMPS_STRUC_C& id = impl_->id;
  id.comm_fortran = kUseCommWorld;
  id.par = 1;  // the host works
  id.sym = 1;  // symmetric, factorised without pivoting (see the header)
  impl_->call(-1);
  impl_->initialised = id.info[0] >= 0;
  // No output (ICNTL 1-4), AMD ordering (ICNTL 7 = 0).
  id.icntl[0] = -1;
  id.icntl[1] = -1;
  id.icntl[2] = -1;
  id.icntl[3] = 0;
  id.icntl[6] = 0;
}

SymmetricFactor::~SymmetricFactor() {
  if (impl_->initialised) impl_->call(-2);
}

bool SymmetricFactor::factorise(const SparseMatrixD& A) {
  Impl& m = *impl_;
  m.factored = false;
  if (!m.initialised || A.rows() != A.cols() || A.rows() == 0) return false;
  // The lower triangle, column by column (1-based), compared with the analysed pattern.
  std::vector<MUMPS_INT> irn, jcn;
  std::vector<double> a;
  irn.reserve(static_cast<std::size_t>(A.nonZeros()));
  jcn.reserve(irn.capacity());
  a.reserve(irn.capacity());
  for (Eigen::Index col = 0; col < A.outerSize(); ++col)
    for (SparseMatrixD::InnerIterator it(A, col); it; ++it) {
      if (it.row() < col) continue;
      if (!std::isfinite(it.value())) return false;
      irn.push_back(static_cast<MUMPS_INT>(it.row() + 1));
      jcn.push_back(static_cast<MUMPS_INT>(col + 1));
      a.push_back(it.value());
    }
  const bool same = m.analysed && m.id.n == A.rows() && irn == m.irn && jcn == m.jcn;
  m.a = std::move(a);
  if (!same) {
    m.irn = std::move(irn);
    m.jcn = std::move(jcn);
  }
  m.id.n = static_cast<MUMPS_INT>(A.rows());
  m.id.nnz = static_cast<MUMPS_INT8>(m.a.size());
  m.id.irn = m.irn.data();
  m.id.jcn = m.jcn.data();
  m.id.a = m.a.data();
  if (same) {
    ++reused_;
  } else {
    m.analysed = false;
    m.call(1);
    if (m.id.info[0] < 0) return false;
    m.analysed = true;
  }
  m.call(2);
  m.factored = m.id.info[0] >= 0;
  return m.factored;
}

void SymmetricFactor::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  Impl& m = *impl_;
  m.rhs.assign(b.data(), b.data() + b.size());
  m.id.rhs = m.rhs.data();
  m.id.nrhs = 1;
  m.id.lrhs = m.id.n;
  m.call(3);
  x = Eigen::Map<const Eigen::VectorXd>(m.rhs.data(), b.size());
}

long SymmetricFactor::factor_entries() const {
  // INFOG(29): entries in the factor, or minus millions of them when above 2^31.
  const long v = impl_->id.infog[28];
  return v >= 0 ? v : -v * 1000000L;
}

}  // namespace shellmpm
