#include "arm_identification/base_parameters.hpp"

#include <cmath>

namespace jg::dyn {

BaseParameters base_parameters(const Eigen::MatrixXd& W, const Eigen::VectorXd& scale, double relative_tolerance) {
  BaseParameters out;
  out.tolerance = relative_tolerance;
  if (W.cols() == 0 || W.rows() == 0) return out;
  const Eigen::MatrixXd Ws = W * scale.asDiagonal();
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Ws);
  const Eigen::MatrixXd R = qr.matrixR().template triangularView<Eigen::Upper>();
  const Eigen::Index k_max = std::min(R.rows(), R.cols());
  const double r0 = k_max > 0 ? std::abs(R(0, 0)) : 0.0;
  const auto perm = qr.colsPermutation().indices();
  for (Eigen::Index k = 0; k < W.cols(); ++k) {
    const bool kept = k < k_max && r0 > 0.0 && std::abs(R(k, k)) > relative_tolerance * r0;
    (kept ? out.independent : out.dependent).push_back(static_cast<int>(perm(k)));
  }
  out.rank = static_cast<int>(out.independent.size());
  return out;
}

}  // namespace jg::dyn
