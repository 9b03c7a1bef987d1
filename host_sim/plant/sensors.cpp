#include "plant/sensors.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace jg::sim {

JointSensors::JointSensors(SensorConfig config, int joints) : config_(std::move(config)), rng_(config_.seed) {
  if (config_.drives.size() != static_cast<std::size_t>(joints)) {
    throw std::invalid_argument("JointSensors: one drive configuration per joint required");
  }
  if (config_.link_encoder_bits < 8 || config_.link_encoder_bits > 30 || config_.motor_encoder_counts_per_rev < 4 ||
      config_.delay_samples < 0 || config_.current_delay_samples < 0 || !(config_.current_delay_fraction >= 0.0) ||
      config_.current_delay_fraction >= 1.0) {
    throw std::invalid_argument("JointSensors: encoder resolution or delay out of range");
  }
  for (const auto* v : {&config_.torque_constant_saturation_per_a, &config_.current_offset_drift_a_per_s}) {
    if (!v->empty() && v->size() != static_cast<std::size_t>(joints)) {
      throw std::invalid_argument("JointSensors: per-joint sensor shapes need one value per joint");
    }
  }
  last_counts_ = JointVector::Zero(joints);
}

JointVector JointSensors::current_command(const JointVector& torque_demand) const {
  JointVector i(torque_demand.size());
  for (Eigen::Index j = 0; j < i.size(); ++j) {
    const auto& d = config_.drives[static_cast<std::size_t>(j)];
    i(j) = std::clamp(torque_demand(j) / d.torque_constant_nominal, -d.current_limit_a, d.current_limit_a);
  }
  return i;
}

JointVector JointSensors::produced_torque(const JointVector& current_cmd) const {
  JointVector t(current_cmd.size());
  for (Eigen::Index j = 0; j < t.size(); ++j) {
    const auto& d = config_.drives[static_cast<std::size_t>(j)];
    t(j) = d.torque_constant_nominal * (1.0 + d.torque_constant_error) * current_cmd(j);
    if (!config_.torque_constant_saturation_per_a.empty()) {
      t(j) *= 1.0 - config_.torque_constant_saturation_per_a[static_cast<std::size_t>(j)] * std::fabs(current_cmd(j));
    }
  }
  return t;
}

Measurement JointSensors::sample(const JointVector& q_link, const JointVector& theta, const JointVector& current_cmd,
                                 double dt) {
  const Eigen::Index n = q_link.size();
  const double link_step = 2.0 * M_PI / std::ldexp(1.0, config_.link_encoder_bits);
  const double motor_step = 2.0 * M_PI / config_.motor_encoder_counts_per_rev;
  Measurement m{JointVector(n), JointVector(n), JointVector(n), JointVector(n)};
  for (Eigen::Index j = 0; j < n; ++j) {
    const auto& d = config_.drives[static_cast<std::size_t>(j)];
    m.q(j) = std::floor(q_link(j) / link_step + 0.5) * link_step;
    const double counts = std::floor(theta(j) * d.gear_ratio / motor_step);
    m.dq(j) = first_ ? 0.0 : (counts - last_counts_(j)) * motor_step / d.gear_ratio / dt;
    last_counts_(j) = counts;
    double i = current_cmd(j) + d.current_offset_a + d.current_noise_rms_a * unit_normal_(rng_);
    if (!config_.current_offset_drift_a_per_s.empty()) i += config_.current_offset_drift_a_per_s[static_cast<std::size_t>(j)] * time_s_;
    if (d.current_lsb_a > 0.0) {
      i = std::floor(i / d.current_lsb_a + 0.5) * d.current_lsb_a;
    }
    m.current(j) = i;
    m.tau_m(j) = d.torque_constant_nominal * i;
  }
  first_ = false;
  if (config_.current_delay_samples > 0) {
    current_pipeline_.push_back(m.current);
    if (current_pipeline_.size() > static_cast<std::size_t>(config_.current_delay_samples)) {
      m.current = current_pipeline_.front();
      current_pipeline_.pop_front();
    } else {
      m.current = current_pipeline_.front();
    }
    for (Eigen::Index j = 0; j < n; ++j) m.tau_m(j) = config_.drives[static_cast<std::size_t>(j)].torque_constant_nominal * m.current(j);
  }
  if (config_.current_delay_fraction > 0.0) {
    const JointVector now = m.current;
    const double f = config_.current_delay_fraction;
    if (last_current_.size() == n) m.current = (1.0 - f) * now + f * last_current_;
    last_current_ = now;
    for (Eigen::Index j = 0; j < n; ++j) m.tau_m(j) = config_.drives[static_cast<std::size_t>(j)].torque_constant_nominal * m.current(j);
  }
  time_s_ += dt;
  pipeline_.push_back(m);
  if (pipeline_.size() > static_cast<std::size_t>(config_.delay_samples)) {
    Measurement out = pipeline_.front();
    pipeline_.pop_front();
    return out;
  }
  return pipeline_.front();  // not yet filled: repeat the oldest sample
}

}  // namespace jg::sim
