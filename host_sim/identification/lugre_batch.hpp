// LuGre over a recorded velocity series for many candidate parameter sets at once: the
// inner loop runs across candidates (structure of arrays), so the compiler vectorises it.
// Same equations as the firmware's lugre_step (implicit Euler in the bristle torque,
// lugre.hpp); tests/identification checks the two agree to 1e-12 relative.
#pragma once

#include <cstddef>
#include <vector>

#include "jointguard/friction/lugre.hpp"

namespace jg::ident {

/// Candidates in physical units, one array per parameter (size = number of candidates).
struct LuGreBatch {
  std::vector<double> sigma0, sigma1, sigma2, tau_c, tau_s, w_s;
  [[nodiscard]] std::size_t size() const { return sigma0.size(); }
  void resize(std::size_t n);
  void set(std::size_t i, const LuGreParams<double>& p);
  [[nodiscard]] LuGreParams<double> get(std::size_t i) const;
};

/// Mean squared error of each candidate's LuGre prediction against `measured` friction
/// over the series (velocity w[k], sample time dt), starting from zero bristle state.
/// Writes one cost per candidate into `cost` (resized). Samples before `skip` warm the
/// state up but are not scored.
/// `observer_decay` a = exp(-K dT) > 0 passes each prediction through the first-order
/// observer's filter y_k = a y_{k-1} + (1 - a) tau_k before scoring, so that friction
/// "measured" by a momentum observer is compared with what the observer would show for
/// the candidate (the observer's lag is not mistaken for friction dynamics).
void lugre_batch_cost(const LuGreBatch& batch, const std::vector<double>& velocity,
                      const std::vector<double>& measured, double dt, std::size_t skip, std::vector<double>& cost,
                      double observer_decay = 0.0);

/// One candidate's prediction (double), for residuals and reports.
std::vector<double> lugre_predict(const LuGreParams<double>& p, const std::vector<double>& velocity, double dt,
                                  double observer_decay = 0.0);

}  // namespace jg::ident
