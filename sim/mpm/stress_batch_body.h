// The body of the per-ISA entry points of stress_batch.h, included once by each
// stress_batch_<isa>.cpp with SHELLMPM_STRESS_BATCH_ENTRY naming its function.
#include <variant>

#include "sim/mpm/constitutive.h"
#include "sim/mpm/stress_batch.h"

namespace shellmpm::stress_batch {

__attribute__((flatten)) void SHELLMPM_STRESS_BATCH_ENTRY(int op, const ConstitutiveModelT<Real>& m,
                                                          Mat3* F, const Real* plastic_in,
                                                          Real* plastic, Mat3* tau, std::size_t n) {
  using CM = ConstitutiveModelT<Real>;
  // No std::visit: its dispatch table takes the address of instantiations, which would
  // then be emitted here for this ISA.
  const auto run = [&](const auto& model) {
    if (op == 0)
      CM::batch_impl<false, true>(model, nullptr, F, nullptr, plastic_in, tau, n);
    else if (op == 1)
      CM::batch_impl<true, false>(model, F, nullptr, plastic, nullptr, nullptr, n);
    else
      CM::batch_impl<true, true>(model, F, nullptr, plastic, nullptr, tau, n);
  };
  if (const auto* a = std::get_if<FixedCorotatedT<Real>>(&m.model))
    run(*a);
  else if (const auto* b = std::get_if<DruckerPragerT<Real>>(&m.model))
    run(*b);
  else if (const auto* c = std::get_if<SnowT<Real>>(&m.model))
    run(*c);
}

}  // namespace shellmpm::stress_batch
