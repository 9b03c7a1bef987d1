#include "diagnosis/arm.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace jg::diag {
namespace {
using Eigen::MatrixXd;
using Eigen::VectorXd;

/// One arm-level candidate: shared columns per joint ([column][joint][sample]) and the
/// nonlinear setting it was built for.
struct ArmCandidate {
  std::string effect;
  std::vector<std::vector<std::vector<double>>> columns;
  double pickup_s = -1.0;  ///< step time of a payload picked up during the recording (< 0: throughout)
  int nonlinear_params = 0;
};

/// The stacked, noise-weighted problem: rows = (joint, sample) for the given samples.
struct Stack {
  std::vector<std::size_t> rows;
  std::size_t joints = 0;
  std::vector<double> weight;  ///< per joint
};

double soft_sign(double w, double band) { return std::fabs(w) >= band ? (w > 0.0 ? 1.0 : -1.0) : w / band; }

/// Nuisance columns of joint j (offset, Coulomb sign, viscous), zero on other joints' rows.
MatrixXd nuisance(const std::vector<JointSignals>& js, const Stack& st) {
  const auto nr = static_cast<Eigen::Index>(st.rows.size() * st.joints);
  MatrixXd X = MatrixXd::Zero(nr, static_cast<Eigen::Index>(3 * st.joints));
  for (std::size_t j = 0; j < st.joints; ++j) {
    const auto& s = js[j];
    double vmax = 0.0;
    for (const double w : s.dq) vmax = std::max(vmax, std::fabs(w));
    const double band = std::max(1e-4, 0.005 * vmax);
    for (std::size_t r = 0; r < st.rows.size(); ++r) {
      const auto row = static_cast<Eigen::Index>(j * st.rows.size() + r);
      const std::size_t k = st.rows[r];
      const auto c = static_cast<Eigen::Index>(3 * j);
      X(row, c) = st.weight[j];
      X(row, c + 1) = st.weight[j] * soft_sign(s.dq[k], band);
      X(row, c + 2) = st.weight[j] * s.dq[k];
    }
  }
  return X;
}

MatrixXd shared(const ArmCandidate& c, const Stack& st) {
  const auto nr = static_cast<Eigen::Index>(st.rows.size() * st.joints);
  MatrixXd X(nr, static_cast<Eigen::Index>(c.columns.size()));
  for (std::size_t p = 0; p < c.columns.size(); ++p) {
    for (std::size_t j = 0; j < st.joints; ++j) {
      for (std::size_t r = 0; r < st.rows.size(); ++r) {
        X(static_cast<Eigen::Index>(j * st.rows.size() + r), static_cast<Eigen::Index>(p)) =
            st.weight[j] * c.columns[p][j][st.rows[r]];
      }
    }
  }
  return X;
}

VectorXd target(const std::vector<JointSignals>& js, const Stack& st) {
  VectorXd y(static_cast<Eigen::Index>(st.rows.size() * st.joints));
  for (std::size_t j = 0; j < st.joints; ++j) {
    for (std::size_t r = 0; r < st.rows.size(); ++r) y(static_cast<Eigen::Index>(j * st.rows.size() + r)) = st.weight[j] * js[j].residual[st.rows[r]];
  }
  return y;
}

double bic(double rss, std::size_t n, int k) {
  const double nn = static_cast<double>(n);
  return nn * std::log(std::max(rss, 1e-300) / nn) + k * std::log(nn);
}

/// Per-joint RMS (unweighted) of the stacked residual e on the rows of `st`.
std::vector<double> joint_rms(const VectorXd& e, const Stack& st) {
  std::vector<double> out(st.joints, 0.0);
  const auto m = static_cast<Eigen::Index>(st.rows.size());
  for (std::size_t j = 0; j < st.joints; ++j) {
    out[j] = m > 0 ? e.segment(static_cast<Eigen::Index>(j) * m, m).norm() / std::sqrt(static_cast<double>(m)) / st.weight[j] : 0.0;
  }
  return out;
}

std::vector<ArmCandidate> payload_candidates(const std::vector<JointSignals>& js) {
  std::vector<ArmCandidate> out;
  const auto& t = js.front().t;
  const double t0 = t.front(), span = t.back() - t.front();
  // Carried throughout, or picked up during the recording (a step at pickup_s): the
  // columns are the model's sensitivities to the last link's mass and first moment.
  for (int i = 0; i <= 17; ++i) {
    ArmCandidate c;
    c.effect = "payload";
    if (i > 0) {
      c.pickup_s = t0 + span * (0.05 + 0.05 * i);
      c.nonlinear_params = 1;
    }
    c.columns.assign(4, std::vector<std::vector<double>>(js.size()));
    for (std::size_t p = 0; p < 4; ++p) {
      for (std::size_t j = 0; j < js.size(); ++j) {
        auto col = js[j].payload_columns[p];
        if (c.pickup_s >= 0.0) {
          for (std::size_t k = 0; k < col.size(); ++k) col[k] = t[k] >= c.pickup_s ? col[k] : 0.0;
        }
        c.columns[p][j] = std::move(col);
      }
    }
    out.push_back(std::move(c));
  }
  return out;
}
}  // namespace

ArmDiagnosis diagnose_arm(const std::vector<JointSignals>& js, const ArmDiagnosisOptions& o) {
  ArmDiagnosis d;
  d.explained.assign(js.size(), {});
  d.explained_rms.assign(js.size(), 0.0);
  for (std::size_t j = 0; j < js.size(); ++j) d.explained[j].assign(js[j].size(), 0.0);
  if (js.empty() || std::any_of(js.begin(), js.end(), [](const JointSignals& s) { return s.payload_columns.size() < 4; })) {
    d.notes.push_back("no rigid-body model: arm-level causes (payload) not fitted");
    return d;
  }
  const std::size_t n = js.front().size();
  if (n < 200 || std::any_of(js.begin(), js.end(), [n](const JointSignals& s) { return s.size() != n; })) {
    d.notes.push_back("too few samples for the arm-level fit");
    return d;
  }
  const auto held = heldout_mask(n, o.joint);
  Stack train, test;
  for (std::size_t k = 0; k < n; ++k) (held[k] ? test : train).rows.push_back(k);
  train.joints = test.joints = js.size();
  // Each joint weighted by its own error scale (residual RMS after its nuisance terms on
  // the training blocks): a joint with a large model error does not drown the others.
  train.weight.assign(js.size(), 1.0);
  {
    const MatrixXd N = nuisance(js, train);
    const VectorXd y = target(js, train);
    const VectorXd e = y - N * N.colPivHouseholderQr().solve(y);
    const auto r = joint_rms(e, train);
    for (std::size_t j = 0; j < js.size(); ++j) train.weight[j] = 1.0 / std::max(r[j], 1e-9);
  }
  test.weight = train.weight;
  const MatrixXd N_train = nuisance(js, train), N_test = nuisance(js, test);
  const VectorXd y_train = target(js, train), y_test = target(js, test);
  const VectorXd b0 = N_train.colPivHouseholderQr().solve(y_train);
  const double rss0 = (y_train - N_train * b0).squaredNorm();
  const auto k0 = static_cast<int>(N_train.cols());
  const std::size_t n_train = static_cast<std::size_t>(y_train.size());
  const double bic0 = bic(rss0, n_train, k0);
  const VectorXd e0_test = y_test - N_test * b0;
  const double held0 = e0_test.norm();
  const auto held0_joint = joint_rms(e0_test, test);

  const auto candidates = payload_candidates(js);
  const ArmCandidate* best = nullptr;
  double best_delta = 0.0;
  VectorXd best_b;
  for (const auto& c : candidates) {
    MatrixXd X(N_train.rows(), N_train.cols() + static_cast<Eigen::Index>(c.columns.size()));
    X << shared(c, train), N_train;
    const VectorXd b = X.colPivHouseholderQr().solve(y_train);
    const double delta = bic((y_train - X * b).squaredNorm(), n_train, k0 + static_cast<int>(c.columns.size()) + c.nonlinear_params) - bic0;
    if (delta < best_delta) {
      best_delta = delta;
      best = &c;
      best_b = b;
    }
  }
  if (best == nullptr || best_delta > -o.joint.min_delta_bic) {
    d.notes.push_back("payload: no evidence on the training blocks");
    return d;
  }
  const auto p = static_cast<Eigen::Index>(best->columns.size());
  MatrixXd Xt(N_test.rows(), N_test.cols() + p);
  Xt << shared(*best, test), N_test;
  const VectorXd e_test = y_test - Xt * best_b;
  const auto held_joint = joint_rms(e_test, test);
  std::ostringstream why;
  why.precision(3);
  const double mass = best_b(0);
  const Eigen::Vector3d first(best_b(1), best_b(2), best_b(3));
  const Eigen::Vector3d com = mass != 0.0 ? Eigen::Vector3d(first / mass) : Eigen::Vector3d::Zero();
  bool claim = true;
  if (e_test.norm() > held0 * (1.0 - o.joint.min_heldout_gain)) {
    why << "payload improved the training fit but not the held-out blocks: not claimed";
    claim = false;
  } else if (!(mass > o.min_mass_kg)) {
    why << "payload fit gives a mass of " << mass << " kg (must be positive): not claimed";
    claim = false;
  } else if (com.norm() > o.com_bound_m) {
    why << "payload fit puts its centre of mass " << com.norm() << " m from the last link's origin (bound "
        << o.com_bound_m << " m): not claimed";
    claim = false;
  } else {
    for (std::size_t j = 0; j < js.size() && claim; ++j) {
      // One cause explains every joint it loads: it must not make any joint worse.
      if (held_joint[j] > held0_joint[j] * (1.0 + o.joint.min_heldout_gain)) {
        why << "payload would worsen joint " << js[j].joint << "'s held-out fit (" << held0_joint[j] << " -> "
            << held_joint[j] << " N·m): not one cause, not claimed";
        claim = false;
      }
    }
  }
  if (!claim) {
    d.notes.push_back(why.str());
    return d;
  }
  // Final shared coefficients on all samples (nuisance alongside, not kept).
  Stack all;
  all.joints = js.size();
  all.weight = train.weight;
  for (std::size_t k = 0; k < n; ++k) all.rows.push_back(k);
  const MatrixXd Na = nuisance(js, all);
  MatrixXd Xa(Na.rows(), Na.cols() + p);
  Xa << shared(*best, all), Na;
  const VectorXd ya = target(js, all);
  const VectorXd ba = Xa.colPivHouseholderQr().solve(ya);
  Finding f;
  f.effect = "payload";
  f.delta_bic = -best_delta;
  f.confidence = 1.0 / (1.0 + std::exp(-(f.delta_bic - o.joint.min_delta_bic) / 10.0));
  const double m_all = ba(0);
  const Eigen::Vector3d c_all = m_all != 0.0 ? Eigen::Vector3d(Eigen::Vector3d(ba(1), ba(2), ba(3)) / m_all) : Eigen::Vector3d::Zero();
  f.params["mass_kg"] = m_all;
  f.params["com_x_m"] = c_all.x();
  f.params["com_y_m"] = c_all.y();
  f.params["com_z_m"] = c_all.z();
  if (best->pickup_s >= 0.0) f.params["picked_up_at_s"] = best->pickup_s;
  f.params["heldout_weighted_rms_before"] = held0 / std::sqrt(static_cast<double>(y_test.size()));
  f.params["heldout_weighted_rms_after"] = e_test.norm() / std::sqrt(static_cast<double>(y_test.size()));
  FittedEffect fe;
  fe.effect = "payload";
  if (best->pickup_s >= 0.0) fe.setting["picked_up_at_s"] = best->pickup_s;
  for (Eigen::Index i = 0; i < p; ++i) fe.coefficients.push_back(ba(i));
  std::ostringstream text;
  text.precision(3);
  text << "payload on the last link: " << m_all << " kg, centre of mass (" << c_all.x() << ", " << c_all.y() << ", "
       << c_all.z() << ") m in its frame";
  if (best->pickup_s >= 0.0) text << ", picked up at t = " << best->pickup_s << " s";
  text << "; torque it explains per joint (RMS):";
  for (std::size_t j = 0; j < js.size(); ++j) {
    double acc = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      double v = 0.0;
      for (Eigen::Index i = 0; i < p; ++i) v += ba(i) * best->columns[static_cast<std::size_t>(i)][j][k];
      d.explained[j][k] = v;
      acc += v * v;
    }
    d.explained_rms[j] = std::sqrt(acc / static_cast<double>(n));
    f.params["torque_rms_joint" + std::to_string(js[j].joint)] = d.explained_rms[j];
    text << ' ' << d.explained_rms[j];
  }
  text << " N·m";
  f.text = text.str();
  d.findings.push_back(f);
  d.model.push_back(fe);
  return d;
}

std::vector<JointSignals> without_arm_causes(const std::vector<JointSignals>& js, const ArmDiagnosis& arm) {
  std::vector<JointSignals> out = js;
  for (std::size_t j = 0; j < out.size(); ++j) {
    auto& s = out[j];
    s.arm_level_fitted = true;
    if (j >= arm.explained.size() || arm.explained[j].size() != s.size()) continue;
    for (std::size_t k = 0; k < s.size(); ++k) {
      s.tau_model[k] += arm.explained[j][k];
      if (s.load.size() == s.size()) s.load[k] += arm.explained[j][k];
      s.residual[k] -= arm.explained[j][k];
    }
  }
  return out;
}

}  // namespace jg::diag
