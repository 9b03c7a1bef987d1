#include "diagnosis/pairing.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "dynamics/acceleration.hpp"
#include "dynamics/sensitivity.hpp"
#include "identification/lugre_batch.hpp"

namespace jg::diag {
namespace {

/// The rows joint j's samples were resampled from (io::Recording::rows_t), when there are.
void copy_rows(const io::Recording& real, std::size_t j, JointSignals& s) {
  if (real.rows_t.empty() || j >= real.rows_q.size() || j >= real.rows_dq.size()) return;
  s.rows_t = real.rows_t;
  s.rows_q = real.rows_q[j];
  s.rows_dq = real.rows_dq[j];
}

double uniform_dt(const io::Recording& r, const char* which) {
  const std::size_t n = r.samples();
  if (n < 3) throw std::invalid_argument(std::string(which) + " recording has fewer than 3 samples");
  const double dt = (r.t.back() - r.t.front()) / static_cast<double>(n - 1);
  for (std::size_t k = 1; k < n; ++k) {
    const double step = r.t[k] - r.t[k - 1];
    if (step > 1.5 * dt || step < 0.5 * dt) {
      throw std::invalid_argument(std::string(which) + " recording has a gap or irregular step at t = " +
                                  std::to_string(r.t[k - 1]) + " s (step " + std::to_string(step) +
                                  " s, mean " + std::to_string(dt) + " s): resample it to a uniform rate first");
    }
  }
  return dt;
}

std::vector<double> torque_of(const io::Recording& r, std::size_t j, const ModelContext& m, const char* which) {
  if (r.torque_kind != io::TorqueKind::current) {
    const auto& tau = io::torque_columns(r);
    if (j < tau.size()) return tau[j];
  }
  if (!r.current.empty() && j < m.torque_constant.size()) {
    std::vector<double> t(r.current[j]);
    for (auto& v : t) v *= m.torque_constant[j];
    return t;
  }
  throw std::invalid_argument(std::string(which) + " recording: joint " + std::to_string(r.joint_ids[j]) +
                              " has no torque column and the model gives no torque constant for its currents");
}

double interp(const std::vector<double>& t, const std::vector<double>& x, double at, std::size_t& hint) {
  while (hint + 1 < t.size() && t[hint + 1] < at) ++hint;
  if (hint + 1 >= t.size()) return x.back();
  const double a = (at - t[hint]) / (t[hint + 1] - t[hint]);
  return x[hint] + std::clamp(a, 0.0, 1.0) * (x[hint + 1] - x[hint]);
}

sim::JointVector column_at(const std::vector<std::vector<double>>& sig, std::size_t k) {
  sim::JointVector v(static_cast<Eigen::Index>(sig.size()));
  for (std::size_t j = 0; j < sig.size(); ++j) v(static_cast<Eigen::Index>(j)) = sig[j][k];
  return v;
}

/// Motor-side position (dq integrated) minus link position, both from their first sample.
std::vector<double> deflection_of(const io::Recording& r, std::size_t j) {
  const std::size_t n = r.samples();
  std::vector<double> d(n, 0.0);
  double theta = 0.0;
  for (std::size_t k = 1; k < n; ++k) {
    theta += r.dq[j][k] * (r.t[k] - r.t[k - 1]);
    d[k] = theta - (r.q[j][k] - r.q[j][0]);
  }
  return d;
}

/// The acceleration the model's torque is computed with: a zero-phase Gaussian derivative
/// of the velocity whose width comes from the data (dynamics/acceleration.hpp: where the
/// velocity spectrum meets its noise floor), unless the context fixes it (0: the +/-10 ms
/// Savitzky-Golay slope).
double acceleration_sigma(const std::vector<std::vector<double>>& dq, double dt, const ModelContext& m) {
  return m.acceleration_sigma_s >= 0.0 ? m.acceleration_sigma_s : dyn::choose_sigma(dq, dt);
}
std::vector<double> acceleration(const std::vector<double>& dq, double dt, double sigma_s) {
  return sigma_s > 0.0 ? dyn::smooth_derivative(dq, dt, sigma_s) : derivative(dq, dt);
}

/// Fills the model-dependent signals: ddq, rigid-body load, payload columns, mismatch.
void add_model_terms(std::vector<JointSignals>& out, const io::Recording& real, const ModelContext& m) {
  const std::size_t n = real.samples();
  const std::size_t nj = real.joints();
  std::vector<std::vector<double>> ddq(nj);
  const double sigma = out.empty() ? 0.0 : acceleration_sigma(real.dq, out.front().dt, m);
  for (std::size_t j = 0; j < nj; ++j) {
    ddq[j] = acceleration(real.dq[j], out[j].dt, sigma);
    out[j].acceleration_sigma_s = sigma;
    out[j].ddq = ddq[j];
    const auto dq_link = derivative(real.q[j], out[j].dt);
    out[j].velocity_mismatch.resize(n);
    for (std::size_t k = 0; k < n; ++k) out[j].velocity_mismatch[k] = real.dq[j][k] - dq_link[k];
    out[j].deflection = deflection_of(real, j);
    if (j < m.friction.size()) out[j].friction = m.friction[j];
  }
  if (m.arm == nullptr || m.arm->joints() != static_cast<int>(nj)) return;
  const int last = m.arm->joints() - 1;
  for (auto& s : out) {
    s.load.resize(n);
    s.payload_columns.assign(4, std::vector<double>(n, 0.0));
  }
  // d tau / d (m, m c) of the last link, its rotational inertia about the link origin held
  // fixed: the payload's columns (exact: the dynamics are linear in those parameters).
  for (std::size_t k = 0; k < n; ++k) {
    sim::JointVector tau0;
    const auto cols = sim::mass_first_moment_sensitivity(*m.arm, last, column_at(real.q, k), column_at(real.dq, k),
                                                         column_at(ddq, k), &tau0);
    for (std::size_t j = 0; j < nj; ++j) {
      out[j].load[k] = tau0(static_cast<Eigen::Index>(j));
      for (std::size_t p = 0; p < 4; ++p) out[j].payload_columns[p][k] = cols[p](static_cast<Eigen::Index>(j));
    }
  }
}

}  // namespace

std::vector<JointSignals> signals_from_pair(const io::Recording& real, const io::Recording& simulated,
                                            const ModelContext& model) {
  if (real.joint_ids != simulated.joint_ids) {
    throw std::invalid_argument("real and simulated recordings have different joints (" +
                                std::to_string(real.joints()) + " vs " + std::to_string(simulated.joints()) + ")");
  }
  const double dt = uniform_dt(real, "real");
  if (simulated.t.front() > real.t.front() + dt || simulated.t.back() < real.t.back() - dt) {
    throw std::invalid_argument("the simulated recording does not cover the real one's time span [" +
                                std::to_string(real.t.front()) + ", " + std::to_string(real.t.back()) + "] s");
  }
  std::vector<JointSignals> out(real.joints());
  for (std::size_t j = 0; j < real.joints(); ++j) {
    JointSignals& s = out[j];
    s.joint = real.joint_ids[j];
    s.dt = dt;
    s.t = real.t;
    s.q = real.q[j];
    s.dq = real.dq[j];
    copy_rows(real, j, s);
    s.tau_real = torque_of(real, j, model, "real");
    const auto sim_tau = torque_of(simulated, j, model, "simulated");
    s.tau_model.resize(s.t.size());
    std::size_t hint = 0;
    for (std::size_t k = 0; k < s.t.size(); ++k) s.tau_model[k] = interp(simulated.t, sim_tau, s.t[k], hint);
  }
  add_model_terms(out, real, model);
  // The deflection the simulation already has (an elastic model) is not missing.
  for (std::size_t j = 0; j < real.joints(); ++j) {
    const auto d_sim = deflection_of(simulated, j);
    std::size_t hint = 0;
    for (std::size_t k = 0; k < real.samples(); ++k) out[j].deflection[k] -= interp(simulated.t, d_sim, real.t[k], hint);
  }
  // With a model, correct the simulated torque for the difference between the two runs'
  // motions (the same reference, tracked slightly differently): otherwise that
  // difference, not missing physics, would dominate near reversals and accelerations.
  if (model.arm != nullptr && model.arm->joints() == static_cast<int>(real.joints()) && !out.empty() &&
      !out[0].load.empty()) {
    const std::size_t nj = real.joints();
    std::vector<std::vector<double>> q_s(nj), dq_s(nj), ddq_s(nj);
    for (std::size_t j = 0; j < nj; ++j) {
      std::size_t h1 = 0, h2 = 0;
      q_s[j].resize(real.samples());
      dq_s[j].resize(real.samples());
      for (std::size_t k = 0; k < real.samples(); ++k) {
        q_s[j][k] = interp(simulated.t, simulated.q[j], real.t[k], h1);
        dq_s[j][k] = interp(simulated.t, simulated.dq[j], real.t[k], h2);
      }
      ddq_s[j] = acceleration(dq_s[j], dt, out[j].acceleration_sigma_s);
    }
    for (std::size_t k = 0; k < real.samples(); ++k) {
      const auto tau_sim_motion = model.arm->inverse_dynamics(column_at(q_s, k), column_at(dq_s, k), column_at(ddq_s, k));
      for (std::size_t j = 0; j < nj; ++j) out[j].tau_model[k] += out[j].load[k] - tau_sim_motion(static_cast<Eigen::Index>(j));
    }
    for (std::size_t j = 0; j < nj && j < model.friction.size() && model.correct_friction; ++j) {
      const auto f_real = ident::lugre_predict(model.friction[j], real.dq[j], dt);
      const auto f_sim = ident::lugre_predict(model.friction[j], dq_s[j], dt);
      for (std::size_t k = 0; k < real.samples(); ++k) out[j].tau_model[k] += f_real[k] - f_sim[k];
    }
  }
  // A joint torque sensor does not see the rotor: take the simulation's rotor torque off
  // a simulated motor torque before comparing.
  if (real.torque_kind == io::TorqueKind::tau_j && simulated.torque_kind != io::TorqueKind::tau_j) {
    for (std::size_t j = 0; j < real.joints() && j < model.rotor_inertia.size(); ++j) {
      if (model.rotor_inertia[j] == 0.0) continue;
      std::vector<double> dq_s(real.samples());
      std::size_t hint = 0;
      for (std::size_t k = 0; k < real.samples(); ++k) dq_s[k] = interp(simulated.t, simulated.dq[j], real.t[k], hint);
      const auto ddq_s = acceleration(dq_s, dt, out[j].acceleration_sigma_s);
      for (std::size_t k = 0; k < real.samples(); ++k) out[j].tau_model[k] -= model.rotor_inertia[j] * ddq_s[k];
    }
  }
  for (auto& s : out) {
    s.residual.resize(s.t.size());
    for (std::size_t k = 0; k < s.t.size(); ++k) s.residual[k] = s.tau_real[k] - s.tau_model[k];
  }
  return out;
}

std::vector<JointSignals> signals_from_model(const io::Recording& real, const ModelContext& model) {
  const double dt = uniform_dt(real, "real");
  std::vector<JointSignals> out(real.joints());
  for (std::size_t j = 0; j < real.joints(); ++j) {
    out[j].joint = real.joint_ids[j];
    out[j].dt = dt;
    out[j].t = real.t;
    out[j].q = real.q[j];
    out[j].dq = real.dq[j];
    out[j].tau_real = torque_of(real, j, model, "real");
    copy_rows(real, j, out[j]);
  }
  add_model_terms(out, real, model);
  for (std::size_t j = 0; j < real.joints(); ++j) {
    JointSignals& s = out[j];
    s.tau_model = s.load.empty() ? std::vector<double>(s.t.size(), 0.0) : s.load;
    if (j < model.friction.size()) {
      const auto f = ident::lugre_predict(model.friction[j], s.dq, dt);
      for (std::size_t k = 0; k < s.t.size(); ++k) s.tau_model[k] += f[k];
    }
    s.residual.resize(s.t.size());
    for (std::size_t k = 0; k < s.t.size(); ++k) s.residual[k] = s.tau_real[k] - s.tau_model[k];
  }
  return out;
}

std::vector<JointSignals> concatenate_signals(const std::vector<std::vector<JointSignals>>& parts) {
  if (parts.empty()) return {};
  std::vector<JointSignals> out = parts.front();
  // The rows resampled from, one part after the other: only where every part has them.
  const bool rows = std::all_of(parts.begin(), parts.end(), [](const auto& p) { return p.empty() || !p.front().rows_t.empty(); });
  auto append = [](std::vector<double>& a, const std::vector<double>& b) { a.insert(a.end(), b.begin(), b.end()); };
  for (std::size_t p = 1; p < parts.size(); ++p) {
    if (parts[p].size() != out.size()) throw std::invalid_argument("segments with different joints");
    for (std::size_t j = 0; j < out.size(); ++j) {
      JointSignals& a = out[j];
      const JointSignals& b = parts[p][j];
      for (auto [dst, src] : {std::pair{&a.t, &b.t}, {&a.q, &b.q}, {&a.dq, &b.dq}, {&a.ddq, &b.ddq}, {&a.tau_real, &b.tau_real},
                              {&a.tau_model, &b.tau_model}, {&a.load, &b.load}, {&a.residual, &b.residual},
                              {&a.velocity_mismatch, &b.velocity_mismatch}, {&a.deflection, &b.deflection}}) {
        append(*dst, *src);
      }
      for (std::size_t c = 0; c < a.payload_columns.size() && c < b.payload_columns.size(); ++c) {
        append(a.payload_columns[c], b.payload_columns[c]);
      }
      for (auto [dst, src] : {std::pair{&a.rows_t, &b.rows_t}, {&a.rows_q, &b.rows_q}, {&a.rows_dq, &b.rows_dq}}) append(*dst, *src);
    }
  }
  if (!rows) {
    for (auto& s : out) s.rows_t.clear(), s.rows_q.clear(), s.rows_dq.clear();
  }
  return out;
}

}  // namespace jg::diag
