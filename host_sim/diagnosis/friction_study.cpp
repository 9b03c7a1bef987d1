#include "diagnosis/friction_study.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "identification/lugre_batch.hpp"
#include "io/regularize.hpp"

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
  // By time stamp (io::regularize), the study needing one continuous run: any gap longer
  // than max_gap_steps median steps is refused rather than split.
  io::RegularizeOptions o;
  o.gap_steps = max_gap_steps;
  o.gap_min_s = 0.0;
  const io::Regularized reg = io::regularize(r, o, "friction study recording");
  if (reg.report.gaps_split > 0 || reg.segments.size() != 1) {
    throw std::invalid_argument("friction study: a gap longer than " + std::to_string(reg.report.split_gap_s) +
                                " s: too long to interpolate over");
  }
  return reg.segments.front();
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
      if (!(s.offset_at_start && i != train_index && m.effect == robot::Effect::current_offset)) model.push_back(m);
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
