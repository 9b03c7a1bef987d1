#include "diagnosis/friction_study.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "identification/lugre_batch.hpp"

namespace jg::diag {
namespace {
double rms_diff(const std::vector<double>& a, const std::vector<double>& b) {
  double acc = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) acc += (a[k] - b[k]) * (a[k] - b[k]);
  return std::sqrt(acc / static_cast<double>(a.size()));
}

JointSignals signals_for(const io::Recording& r, const LuGreParams<double>& lugre, bool offset_at_start) {
  JointSignals s;
  s.joint = r.joint_ids.front();
  s.dt = r.t[1] - r.t[0];
  s.t = r.t;
  s.q = r.q[0];
  s.dq = r.dq[0];
  s.ddq = derivative(s.dq, s.dt);
  s.tau_real = r.tau_m[0];
  // LuGre from rest with relaxed bristles (z = 0): its torque at the first sample is the
  // one at rest, zero, so the start offset leaves it as it is.
  s.tau_model = ident::lugre_predict(lugre, s.dq, s.dt);
  s.offset_at_start = offset_at_start;
  s.residual.resize(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) s.residual[k] = s.tau_real[k] - s.tau_model[k];
  return s;
}
}  // namespace

io::Recording resample_uniform(const io::Recording& r, double max_gap_steps) {
  if (r.joints() != 1 || r.tau_m.empty()) {
    throw std::invalid_argument("friction study: expected one joint with a torque column");
  }
  std::vector<double> steps;
  for (std::size_t k = 1; k < r.samples(); ++k) steps.push_back(r.t[k] - r.t[k - 1]);
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2), steps.end());
  const double dt = steps[steps.size() / 2];
  for (std::size_t k = 1; k < r.samples(); ++k) {
    if (r.t[k] - r.t[k - 1] > max_gap_steps * dt) {
      throw std::invalid_argument("gap of " + std::to_string(r.t[k] - r.t[k - 1]) + " s at t = " + std::to_string(r.t[k - 1]) +
                                  " s: too long to interpolate over");
    }
  }
  io::Recording out;
  const auto n = static_cast<std::size_t>(std::floor((r.t.back() - r.t.front()) / dt)) + 1;
  out.resize(1, n, false, true, false, false);
  out.joint_ids = r.joint_ids;
  out.meta = r.meta;
  out.meta.sample_time = dt;
  std::size_t i = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = r.t.front() + static_cast<double>(k) * dt;
    while (i + 2 < r.samples() && r.t[i + 1] < t) ++i;
    const double a = std::clamp((t - r.t[i]) / (r.t[i + 1] - r.t[i]), 0.0, 1.0);
    out.t[k] = t;
    out.q[0][k] = r.q[0][i] + a * (r.q[0][i + 1] - r.q[0][i]);
    out.dq[0][k] = r.dq[0][i] + a * (r.dq[0][i + 1] - r.dq[0][i]);
    out.tau_m[0][k] = r.tau_m[0][i] + a * (r.tau_m[0][i + 1] - r.tau_m[0][i]);
  }
  return out;
}

StudyResult friction_study(const std::vector<StudyFile>& files, std::size_t train_index, const ident::GaSettings& ga,
                           const ident::SearchRanges& ranges) {
  if (train_index >= files.size()) throw std::invalid_argument("friction study: training file index out of range");
  std::vector<io::Recording> recs;
  for (const auto& f : files) recs.push_back(resample_uniform(io::read_recording(f.path, f.read)));
  StudyResult out;
  const io::Recording& train = recs[train_index];
  out.joint = train.joint_ids.front();
  ident::FrictionSeries series;
  series.velocity = train.dq[0];
  series.friction = train.tau_m[0];
  series.dt = train.t[1] - train.t[0];
  series.skip = std::min<std::size_t>(series.velocity.size() / 20, 500);
  out.identification = ident::identify_lugre(series, ga, ranges);
  out.lugre = out.identification.params;
  out.diagnosis = diagnose_joint(signals_for(train, out.lugre, files[train_index].offset_at_start));
  for (std::size_t i = 0; i < recs.size(); ++i) {
    const JointSignals s = signals_for(recs[i], out.lugre, files[i].offset_at_start);
    // The training file's constant is its own friction state at t0 (offset data): it is
    // not carried to the other files, whose state at t0 is unknown (relaxed assumed).
    std::vector<FittedEffect> model;
    for (const auto& m : out.diagnosis.model) {
      if (!(s.offset_at_start && i != train_index && m.effect == "current_offset")) model.push_back(m);
    }
    const auto extra = predict_effects(model, s);
    std::vector<double> extended(s.size());
    for (std::size_t k = 0; k < s.size(); ++k) extended[k] = s.tau_model[k] + extra[k];
    StudyFileResult r;
    r.path = files[i].path;
    r.training = i == train_index;
    r.samples = s.size();
    r.lugre_rms = rms_diff(s.tau_real, s.tau_model);
    r.extended_rms = rms_diff(s.tau_real, extended);
    out.files.push_back(r);
  }
  return out;
}

}  // namespace jg::diag
