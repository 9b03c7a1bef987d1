#include "injection/added_torque.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "diagnosis/diagnose.hpp"
#include "diagnosis/pairing.hpp"
#include "diagnosis/signals.hpp"
#include "dynamics/sensitivity.hpp"
#include "injection/effects_file.hpp"

namespace jg::inject {
namespace {

using Signals = std::vector<diag::JointSignals>;
using PerJoint = std::vector<std::vector<double>>;

sim::JointVector at(const Signals& s, std::size_t k, std::vector<double> diag::JointSignals::*member) {
  sim::JointVector v(static_cast<Eigen::Index>(s.size()));
  for (std::size_t j = 0; j < s.size(); ++j) v(static_cast<Eigen::Index>(j)) = (s[j].*member)[k];
  return v;
}

/// When an arm-level effect starts acting [s, the recording's clock]: a payload picked up
/// during the recording from then on, everything else throughout.
double start_s(const robot::PlantEffect& e) {
  const auto it = e.setting.find("picked_up_at_s");
  return it != e.setting.end() ? it->second : -std::numeric_limits<double>::infinity();
}

struct ArmStage {
  double from_s;
  sim::ArmDynamics arm;
};

/// The arm with the first 1, 2, ... arm-level effects (in order of their start) applied.
std::vector<ArmStage> arm_stages(const sim::ArmDynamics& nominal, std::vector<robot::PlantEffect> arm) {
  std::stable_sort(arm.begin(), arm.end(), [](const auto& a, const auto& b) { return start_s(a) < start_s(b); });
  std::vector<sim::PlantLink> links;
  for (int l = 0; l < nominal.joints(); ++l) links.push_back(nominal.link(l));
  std::vector<ArmStage> stages;
  for (const auto& e : arm) {
    const Eigen::Vector3d h(e.coefficients[1], e.coefficients[2], e.coefficients[3]);
    if (e.effect == robot::Effect::payload) {
      // A point mass, as the plant adds a payload (plant/plant.cpp, apply_payload_if_due).
      links.back() = sim::with_point_mass(links.back(), e.coefficients[0], h / e.coefficients[0]);
    } else {
      // A link's mass and first moment changed, its inertia about the link origin kept: as
      // the plant (sim/apply_effects.cpp) and the diagnosis's columns have it.
      auto& link = links[static_cast<std::size_t>(e.setting.at("link")) - 1];
      link = sim::with_mass_first_moment_change(link, e.coefficients[0], h);
    }
    stages.push_back({start_s(e), sim::ArmDynamics(links, nominal.gravity())});
  }
  return stages;
}

/// Changed minus nominal inverse dynamics on the measured motion, per joint.
PerJoint arm_added(const Signals& s, const sim::ArmDynamics& nominal, const std::vector<robot::PlantEffect>& arm) {
  const std::size_t n = s.empty() ? 0 : s.front().size();
  PerJoint out(s.size(), std::vector<double>(n, 0.0));
  const std::vector<ArmStage> stages = arm_stages(nominal, arm);
  if (stages.empty()) return out;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = s.front().t[k];
    const ArmStage* active = nullptr;
    for (const auto& st : stages) {
      if (st.from_s <= t) active = &st;
    }
    if (active == nullptr) continue;
    const auto q = at(s, k, &diag::JointSignals::q), dq = at(s, k, &diag::JointSignals::dq), ddq = at(s, k, &diag::JointSignals::ddq);
    const sim::JointVector d = active->arm.inverse_dynamics(q, dq, ddq) - nominal.inverse_dynamics(q, dq, ddq);
    for (std::size_t j = 0; j < s.size(); ++j) out[j][k] = d(static_cast<Eigen::Index>(j));
  }
  return out;
}

/// Per-joint effects with the diagnosis's own columns over all segments one after the other
/// (a temperature drift counts from the recording's start, as diagnose sees it); split back.
std::vector<PerJoint> joint_added(const std::vector<Signals>& parts, const std::vector<robot::PlantEffect>& effects) {
  std::vector<PerJoint> out;
  for (const auto& p : parts) out.emplace_back(p.size(), std::vector<double>(p.empty() ? 0 : p.front().size(), 0.0));
  if (parts.empty()) return out;
  const Signals all = diag::concatenate_signals(parts);
  for (std::size_t j = 0; j < all.size(); ++j) {
    std::vector<diag::FittedEffect> model;
    for (const auto& e : effects) {
      if (e.joint != static_cast<int>(j) + 1 || channel_of(e) != Channel::joint) continue;  // joint: 1-based position
      std::vector<double> b = e.coefficients;
      if (e.effect == robot::Effect::asymmetric_friction) b.resize(2, 0.0);  // the viscous slope is optional
      model.push_back({e.effect, e.setting, b});
    }
    if (model.empty()) continue;
    const std::vector<double> extra = diag::predict_effects(model, all[j]);
    std::size_t offset = 0;
    for (auto& p : out) {
      std::copy_n(extra.begin() + static_cast<std::ptrdiff_t>(offset), p[j].size(), p[j].begin());
      offset += p[j].size();
    }
  }
  return out;
}

/// The reading (with what was added) delayed by `delay_s` on a uniform grid: the value at
/// t - delay, held at the segment's ends; returns what that adds.
std::vector<double> delay_added(const std::vector<double>& reading, double dt, double delay_s) {
  const std::size_t n = reading.size();
  std::vector<double> out(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    const double x = std::clamp(static_cast<double>(k) - delay_s / dt, 0.0, static_cast<double>(n - 1));
    const auto i = std::min(static_cast<std::size_t>(x), n - 1);
    const double a = x - static_cast<double>(i);
    const double v = i + 1 < n ? reading[i] + a * (reading[i + 1] - reading[i]) : reading[i];
    out[k] = v - reading[k];
  }
  return out;
}

/// -b [s] summed per joint (the diagnosis's time_delay column is b d tau/dt).
std::vector<double> delays_s(const std::vector<robot::PlantEffect>& effects, std::size_t joints) {
  std::vector<double> d(joints, 0.0);
  for (const auto& e : effects) {
    if (channel_of(e) == Channel::delay && e.joint >= 1) d[static_cast<std::size_t>(e.joint) - 1] -= e.coefficients[0];
  }
  return d;
}

}  // namespace

std::vector<SegmentAddition> physics_added(const std::vector<io::Recording>& segments, const InjectModel& m,
                                           const std::vector<robot::PlantEffect>& effects) {
  const sim::ArmDynamics nominal = m.model->dynamics();
  diag::ModelContext ctx;
  ctx.arm = &nominal;
  ctx.friction = m.friction;
  ctx.torque_constant = m.torque_constant;
  std::vector<Signals> parts;
  for (const auto& seg : segments) parts.push_back(diag::signals_from_model(seg, ctx));
  std::vector<robot::PlantEffect> arm;
  for (const auto& e : effects) {
    if (channel_of(e) == Channel::arm) arm.push_back(e);
  }
  const std::vector<PerJoint> per_joint = joint_added(parts, effects);
  const std::size_t nj = segments.empty() ? 0 : segments.front().joints();
  const std::vector<double> delay = delays_s(effects, nj);
  std::vector<SegmentAddition> out;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    SegmentAddition a{segments[p].t, arm_added(parts[p], nominal, arm), std::vector<double>(nj, 0.0)};
    for (std::size_t j = 0; j < nj; ++j) {
      for (std::size_t k = 0; k < a.t.size(); ++k) a.added_nm[j][k] += per_joint[p][j][k];
      if (delay[j] == 0.0) continue;
      std::vector<double> reading = parts[p][j].tau_real;
      for (std::size_t k = 0; k < reading.size(); ++k) reading[k] += a.added_nm[j][k];
      const auto d = delay_added(reading, parts[p][j].dt, delay[j]);
      for (std::size_t k = 0; k < a.t.size(); ++k) a.added_nm[j][k] += d[k];
      // The same derivative as the diagnosis's time_delay column (diagnosis/effects.cpp).
      for (const double rate : diag::derivative(parts[p][j].tau_model, parts[p][j].dt)) {
        a.delay_on_model_ss[j] += delay[j] * rate * delay[j] * rate;
      }
    }
    out.push_back(std::move(a));
  }
  return out;
}

bool acts_on_the_row_alone(const robot::PlantEffect& e) {
  using robot::Effect;
  if (channel_of(e) != Channel::joint) return false;
  const bool model_curve = e.setting.count("model_curve") != 0U;
  return e.effect == Effect::viscous || e.effect == Effect::position_ripple || e.effect == Effect::temperature_drift ||
         (e.effect == Effect::stribeck && !model_curve) || (e.effect == Effect::coulomb && !model_curve) ||
         (e.effect == Effect::asymmetric_friction && e.setting.count("side") == 0U);
}

std::vector<std::vector<double>> rows_added(const io::Recording& rows, const std::vector<robot::PlantEffect>& effects, double step_s) {
  const std::size_t nj = rows.joints(), n = rows.t.size();
  std::vector<std::vector<double>> out(nj, std::vector<double>(n, 0.0));
  for (std::size_t j = 0; j < nj; ++j) {
    std::vector<diag::FittedEffect> model;
    for (const auto& e : effects) {
      if (e.joint != static_cast<int>(j) + 1 || !acts_on_the_row_alone(e)) continue;
      std::vector<double> b = e.coefficients;
      if (e.effect == robot::Effect::asymmetric_friction) b.resize(2, 0.0);  // the viscous slope is optional
      model.push_back({e.effect, e.setting, b});
    }
    if (model.empty()) continue;
    diag::JointSignals s;
    s.joint = static_cast<int>(j) + 1;
    s.dt = step_s;
    s.t = rows.t;
    s.q = rows.q[j];
    s.dq = rows.dq[j];
    out[j] = diag::predict_effects(model, s);
  }
  return out;
}

SensorChange sensor_change(const std::vector<robot::PlantEffect>& effects, std::size_t joints) {
  SensorChange s{std::vector<double>(joints, 1.0), std::vector<double>(joints, 0.0)};
  for (const auto& e : effects) {
    if (e.joint < 1 || static_cast<std::size_t>(e.joint) > joints) continue;
    const auto j = static_cast<std::size_t>(e.joint) - 1;
    if (channel_of(e) == Channel::scale) s.scale[j] *= 1.0 + e.coefficients[0];
    if (channel_of(e) == Channel::offset) s.offset_nm[j] += e.coefficients[0];
  }
  return s;
}

}  // namespace jg::inject
