#include "diagnosis/cross_motion.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "diagnosis/diagnose.hpp"
#include "diagnosis/pairing.hpp"

namespace jg::diag {
namespace {

/// Samples [b, e) of every signal of one joint (optional signals stay empty when empty).
JointSignals sub_signals(const JointSignals& s, std::size_t b, std::size_t e) {
  JointSignals out = s;
  auto cut = [&](std::vector<double>& v) {
    if (v.size() == s.size()) v = std::vector<double>(v.begin() + static_cast<std::ptrdiff_t>(b), v.begin() + static_cast<std::ptrdiff_t>(e));
  };
  for (auto* v : {&out.t, &out.q, &out.dq, &out.ddq, &out.tau_real, &out.tau_model, &out.load, &out.residual,
                  &out.velocity_mismatch, &out.deflection}) {
    cut(*v);
  }
  for (auto& c : out.payload_columns) cut(c);
  return out;
}

std::vector<double> minus(std::vector<double> a, const std::vector<double>& b) {
  for (std::size_t k = 0; k < a.size() && k < b.size(); ++k) a[k] -= b[k];
  return a;
}

/// One fold: fitted on `train`, predicted over `test`.
CrossMotionFold one_fold(const std::vector<JointSignals>& train, const std::vector<JointSignals>& test,
                         const ArmDiagnosisOptions& o, const sim::ArmDynamics* arm, bool with_joints) {
  CrossMotionFold f;
  const ArmDiagnosis a = diagnose_arm(train, o, arm);
  f.arm_causes = cause_names(a.model);
  const auto arm_torque = predict_arm_causes(a.model, test, arm);
  const auto train_joints = without_arm_causes(train, a);
  double ratio_sum = 0.0;
  for (std::size_t j = 0; j < test.size(); ++j) {
    CrossMotionJoint cj;
    cj.joint = test[j].joint;
    const auto after_arm = minus(test[j].residual, arm_torque[j]);
    cj.rms_before = rms(test[j].residual);
    cj.rms_after_arm = rms(after_arm);
    cj.rms_after = cj.rms_after_arm;
    ratio_sum += cj.rms_before > 0.0 ? std::pow(cj.rms_after_arm / cj.rms_before, 2) : 1.0;
    if (!with_joints) {
      f.joints.push_back(cj);
      continue;
    }
    const JointDiagnosis d = diagnose_joint(train_joints[j], o.joint);
    for (const auto& e : d.model) cj.effects.push_back(e.effect);
    JointSignals t = test[j];
    t.residual = after_arm;
    t.arm_level_fitted = true;
    cj.rms_after = rms(minus(after_arm, predict_effects(d.model, t)));
    for (std::size_t e = 0; e < d.model.size(); ++e) {
      auto without = d.model;
      without.erase(without.begin() + static_cast<std::ptrdiff_t>(e));
      if (rms(minus(after_arm, predict_effects(without, t))) * (1.0 + kCrossMotionWorseShare) < cj.rms_after) {
        cj.worse_effects.push_back(d.model[e].effect);
      }
    }
    f.joints.push_back(cj);
  }
  f.arm_mse_ratio = test.empty() ? 1.0 : ratio_sum / static_cast<double>(test.size());
  return f;
}

}  // namespace

std::vector<JointSignals> slice_signals(const std::vector<JointSignals>& joints, const std::vector<SampleSpan>& spans) {
  std::vector<std::vector<JointSignals>> parts;
  for (const auto& sp : spans) {
    std::vector<JointSignals> part;
    for (const auto& s : joints) {
      if (sp.begin >= sp.end || sp.end > s.size()) throw std::invalid_argument("sample span outside the signals");
      part.push_back(sub_signals(s, sp.begin, sp.end));
    }
    parts.push_back(std::move(part));
  }
  return concatenate_signals(parts);
}

std::vector<CrossMotionFold> cross_motion_folds(const std::vector<JointSignals>& joints,
                                                const std::vector<SampleSpan>& recordings,
                                                const ArmDiagnosisOptions& options, const sim::ArmDynamics* arm,
                                                bool with_joints) {
  if (recordings.size() < 2) throw std::invalid_argument("cross-motion validation needs at least 2 recordings");
  ArmDiagnosisOptions o = options;
  o.payload_picked_up = false;
  std::vector<CrossMotionFold> folds;
  for (std::size_t r = 0; r < recordings.size(); ++r) {
    std::vector<SampleSpan> others;
    for (std::size_t i = 0; i < recordings.size(); ++i) {
      if (i != r) others.push_back(recordings[i]);
    }
    CrossMotionFold f = one_fold(slice_signals(joints, others), slice_signals(joints, {recordings[r]}), o, arm, with_joints);
    f.left_out = r;
    folds.push_back(std::move(f));
  }
  return folds;
}

std::vector<NotTransferring> effects_not_transferring(const std::vector<CrossMotionFold>& folds,
                                                     const std::vector<std::string>& names) {
  std::vector<NotTransferring> out;
  for (const auto& f : folds) {
    for (const auto& cj : f.joints) {
      for (const auto& e : cj.worse_effects) {
        bool seen = false;
        for (const auto& n : out) seen = seen || (n.joint == cj.joint && n.effect == e);
        if (seen) continue;
        std::ostringstream why;
        why << "joint " << cj.joint << ": " << e << " fitted on the other recordings makes "
            << (f.left_out < names.size() ? names[f.left_out] : "a recording")
            << " worse: it describes one motion, not the joint, and is not claimed";
        out.push_back({cj.joint, e, why.str()});
      }
    }
  }
  return out;
}

std::vector<std::string> cause_names(const std::vector<FittedEffect>& model) {
  std::vector<std::string> out;
  for (const auto& m : model) {
    const auto link = m.setting.find("link");
    out.push_back(m.effect + "@" + std::to_string(link == m.setting.end() ? 0 : static_cast<int>(link->second)));
  }
  return out;
}

std::string arm_not_transferring(const std::vector<CrossMotionFold>& folds, const std::vector<std::string>& names,
                                 const std::vector<std::string>& claimed) {
  auto sorted = [](std::vector<std::string> v) {
    std::sort(v.begin(), v.end());
    return v;
  };
  for (const auto& f : folds) {
    if (f.arm_causes.empty()) continue;
    const std::string left_out = f.left_out < names.size() ? names[f.left_out] : "a recording";
    std::ostringstream why;
    why.precision(3);
    if (sorted(f.arm_causes) != sorted(claimed)) {
      why << "the arm-level causes depend on the motion: fitted without " << left_out << ":";
      for (const auto& c : f.arm_causes) why << ' ' << c;
      why << "; on all recordings:";
      for (const auto& c : claimed) why << ' ' << c;
      why << ": not one cause across the recordings, not claimed";
      return why.str();
    }
    if (f.arm_mse_ratio <= 1.0 + kCrossMotionWorseShare) continue;
    why << "the arm-level causes fitted on the other recordings make " << left_out << " worse (mean MSE ratio "
        << f.arm_mse_ratio << "): not one cause across the recordings, not claimed";
    return why.str();
  }
  return {};
}

}  // namespace jg::diag
