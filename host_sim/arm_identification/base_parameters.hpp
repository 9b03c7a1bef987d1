// Identifiable (base) parameters of a stacked regressor: QR with column pivoting.
#pragma once

#include <Eigen/Dense>
#include <vector>

namespace jg::dyn {

struct BaseParameters {
  int rank = 0;                 ///< number of base parameters
  std::vector<int> independent; ///< columns kept by the pivoting, in pivot order
  std::vector<int> dependent;   ///< the others: linear combinations of the independent ones (or zero)
  double tolerance = 0.0;       ///< relative to the largest |R_kk|
};

/// `W` is the stacked regressor (rows: samples x joints); `scale` multiplies each column
/// first (the parameters' typical sizes, so that the pivoting compares torques, not units).
/// A column counts when its |R_kk| exceeds `relative_tolerance` x the largest.
[[nodiscard]] BaseParameters base_parameters(const Eigen::MatrixXd& W, const Eigen::VectorXd& scale,
                                             double relative_tolerance = 1e-6);

}  // namespace jg::dyn
