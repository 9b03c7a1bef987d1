#include "arm_identification/rigid_body_identification.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "arm_identification/base_parameters.hpp"
#include "arm_identification/constrained_fit.hpp"
#include "robot/torque_kind.hpp"

namespace jg::dyn {
namespace {

using Vec = Eigen::VectorXd;
using Mat = Eigen::MatrixXd;

sim::JointVector column(const std::vector<std::vector<double>>& s, std::size_t k) {
  sim::JointVector v(static_cast<Eigen::Index>(s.size()));
  for (std::size_t j = 0; j < s.size(); ++j) v(static_cast<Eigen::Index>(j)) = s[j][k];
  return v;
}

sim::ArmDynamics make_arm(const robot::RobotModel& m) {
  return sim::ArmDynamics(m.plant_links(), Eigen::Vector3d(m.gravity[0], m.gravity[1], m.gravity[2]));
}

/// Column layout of the joint problem: [links 10n | rotor n (motor torque only) | friction per joint].
struct Layout {
  int n = 0;
  bool rotor = false;
  int fric_per_joint = 3;
  [[nodiscard]] int link0() const { return 0; }
  [[nodiscard]] int rotor0() const { return kLinkParams * n; }
  [[nodiscard]] int fric0() const { return rotor0() + (rotor ? n : 0); }
  [[nodiscard]] int total() const { return fric0() + fric_per_joint * n; }
  [[nodiscard]] int rigid() const { return fric0(); }
};

void friction_columns(const Layout& L, bool asym, int j, double dq, double eps, Mat& A) {
  auto row = A.row(j);
  const int c = L.fric0() + L.fric_per_joint * j;
  const double t = std::tanh(dq / eps);
  if (L.fric_per_joint == 2) {  // symmetric, no offset (RigidBodyIdOptions::friction_offset false)
    row(c) = t;
    row(c + 1) = dq;
  } else if (L.fric_per_joint == 3 && asym) {
    // While moving, an offset and a direction-dependent Coulomb level are the same
    // column (|tanh| = 1), and slow rows are left out of the fit: so no offset here.
    row(c) = std::max(t, 0.0);
    row(c + 1) = std::min(t, 0.0);
    row(c + 2) = dq;
  } else {
    row(c) = t;
    row(c + 1) = dq;
    row(c + 2) = 1.0;
  }
}

FrictionFit friction_from(const Layout& L, bool asym, const Vec& x, int j, double eps) {
  FrictionFit f;
  f.eps = eps;
  const int c = L.fric0() + L.fric_per_joint * j;
  if (L.fric_per_joint == 2) {
    f.coulomb = f.coulomb_pos = f.coulomb_neg = x(c);
    f.viscous = x(c + 1);
  } else if (asym) {
    f.coulomb_pos = x(c);
    f.coulomb_neg = x(c + 1);
    f.coulomb = 0.5 * (f.coulomb_pos + f.coulomb_neg);
    f.viscous = x(c + 2);
    f.offset = 0.0;
  } else {
    f.coulomb = f.coulomb_pos = f.coulomb_neg = x(c);
    f.viscous = x(c + 1);
    f.offset = x(c + 2);
  }
  return f;
}

/// Per-joint normal equations of a sample set: H_j = sum a a^T, g_j = sum a tau, tt_j = sum tau^2.
struct Normal {
  std::vector<Mat> H;
  std::vector<Vec> g;
  std::vector<double> tt;
  long count = 0;
  void init(int n, int P) {
    H.assign(static_cast<std::size_t>(n), Mat::Zero(P, P));
    g.assign(static_cast<std::size_t>(n), Vec::Zero(P));
    tt.assign(static_cast<std::size_t>(n), 0.0);
  }
  [[nodiscard]] double sse(int j, const Vec& x) const {
    const auto u = static_cast<std::size_t>(j);
    return std::max(0.0, x.dot(H[u] * x) - 2.0 * x.dot(g[u]) + tt[u]);
  }
  [[nodiscard]] double rms(int j, const Vec& x) const {
    return count > 0 ? std::sqrt(sse(j, x) / static_cast<double>(count)) : 0.0;
  }
};

/// Minimises sum_j w_j^2 |A_j x - tau_j|^2 + sum_k lambda_k (x_k - x0_k)^2 over the free
/// entries, the others held at `x_fixed`.
Vec solve(const Normal& N, const std::vector<double>& w, const Vec& lambda, const Vec& x0, const std::vector<bool>& free,
          const Vec& x_fixed) {
  const auto P = static_cast<int>(x0.size());
  Mat H = Mat::Zero(P, P);
  Vec g = Vec::Zero(P);
  for (std::size_t j = 0; j < N.H.size(); ++j) {
    H += w[j] * w[j] * N.H[j];
    g += w[j] * w[j] * N.g[j];
  }
  std::vector<int> fi;
  for (int k = 0; k < P; ++k) {
    if (free[static_cast<std::size_t>(k)]) fi.push_back(k);
  }
  Vec x = x_fixed;
  if (fi.empty()) return x;
  const auto m = static_cast<Eigen::Index>(fi.size());
  Mat Hf(m, m);
  Vec gf(m);
  for (Eigen::Index a = 0; a < m; ++a) {
    double rhs = g(fi[static_cast<std::size_t>(a)]) + lambda(fi[static_cast<std::size_t>(a)]) * x0(fi[static_cast<std::size_t>(a)]);
    for (int k = 0; k < P; ++k) {
      if (!free[static_cast<std::size_t>(k)]) rhs -= H(fi[static_cast<std::size_t>(a)], k) * x_fixed(k);
    }
    gf(a) = rhs;
    for (Eigen::Index b = 0; b < m; ++b) Hf(a, b) = H(fi[static_cast<std::size_t>(a)], fi[static_cast<std::size_t>(b)]);
    Hf(a, a) += lambda(fi[static_cast<std::size_t>(a)]);
  }
  // Symmetric positive definite thanks to the prior term; LDLT is robust to poor scaling.
  const Vec xf = Hf.ldlt().solve(gf);
  for (Eigen::Index a = 0; a < m; ++a) x(fi[static_cast<std::size_t>(a)]) = xf(a);
  return x;
}

}  // namespace

double FrictionFit::torque(double dq) const {
  const double t = std::tanh(dq / eps);
  return coulomb_pos * std::max(t, 0.0) + coulomb_neg * std::min(t, 0.0) + viscous * dq + offset;
}

std::vector<bool> default_train_mask(std::size_t samples) {
  std::vector<bool> m(samples, true);
  for (std::size_t k = 0; k < samples; ++k) {
    const std::size_t block = k * 10 / std::max<std::size_t>(samples, 1);
    if (block == 1 || block == 4 || block == 7) m[k] = false;
  }
  return m;
}

std::vector<std::vector<double>> recording_torque(const io::Recording& rec, const robot::RobotModel& model,
                                                  bool* joint_sensor) {
  // The torque the recording's kind names (io::torque_columns): a joint torque sensor's
  // reading, a motor torque, or the currents times each drive's K_I.
  if (joint_sensor) *joint_sensor = rec.torque_kind == io::TorqueKind::tau_j;
  robot::check_torque_constant(model, rec.torque_kind);
  const auto& cols = io::torque_columns(rec);
  if (cols.empty()) throw std::invalid_argument("recording has no torque (tau_m<j>, tau_j<j>) or current (i<j>) columns");
  std::vector<std::vector<double>> tau = cols;
  if (rec.torque_kind == io::TorqueKind::current) {
    for (std::size_t j = 0; j < tau.size(); ++j) {
      for (double& v : tau[j]) v *= model.joints[j].link.torque_constant;
    }
  }
  return tau;
}

/// RigidBodyIdOptions::known_torque taken off the measured torque (shapes checked).
void subtract_known_torque(const std::vector<std::vector<double>>& known, std::vector<std::vector<double>>& measured) {
  if (known.empty()) return;
  if (known.size() != measured.size()) throw std::invalid_argument("known_torque has " + std::to_string(known.size()) + " joints, the recording " + std::to_string(measured.size()));
  for (std::size_t j = 0; j < known.size(); ++j) {
    if (known[j].size() != measured[j].size()) throw std::invalid_argument("known_torque of joint " + std::to_string(j + 1) + " has " + std::to_string(known[j].size()) + " samples, the recording " + std::to_string(measured[j].size()));
    for (std::size_t k = 0; k < known[j].size(); ++k) measured[j][k] -= known[j][k];
  }
}

std::vector<std::vector<double>> predict_torque(const robot::RobotModel& model, const std::vector<FrictionFit>& friction,
                                                const std::vector<std::vector<double>>& q,
                                                const std::vector<std::vector<double>>& dq,
                                                const std::vector<std::vector<double>>& ddq, bool joint_torque_sensor) {
  robot::RobotModel m = model;
  if (joint_torque_sensor) {
    for (auto& j : m.joints) j.link.rotor_inertia = 0.0;
  }
  const sim::ArmDynamics arm = make_arm(m);
  const std::size_t n = q.size(), S = n ? q[0].size() : 0;
  std::vector<std::vector<double>> out(n, std::vector<double>(S, 0.0));
  for (std::size_t k = 0; k < S; ++k) {
    const sim::JointVector tau = arm.inverse_dynamics(column(q, k), column(dq, k), column(ddq, k));
    for (std::size_t j = 0; j < n; ++j) {
      out[j][k] = tau(static_cast<Eigen::Index>(j)) + (j < friction.size() ? friction[j].torque(dq[j][k]) : 0.0);
    }
  }
  return out;
}

namespace {

// identify_rigid_body's stages, in the order it runs them. What one stage hands the next is
// a struct (the signals, the prior as parameters, the normal equations, the fit), so each
// stage reads as the step of the method it is.

/// The recording's checks (joints against the model, length, uniform sampling) and its step.
/// Uniform sampling is a precondition (recordings are made uniform upstream).
double checked_step(const io::Recording& rec, const robot::RobotModel& prior) {
  const std::size_t n = rec.joints(), S = rec.samples();
  if (n != prior.joints.size()) {
    throw std::invalid_argument("the recording has " + std::to_string(n) + " joints, the model " +
                                std::to_string(prior.joints.size()));
  }
  if (S < 200) throw std::invalid_argument("too few samples for rigid-body identification (" + std::to_string(S) + " < 200)");
  std::vector<double> steps(S - 1);
  for (std::size_t k = 1; k < S; ++k) steps[k - 1] = rec.t[k] - rec.t[k - 1];
  std::vector<double> sorted = steps;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  const double dt = sorted[sorted.size() / 2];
  for (std::size_t k = 0; k < steps.size(); ++k) {
    if (!(std::abs(steps[k] - dt) <= 0.01 * dt)) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "non-uniform time step at t = %.6f s (%.6f s against %.6f s): resample first",
                    rec.t[k], steps[k], dt);
      throw std::invalid_argument(buf);
    }
  }
  return dt;
}

/// Per joint: the smoothed velocity, the friction's tanh width and the speed below which a
/// row is left out of the fit.
struct Signals {
  std::vector<double> eps, slow;
  std::vector<std::vector<double>> dq_smooth;
};

/// The accelerations (a Gaussian derivative of dq, into res.acceleration and res.ddq) and
/// the Signals: eps 3x the velocity noise (the residual of the smoothing) unless given.
Signals accelerations(const io::Recording& rec, const RigidBodyIdOptions& opt, double dt, RigidBodyIdResult& res) {
  const std::size_t n = rec.joints(), S = rec.samples();
  res.acceleration = choose_sigma_detail(rec.dq, dt);
  if (opt.sigma_s > 0.0) {
    res.acceleration.sigma_s = opt.sigma_s;
    res.acceleration.joint_index = -1;
  }
  const double sigma = res.acceleration.sigma_s;
  res.ddq.resize(n);
  Signals sig;
  sig.eps.resize(n);
  sig.slow.assign(n, 0.0);
  sig.dq_smooth.resize(n);
  std::vector<double> motion(n, 0.0);
  for (std::size_t j = 0; j < n; ++j) {
    res.ddq[j] = smooth_derivative(rec.dq[j], dt, sigma);
    sig.dq_smooth[j] = smooth(rec.dq[j], dt, sigma);
    const std::vector<double>& dqs = sig.dq_smooth[j];
    double s = 0.0;
    for (std::size_t k = 0; k < S; ++k) {
      s += (rec.dq[j][k] - dqs[k]) * (rec.dq[j][k] - dqs[k]);
      motion[j] = std::max(motion[j], std::abs(dqs[k]));
    }
    const double noise = std::sqrt(s / static_cast<double>(S));
    sig.eps[j] = opt.friction_eps > 0.0 ? opt.friction_eps : std::max(3.0 * noise, 1e-3);
    sig.slow[j] = opt.slow_speed_rad_s >= 0.0 ? opt.slow_speed_rad_s : 3.0 * sig.eps[j];
  }
  if (*std::max_element(motion.begin(), motion.end()) < 1e-3) throw std::invalid_argument("no joint moves: nothing to identify");
  return sig;
}

/// The prior as parameters: its values x0, their scales (the prior's std is scale /
/// sqrt(prior_weight)), the regularisation weights lambda and the links' consistency bounds.
struct PriorParams {
  Vec x0, scale, lambda;
  std::vector<LinkBounds> bounds;
};

PriorParams prior_params(const robot::RobotModel& prior, const sim::ArmDynamics& arm, const Layout& L,
                         const RigidBodyIdOptions& opt, const std::vector<std::vector<double>>& measured, std::size_t S) {
  const std::size_t n = prior.joints.size();
  const int P = L.total();
  PriorParams pp;
  pp.x0 = Vec::Zero(P);
  pp.scale = Vec::Ones(P);
  pp.bounds.resize(n);
  Vec& x0 = pp.x0;
  Vec& scale = pp.scale;
  for (std::size_t i = 0; i < n; ++i) {
    const sim::PlantLink& l = arm.link(static_cast<int>(i));
    x0.segment<kLinkParams>(kLinkParams * static_cast<int>(i)) = link_params(l);
    const double r = std::max({prior.joints[i].reach_m, l.com.norm(), 0.05});
    const double ms = std::max(l.mass, 0.5);
    scale(kLinkParams * static_cast<int>(i)) = ms;
    scale.segment<3>(kLinkParams * static_cast<int>(i) + 1).setConstant(ms * r);
    scale.segment<6>(kLinkParams * static_cast<int>(i) + 4).setConstant(ms * r * r);
    if (L.rotor) {
      x0(L.rotor0() + static_cast<int>(i)) = l.rotor_inertia;
      scale(L.rotor0() + static_cast<int>(i)) = std::max(l.rotor_inertia, 0.01);
    }
    pp.bounds[i].com_radius_m = std::max(prior.joints[i].reach_m, l.com.norm()) + opt.com_margin_m;
    pp.bounds[i].min_mass_kg = std::max(1e-3, 0.05 * l.mass);
    pp.bounds[i].min_second_moment = 1e-7;
  }
  // Friction: practically unregularised (scale from the torque's spread).
  for (std::size_t j = 0; j < n; ++j) {
    double m = 0.0, v = 0.0;
    for (double t : measured[j]) m += t;
    m /= static_cast<double>(S);
    for (double t : measured[j]) v += (t - m) * (t - m);
    const double s = std::max(std::sqrt(v / static_cast<double>(S)), 1e-3) * 1e3;
    for (int c = 0; c < L.fric_per_joint; ++c) scale(L.fric0() + L.fric_per_joint * static_cast<int>(j) + c) = s;
  }
  pp.lambda = Vec::Zero(P);
  for (int c = 0; c < P; ++c) pp.lambda(c) = opt.prior_weight / (scale(c) * scale(c));
  return pp;
}

/// The data's per-joint normal equations: training and held-out samples, and of each the
/// rows of a moving joint. fit: the training rows the fit uses (a joint's row is left out
/// while it is slower than `slow`: there the joint may stick, and stiction is not a
/// function of the state). stack_rows: a thinned stack of training rows for the
/// base-parameter count.
struct Normals {
  Normal train, held, fit, held_moving;
  std::vector<long> fit_rows, held_moving_rows;
  std::vector<Eigen::RowVectorXd> stack_rows;
};

/// One pass over the data.
Normals accumulate(const io::Recording& rec, const sim::ArmDynamics& arm, const Layout& L, const RigidBodyIdOptions& opt,
                   const RigidBodyIdResult& res, const Signals& sig, const std::vector<bool>& train) {
  const std::size_t n = rec.joints(), S = rec.samples();
  const int P = L.total();
  Normals nm;
  for (Normal* N : {&nm.train, &nm.held, &nm.fit, &nm.held_moving}) N->init(L.n, P);
  nm.fit_rows.assign(n, 0);
  nm.held_moving_rows.assign(n, 0);
  const std::size_t thin = std::max<std::size_t>(1, S / 3000);
  Mat A(L.n, P);
  for (std::size_t k = 0; k < S; ++k) {
    A.setZero();
    const sim::JointVector q = column(rec.q, k), dq = column(rec.dq, k), ddq = column(res.ddq, k);
    A.leftCols(kLinkParams * L.n) = link_regressor(arm, q, dq, ddq);
    for (int j = 0; j < L.n; ++j) {
      if (L.rotor) A(j, L.rotor0() + j) = ddq(j);
      friction_columns(L, opt.asymmetric_coulomb, j, dq(j), sig.eps[static_cast<std::size_t>(j)], A);
    }
    Normal& N = train[k] ? nm.train : nm.held;
    ++N.count;
    for (int j = 0; j < L.n; ++j) {
      const auto u = static_cast<std::size_t>(j);
      const double t = res.measured[u][k];
      N.H[u].selfadjointView<Eigen::Upper>().rankUpdate(A.row(j).transpose());
      N.g[u] += A.row(j).transpose() * t;
      N.tt[u] += t * t;
      if (std::abs(sig.dq_smooth[u][k]) >= sig.slow[u]) {
        Normal& M = train[k] ? nm.fit : nm.held_moving;
        M.H[u].selfadjointView<Eigen::Upper>().rankUpdate(A.row(j).transpose());
        M.g[u] += A.row(j).transpose() * t;
        M.tt[u] += t * t;
        ++(train[k] ? nm.fit_rows : nm.held_moving_rows)[u];
      }
    }
    if (train[k] && k % thin == 0) {
      for (int j = 0; j < L.n; ++j) nm.stack_rows.push_back(A.row(j).head(L.rigid()));
    }
  }
  for (Normal* N : {&nm.train, &nm.held, &nm.fit, &nm.held_moving}) {
    for (auto& H : N->H) H = H.selfadjointView<Eigen::Upper>();
  }
  return nm;
}

/// Which parameters the fit estimates: friction always; links (all, or the last one's with
/// payload_only) and rotor inertias when identifying links.
struct FreeParams {
  std::vector<bool> free, link_free;
};

FreeParams free_params(const Layout& L, const RigidBodyIdOptions& opt, std::size_t n) {
  const int P = L.total();
  FreeParams fp{std::vector<bool>(static_cast<std::size_t>(P), false), std::vector<bool>(n, false)};
  for (int c = L.fric0(); c < P; ++c) fp.free[static_cast<std::size_t>(c)] = true;
  if (opt.identify_links) {
    for (std::size_t i = 0; i < n; ++i) fp.link_free[i] = !opt.payload_only || i + 1 == n;
    for (std::size_t i = 0; i < n; ++i) {
      for (int c = 0; c < kLinkParams; ++c) fp.free[static_cast<std::size_t>(kLinkParams * static_cast<int>(i) + c)] = fp.link_free[i];
    }
    if (L.rotor && !opt.payload_only) {
      for (int j = 0; j < L.n; ++j) fp.free[static_cast<std::size_t>(L.rotor0() + j)] = true;
    }
  }
  return fp;
}

/// Base parameters of the estimated rigid-body columns (res.free_parameters, res.base_parameters).
void count_base_parameters(const Layout& L, const FreeParams& fp, const Normals& nm, const Vec& scale,
                           RigidBodyIdResult& res) {
  std::vector<int> cols;
  for (int c = 0; c < L.rigid(); ++c) {
    if (fp.free[static_cast<std::size_t>(c)]) cols.push_back(c);
  }
  res.free_parameters = static_cast<int>(cols.size());
  if (cols.empty()) return;
  const std::vector<Eigen::RowVectorXd>& stack_rows = nm.stack_rows;
  Mat W(static_cast<Eigen::Index>(stack_rows.size()), static_cast<Eigen::Index>(cols.size()));
  Vec sc(static_cast<Eigen::Index>(cols.size()));
  for (std::size_t r = 0; r < stack_rows.size(); ++r) {
    for (std::size_t c = 0; c < cols.size(); ++c) W(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = stack_rows[r](cols[c]);
  }
  for (std::size_t c = 0; c < cols.size(); ++c) sc(static_cast<Eigen::Index>(c)) = scale(cols[c]);
  res.base_parameters = base_parameters(W, sc).rank;
}

/// A joint's residual std on the rows the fit uses.
double fit_std(const Normals& nm, int j, const Vec& v) {
  return std::max(std::sqrt(nm.fit.sse(j, v) / std::max(1.0, static_cast<double>(nm.fit_rows[static_cast<std::size_t>(j)]))), 1e-6);
}

/// The estimate as it is refined: x, the prior's rigid body with its friction fitted
/// (x_prior_fric, the baseline of the model selection), the joints' row weights w.
struct Fit {
  Vec x, x_prior_fric;
  std::vector<double> w;
};

/// Step 1: friction alone on the prior rigid body, x_prior_fric; its residual sets the
/// joints' weights (res.noise_weight, w).
void fit_friction_on_prior(const Layout& L, const PriorParams& pp, const Normals& nm, Fit& f, RigidBodyIdResult& res) {
  const int P = L.total();
  std::vector<bool> fric_only(static_cast<std::size_t>(P), false);
  for (int c = L.fric0(); c < P; ++c) fric_only[static_cast<std::size_t>(c)] = true;
  const std::vector<double> unit(static_cast<std::size_t>(L.n), 1.0);
  f.x_prior_fric = solve(nm.fit, unit, pp.lambda, pp.x0, fric_only, pp.x0);
  for (int j = 0; j < L.n; ++j) {
    res.noise_weight[static_cast<std::size_t>(j)] = fit_std(nm, j, f.x_prior_fric);
    f.w[static_cast<std::size_t>(j)] = 1.0 / res.noise_weight[static_cast<std::size_t>(j)];
  }
}

/// Does a joint stick? With the model fitted on moving rows, a joint whose slow rows fit
/// about as well as its moving ones (RMS within 2x) does not: its slow rows go back in (and
/// step 1 is redone on them). Returns the moving-rows fit.
Vec readmit_slow_rows(const Layout& L, const PriorParams& pp, const FreeParams& fp, Normals& nm, Signals& sig, Fit& f,
                      RigidBodyIdResult& res) {
  const Vec x = solve(nm.fit, f.w, pp.lambda, pp.x0, fp.free, pp.x0);
  bool changed = false;
  for (int j = 0; j < L.n; ++j) {
    const auto u = static_cast<std::size_t>(j);
    const double slow_rows = static_cast<double>(nm.train.count - nm.fit_rows[u]);
    if (!(slow_rows > 0.0)) continue;
    const double rms_slow = std::sqrt(std::max(0.0, nm.train.sse(j, x) - nm.fit.sse(j, x)) / slow_rows);
    if (rms_slow <= 2.0 * fit_std(nm, j, x)) {
      nm.fit.H[u] = nm.train.H[u];
      nm.fit.g[u] = nm.train.g[u];
      nm.fit.tt[u] = nm.train.tt[u];
      nm.fit_rows[u] = nm.train.count;
      sig.slow[u] = 0.0;
      changed = true;
    }
  }
  if (changed) fit_friction_on_prior(L, pp, nm, f, res);
  return x;
}

/// Step 3, when a link is infeasible: the constrained optimum of the same objective
/// (constrained_fit.hpp), starting from the prior's links; a link whose prior is itself not
/// consistent is held at the prior.
void constrain_links(const Layout& L, const PriorParams& pp, const FreeParams& fp, const Normals& nm, Fit& f,
                     RigidBodyIdResult& res) {
  const std::size_t n = fp.link_free.size();
  const int P = L.total();
  const Vec& x0 = pp.x0;
  std::vector<bool> fr = fp.free;
  Vec start = f.x;
  std::vector<LinkConstraint> cons;
  for (std::size_t i = 0; i < n; ++i) {
    if (!fp.link_free[i]) continue;
    const int c0 = kLinkParams * static_cast<int>(i);
    start.segment<kLinkParams>(c0) = x0.segment<kLinkParams>(c0);
    if (strictly_feasible(x0.segment<kLinkParams>(c0), pp.bounds[i])) {
      cons.push_back({c0, pp.bounds[i]});
    } else {
      for (int c = 0; c < kLinkParams; ++c) fr[static_cast<std::size_t>(c0 + c)] = false;
      res.notes.push_back("link " + std::to_string(i + 1) + ": the prior is not physically consistent (" +
                          check_link(x0.segment<kLinkParams>(c0), pp.bounds[i]).reason + "); held at the prior");
    }
  }
  std::vector<int> positive;
  if (L.rotor) {
    for (int j = 0; j < L.n; ++j) {
      const int c = L.rotor0() + j;
      if (!fr[static_cast<std::size_t>(c)]) continue;
      positive.push_back(c);
      start(c) = std::max(x0(c), 1e-3 * pp.scale(c));
    }
  }
  Mat Q = Mat::Zero(P, P);
  Vec cv = Vec::Zero(P);
  for (std::size_t j = 0; j < n; ++j) {
    Q += f.w[j] * f.w[j] * nm.fit.H[j];
    cv += f.w[j] * f.w[j] * nm.fit.g[j];
  }
  Q.diagonal() += pp.lambda;
  cv += pp.lambda.cwiseProduct(x0);
  const BarrierResult br = constrained_minimize(Q, cv, start, fr, cons, positive);
  f.x = br.x;
  char buf[200];
  std::snprintf(buf, sizeof buf,
                "unconstrained estimate not physically consistent (line-search step from the prior %.3f): "
                "constrained optimum by log-barrier Newton, %d steps%s",
                [&] {
                  double s = 1.0;
                  for (const auto& l : res.links) s = std::min(s, l.step);
                  return s;
                }(),
                br.newton_steps, br.converged ? "" : " (not converged)");
  res.notes.emplace_back(buf);
}

/// Step 2: the joint weighted, regularised estimate, reweighted once by its own residual.
/// Step 3: physical consistency. The line search from the (feasible) prior towards the
/// unconstrained estimate is reported per link (how far the data pull it outside); when any
/// link is infeasible, constrain_links.
void fit_links(const Layout& L, const PriorParams& pp, const FreeParams& fp, const Normals& nm, Fit& f,
               RigidBodyIdResult& res) {
  const std::size_t n = fp.link_free.size();
  for (int pass = 0; pass < 2; ++pass) {
    f.x = solve(nm.fit, f.w, pp.lambda, pp.x0, fp.free, pp.x0);
    for (int j = 0; j < L.n; ++j) {
      const double s = fit_std(nm, j, f.x);
      res.noise_weight[static_cast<std::size_t>(j)] = s;
      f.w[static_cast<std::size_t>(j)] = 1.0 / s;
    }
  }
  res.links.resize(n);
  bool feasible = true;
  for (std::size_t i = 0; i < n; ++i) {
    if (!fp.link_free[i]) continue;
    const int c0 = kLinkParams * static_cast<int>(i);
    const LinkParams p0 = pp.x0.segment<kLinkParams>(c0), pe = f.x.segment<kLinkParams>(c0);
    res.links[i].step = check_link(pe, pp.bounds[i]).ok ? 1.0 : feasible_step(p0, pe, pp.bounds[i]);
    feasible = feasible && res.links[i].step == 1.0;
  }
  if (L.rotor) {
    for (int j = 0; j < L.n; ++j) feasible = feasible && !(fp.free[static_cast<std::size_t>(L.rotor0() + j)] && f.x(L.rotor0() + j) < 0.0);
  }
  if (!feasible) constrain_links(L, pp, fp, nm, f, res);
}

/// Model selection on the held-out blocks: the identified rigid body is kept only when it
/// predicts them better than the prior with its friction re-fitted (mean of the per-joint
/// MSE ratios <= 0.98); otherwise the data did not support the change (a poorly exciting
/// motion, or effects the model lacks) and the prior's links are kept.
void select_on_heldout(const Layout& L, const Normals& nm, Fit& f, RigidBodyIdResult& res) {
  double ratio = 0.0;
  for (int j = 0; j < L.n; ++j) {
    const double before = nm.held.sse(j, f.x_prior_fric), after = nm.held.sse(j, f.x);
    ratio += before > 0.0 ? after / before : 1.0;
  }
  res.heldout_mse_ratio = ratio / L.n;
  res.accepted = res.heldout_mse_ratio <= 0.98;
  if (!res.accepted) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "the identified rigid body does not predict the held-out blocks better than the prior (MSE ratio %.3f > 0.98): prior's links kept",
                  res.heldout_mse_ratio);
    res.notes.emplace_back(buf);
    f.x = f.x_prior_fric;
  }
}

/// The results: per link its report and the model's link written from x; per joint the friction.
void write_model(const robot::RobotModel& prior, const sim::ArmDynamics& arm, const Layout& L, const RigidBodyIdOptions& opt,
                 const PriorParams& pp, const Signals& sig, const Vec& x, RigidBodyIdResult& res) {
  const std::size_t n = prior.joints.size();
  res.model = prior;
  res.feasibility_step = 1.0;
  for (std::size_t i = 0; i < n; ++i) {
    const int c0 = kLinkParams * static_cast<int>(i);
    LinkReport& lr = res.links[i];
    lr.before = pp.x0.segment<kLinkParams>(c0);
    lr.after = x.segment<kLinkParams>(c0);
    lr.com_bound_m = pp.bounds[i].com_radius_m;
    lr.consistency = check_link(lr.after, pp.bounds[i]);
    lr.rotor_before = prior.joints[i].link.rotor_inertia;
    lr.rotor_after = L.rotor ? x(L.rotor0() + static_cast<int>(i)) : lr.rotor_before;
    res.feasibility_step = std::min(res.feasibility_step, lr.step);
    const sim::PlantLink pl = with_params(arm.link(static_cast<int>(i)), lr.after);
    auto& d = res.model.joints[i].link;
    d.mass = pl.mass;
    for (int a = 0; a < 3; ++a) d.com[a] = pl.com(a);
    const Eigen::Matrix3d& Ic = pl.inertia_com;
    const double I6[6] = {Ic(0, 0), Ic(1, 1), Ic(2, 2), Ic(0, 1), Ic(0, 2), Ic(1, 2)};
    for (int a = 0; a < 6; ++a) d.inertia_com[a] = I6[a];
    if (L.rotor) d.rotor_inertia = lr.rotor_after;
  }
  for (std::size_t j = 0; j < n; ++j) res.friction.push_back(friction_from(L, opt.asymmetric_coulomb, x, static_cast<int>(j), sig.eps[j]));
}

/// Payload: the change of the last link against the prior, claimed only when plausible.
void estimate_payload(const RigidBodyIdOptions& opt, const PriorParams& pp, RigidBodyIdResult& res) {
  const LinkReport& last = res.links.back();
  const LinkParams dp = last.after - last.before;
  PayloadEstimate& pe = res.payload;
  pe.mass = dp(0);
  if (std::abs(dp(0)) > 1e-9) {
    pe.com = dp.segment<3>(1) / dp(0);
    pe.inertia_com = inertia_com(dp);
  }
  const double bound = pp.bounds.back().com_radius_m;
  if (!opt.identify_links) {
    pe.reason = "links not identified";
  } else if (!res.accepted) {
    pe.reason = "identified links not kept (no held-out improvement)";
  } else if (std::abs(pe.mass) < 0.01) {
    pe.reason = "no payload: the last link's mass changed by less than 10 g";
  } else if (!(pe.mass >= 0.0)) {
    pe.reason = "negative mass change of the last link";
  } else if (!(pe.com.norm() <= bound)) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "CoM %.3f m from the last link's origin (bound %.3f m)", pe.com.norm(), bound);
    pe.reason = buf;
  } else {
    pe.claimed = true;
  }
}

/// Figures: RMS from the normal equations (exact sums of squares), whole file and held out,
/// of the prior rigid body, the prior with friction and the identified model.
void residual_figures(const Layout& L, const PriorParams& pp, const Normals& nm, const Signals& sig, const Fit& f,
                      RigidBodyIdResult& res) {
  const auto n = static_cast<std::size_t>(L.n);
  const int P = L.total();
  res.rms_prior_rigid.resize(n);
  res.rms_before.resize(n);
  res.rms_after.resize(n);
  res.heldout_rms_prior_rigid.resize(n);
  res.heldout_rms_prior.resize(n);
  res.heldout_rms_after.resize(n);
  Vec x_prior_rigid = pp.x0;
  x_prior_rigid.segment(L.fric0(), P - L.fric0()).setZero();
  for (int j = 0; j < L.n; ++j) {
    const auto u = static_cast<std::size_t>(j);
    const auto whole = [&](const Vec& v) {
      return std::sqrt((nm.train.sse(j, v) + nm.held.sse(j, v)) / static_cast<double>(nm.train.count + nm.held.count));
    };
    res.rms_prior_rigid[u] = whole(x_prior_rigid);
    res.rms_before[u] = whole(f.x_prior_fric);
    res.rms_after[u] = whole(f.x);
    res.heldout_rms_prior_rigid[u] = nm.held.rms(j, x_prior_rigid);
    res.heldout_rms_prior[u] = nm.held.rms(j, f.x_prior_fric);
    res.heldout_rms_after[u] = nm.held.rms(j, f.x);
    const double hm = std::max(1.0, static_cast<double>(nm.held_moving_rows[u]));
    res.heldout_moving_rms_prior.push_back(std::sqrt(nm.held_moving.sse(j, f.x_prior_fric) / hm));
    res.heldout_moving_rms_after.push_back(std::sqrt(nm.held_moving.sse(j, f.x) / hm));
    res.slow_speed_rad_s.push_back(sig.slow[u]);
  }
}

}  // namespace

RigidBodyIdResult identify_rigid_body(const io::Recording& rec, const robot::RobotModel& prior,
                                      const RigidBodyIdOptions& opt) {
  RigidBodyIdResult res;
  const std::size_t n = rec.joints(), S = rec.samples();
  const double dt = checked_step(rec, prior);
  bool tau_j_columns = false;
  res.measured = recording_torque(rec, prior, &tau_j_columns);
  subtract_known_torque(opt.known_torque, res.measured);
  const bool sensor = opt.joint_torque_sensor || tau_j_columns;
  if (tau_j_columns && !opt.joint_torque_sensor) res.notes.push_back("tau_j<j> columns: joint-torque-sensor data, no rotor inertia");
  Signals sig = accelerations(rec, opt, dt, res);

  const std::vector<bool> train = opt.train_mask.empty() ? default_train_mask(S) : opt.train_mask;
  if (train.size() != S) throw std::invalid_argument("train_mask size differs from the sample count");

  Layout L;
  L.n = static_cast<int>(n);
  L.rotor = !sensor;
  L.fric_per_joint = opt.friction_offset || opt.asymmetric_coulomb ? 3 : 2;
  const robot::RobotModel geometry = prior;
  const sim::ArmDynamics arm = make_arm(geometry);
  const PriorParams pp = prior_params(prior, arm, L, opt, res.measured, S);

  Normals nm = accumulate(rec, arm, L, opt, res, sig, train);
  res.train_samples = static_cast<int>(nm.train.count);
  res.heldout_samples = static_cast<int>(nm.held.count);
  if (nm.train.count < 100) throw std::invalid_argument("too few training samples");

  const FreeParams fp = free_params(L, opt, n);
  count_base_parameters(L, fp, nm, pp.scale, res);

  Fit f;
  f.w.resize(n);
  res.noise_weight.resize(n);
  fit_friction_on_prior(L, pp, nm, f, res);
  f.x = f.x_prior_fric;
  if (opt.identify_links && opt.slow_speed_rad_s < 0.0) f.x = readmit_slow_rows(L, pp, fp, nm, sig, f, res);
  if (opt.identify_links) {
    fit_links(L, pp, fp, nm, f, res);
  } else {
    res.links.resize(n);
  }
  if (opt.identify_links && nm.held.count > 0) select_on_heldout(L, nm, f, res);

  write_model(prior, arm, L, opt, pp, sig, f.x, res);
  estimate_payload(opt, pp, res);
  residual_figures(L, pp, nm, sig, f, res);
  res.predicted = predict_torque(res.model, res.friction, rec.q, rec.dq, res.ddq, sensor);
  char buf[200];
  std::snprintf(buf, sizeof buf, "acceleration: Gaussian derivative of dq, sigma = %.1f ms (velocity band up to %.2f Hz)",
                res.acceleration.sigma_s * 1e3, res.acceleration.cutoff_hz);
  res.notes.emplace_back(buf);
  return res;
}

}  // namespace jg::dyn
