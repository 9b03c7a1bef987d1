#include "arm_identification/constrained_fit.hpp"

#include <cmath>

namespace jg::dyn {
namespace {

using Mat4 = Eigen::Matrix4d;

/// dJ/dp_k of the pseudo-inertia J = [[tr(I)/2 1 - I, h], [h^T, m]] (about the origin).
const std::vector<Mat4>& pseudo_basis() {
  static const std::vector<Mat4> basis = [] {
    std::vector<Mat4> b(kLinkParams, Mat4::Zero());
    b[0](3, 3) = 1.0;
    for (int a = 0; a < 3; ++a) b[static_cast<std::size_t>(1 + a)](a, 3) = b[static_cast<std::size_t>(1 + a)](3, a) = 1.0;
    for (int a = 0; a < 3; ++a) {  // I_xx, I_yy, I_zz
      for (int d = 0; d < 3; ++d) b[static_cast<std::size_t>(4 + a)](d, d) = d == a ? -0.5 : 0.5;
    }
    b[7](0, 1) = b[7](1, 0) = -1.0;  // I_xy
    b[8](0, 2) = b[8](2, 0) = -1.0;  // I_xz
    b[9](1, 2) = b[9](2, 1) = -1.0;  // I_yz
    return b;
  }();
  return basis;
}

Mat4 shifted_pseudo(const LinkParams& p, const LinkBounds& b) {
  Mat4 S = Mat4::Zero();
  const auto& B = pseudo_basis();
  for (int k = 0; k < kLinkParams; ++k) S += p(k) * B[static_cast<std::size_t>(k)];
  for (int a = 0; a < 3; ++a) S(a, a) -= b.min_second_moment;
  return S;
}

/// Barrier value of one link, or +inf outside; accumulates gradient and Hessian when asked.
double link_barrier(const LinkParams& p, const LinkBounds& b, Eigen::Ref<Eigen::VectorXd> g, Eigen::Ref<Eigen::MatrixXd> H,
                    bool derivatives) {
  const Mat4 S = shifted_pseudo(p, b);
  const Eigen::LLT<Mat4> llt(S);
  const double dm = p(0) - b.min_mass_kg;
  const Eigen::Vector3d h = p.segment<3>(1);
  const double R2 = b.com_radius_m * b.com_radius_m;
  const double gc = R2 * p(0) * p(0) - h.squaredNorm();
  if (llt.info() != Eigen::Success || !(dm > 0.0) || !(gc > 0.0)) return INFINITY;
  const Mat4 L = llt.matrixL();
  double logdet = 0.0;
  for (int a = 0; a < 4; ++a) {
    if (!(L(a, a) > 0.0)) return INFINITY;
    logdet += 2.0 * std::log(L(a, a));
  }
  const double value = -logdet - std::log(dm) - std::log(gc);
  if (!derivatives) return value;
  const Mat4 Si = llt.solve(Mat4::Identity());
  const auto& B = pseudo_basis();
  Mat4 SiB[kLinkParams];
  for (int k = 0; k < kLinkParams; ++k) SiB[k] = Si * B[static_cast<std::size_t>(k)];
  for (int k = 0; k < kLinkParams; ++k) {
    g(k) -= SiB[k].trace();
    for (int l = 0; l <= k; ++l) {
      const double v = (SiB[k] * SiB[l]).trace();
      H(k, l) += v;
      if (l != k) H(l, k) += v;
    }
  }
  g(0) -= 1.0 / dm;
  H(0, 0) += 1.0 / (dm * dm);
  Eigen::Matrix<double, 4, 1> dg;
  dg << 2.0 * R2 * p(0), -2.0 * h;
  g.head<4>() -= dg / gc;
  H.topLeftCorner<4, 4>() += dg * dg.transpose() / (gc * gc);
  Eigen::Matrix<double, 4, 1> d2;
  d2 << 2.0 * R2, -2.0, -2.0, -2.0;
  H.topLeftCorner<4, 4>().diagonal() -= d2 / gc;
  return value;
}

}  // namespace

bool strictly_feasible(const LinkParams& p, const LinkBounds& b) {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(kLinkParams);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(kLinkParams, kLinkParams);
  return std::isfinite(link_barrier(p, b, g, H, false));
}

BarrierResult constrained_minimize(const Eigen::MatrixXd& Q, const Eigen::VectorXd& c, const Eigen::VectorXd& start,
                                   const std::vector<bool>& free, const std::vector<LinkConstraint>& links,
                                   const std::vector<int>& positive) {
  const auto P = static_cast<int>(start.size());
  std::vector<int> fi;
  for (int k = 0; k < P; ++k) {
    if (free[static_cast<std::size_t>(k)]) fi.push_back(k);
  }
  const auto m = static_cast<Eigen::Index>(fi.size());
  const auto barrier = [&](const Eigen::VectorXd& x, Eigen::VectorXd* g, Eigen::MatrixXd* H) {
    double v = 0.0;
    Eigen::VectorXd gl = Eigen::VectorXd::Zero(kLinkParams);
    Eigen::MatrixXd Hl = Eigen::MatrixXd::Zero(kLinkParams, kLinkParams);
    for (const auto& L : links) {
      gl.setZero();
      Hl.setZero();
      v += link_barrier(x.segment<kLinkParams>(L.first), L.bounds, gl, Hl, g != nullptr);
      if (!std::isfinite(v)) return v;
      if (g) {
        g->segment<kLinkParams>(L.first) += gl;
        H->block<kLinkParams, kLinkParams>(L.first, L.first) += Hl;
      }
    }
    for (int k : positive) {
      if (!(x(k) > 0.0)) return static_cast<double>(INFINITY);
      v -= std::log(x(k));
      if (g) {
        (*g)(k) -= 1.0 / x(k);
        (*H)(k, k) += 1.0 / (x(k) * x(k));
      }
    }
    return v;
  };
  const auto objective = [&](const Eigen::VectorXd& x) { return 0.5 * x.dot(Q * x) - c.dot(x); };
  BarrierResult res;
  res.x = start;
  if (m == 0 || !std::isfinite(barrier(start, nullptr, nullptr))) return res;
  const double constraints = static_cast<double>(links.size() * 6 + positive.size());
  // Units: Q and c come from rows scaled to unit noise, so a gap of 1e-6 is negligible.
  const double gap = 1e-6;
  double t = 1e-3;
  Eigen::VectorXd x = start;
  for (int outer = 0; outer < 40; ++outer) {
    for (int it = 0; it < 100; ++it) {
      Eigen::VectorXd g = t * (Q * x - c);
      Eigen::MatrixXd H = t * Q;
      barrier(x, &g, &H);
      Eigen::VectorXd gf(m);
      Eigen::MatrixXd Hf(m, m);
      for (Eigen::Index a = 0; a < m; ++a) {
        gf(a) = g(fi[static_cast<std::size_t>(a)]);
        for (Eigen::Index b = 0; b < m; ++b) Hf(a, b) = H(fi[static_cast<std::size_t>(a)], fi[static_cast<std::size_t>(b)]);
      }
      const Eigen::VectorXd df = -Hf.ldlt().solve(gf);
      const double decrement = -gf.dot(df);
      if (!(decrement > 1e-10)) break;
      Eigen::VectorXd dx = Eigen::VectorXd::Zero(P);
      for (Eigen::Index a = 0; a < m; ++a) dx(fi[static_cast<std::size_t>(a)]) = df(a);
      const double phi0 = t * objective(x) + barrier(x, nullptr, nullptr);
      double alpha = 1.0;
      bool moved = false;
      for (int ls = 0; ls < 60; ++ls, alpha *= 0.5) {
        const Eigen::VectorXd xn = x + alpha * dx;
        const double b = barrier(xn, nullptr, nullptr);
        if (std::isfinite(b) && t * objective(xn) + b <= phi0 - 0.25 * alpha * decrement) {
          x = xn;
          moved = true;
          break;
        }
      }
      ++res.newton_steps;
      if (!moved) break;
    }
    if (constraints / t < gap) {
      res.converged = true;
      break;
    }
    t *= 10.0;
  }
  res.x = x;
  return res;
}

}  // namespace jg::dyn
