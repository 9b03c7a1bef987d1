#include "eval/torque_reaching_motor.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace jg::eval {
namespace {

/// The first cycle with any external torque; `samples` when there is none.
std::size_t contact_onset(const io::Recording& rec) {
  for (std::size_t k = 0; k < rec.samples(); ++k) {
    for (const auto& joint : rec.tau_ext) {
      if (joint[k] != 0.0) return k;
    }
  }
  return rec.samples();
}

}  // namespace

std::vector<std::vector<double>> torque_reaching_motor(const sim::SimulationResult& r, double dt,
                                                       const StandstillRule& still_rule) {
  const io::Recording& rec = r.recording;
  const std::size_t n = rec.tau_ext.size(), samples = rec.samples();
  if (samples == 0 || r.plant_friction_nm.size() != n || r.plant_speed_rad_s.size() != n) return {};
  std::vector<std::vector<double>> out = rec.tau_ext;
  const std::size_t onset = contact_onset(rec);
  if (onset == samples || onset == 0) return out;
  const auto before = static_cast<std::size_t>(std::ceil(std::max(0.0, still_rule.before_s) / dt - 1e-9));
  const auto still_at = [&](std::size_t j, std::size_t k) { return std::fabs(r.plant_speed_rad_s[j][k]) <= still_rule.speed_rad_s; };
  for (std::size_t j = 0; j < n; ++j) {
    bool still = true;
    for (std::size_t k = onset - 1 > before ? onset - 1 - before : 0; k < onset && still; ++k) still = still_at(j, k);
    const double friction_before = r.plant_friction_nm[j][onset - 1];
    for (std::size_t k = onset; k < samples && still_at(j, k) && still; ++k) {
      // The plant's drive is motor - friction + external: the friction's change along the
      // push cancels that much of it before it can move the joint or the motor's torque.
      const double external = rec.tau_ext[j][k], change = r.plant_friction_nm[j][k] - friction_before;
      const double absorbed = external >= 0.0 ? std::clamp(change, 0.0, external) : std::clamp(change, external, 0.0);
      out[j][k] = external - absorbed;
    }
  }
  return out;
}

}  // namespace jg::eval
