#include "diagnosis/arm.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>

#include "dynamics/sensitivity.hpp"

namespace jg::diag {
namespace {
using Eigen::MatrixXd;
using Eigen::VectorXd;

/// One arm-level candidate: shared columns per joint ([column][joint][sample]) and the
/// nonlinear setting it was built for.
struct ArmCandidate {
  robot::Effect effect = robot::Effect::none;
  std::vector<std::vector<std::vector<double>>> columns;
  int link = 0;            ///< 1-based link the cause belongs to
  int joint = 0;           ///< 1-based joint of a drive's cause (torque constant), 0: none
  double pickup_s = -1.0;  ///< step time of a payload picked up during the recording (< 0: throughout)
  int nonlinear_params = 0;
  /// Columns held at zero (a payload centred on the last joint's axis has no first moment
  /// across it): kept so every cause of one effect has the same coefficient layout, not
  /// counted as parameters.
  int zeroed_columns = 0;
};

/// The stacked, noise-weighted problem: rows = (joint, sample) for the given samples.
struct Stack {
  std::vector<std::size_t> rows;
  std::size_t joints = 0;
  std::vector<double> weight;  ///< per joint
};

/// Least squares with the columns scaled to unit norm and directions the data cannot
/// resolve (singular values below 1e-6 of the largest) left at zero: a parameter the motion
/// does not excite (a first moment along a horizontal joint axis) stays at its model value
/// instead of fitting noise with a huge coefficient.
VectorXd lsq(const MatrixXd& X, const VectorXd& y) {
  if (X.cols() == 0) return VectorXd();
  // A column that is zero but for rounding (a link's mass at a point on its own and its
  // parents' axes, a first moment along a horizontal axis) is no column at all.
  VectorXd scale = X.colwise().norm().transpose();
  const double largest = scale.maxCoeff();
  for (Eigen::Index i = 0; i < scale.size(); ++i) scale(i) = scale(i) > 1e-9 * largest ? 1.0 / scale(i) : 0.0;
  const MatrixXd Xs = X * scale.asDiagonal();
  Eigen::CompleteOrthogonalDecomposition<MatrixXd> cod;
  cod.setThreshold(1e-6);
  cod.compute(Xs);
  return scale.asDiagonal() * cod.solve(y);
}

double soft_sign(double w, double band) { return std::fabs(w) >= band ? (w > 0.0 ? 1.0 : -1.0) : w / band; }

/// Nuisance columns of joint j, zero on other joints' rows: what one joint's own drive or
/// friction adds (offset, Coulomb sign, viscous), fitted beside every arm-level cause so that
/// it must explain more than that; with_acceleration adds the joint's own acceleration (a
/// rotor inertia), used to judge whether a cause can be told apart from per-joint effects.
constexpr int kNuisance = 3;
MatrixXd nuisance(const std::vector<JointSignals>& js, const Stack& st, bool with_acceleration = false) {
  const auto nr = static_cast<Eigen::Index>(st.rows.size() * st.joints);
  const int per_joint = kNuisance + (with_acceleration ? 1 : 0);
  MatrixXd X = MatrixXd::Zero(nr, static_cast<Eigen::Index>(per_joint * st.joints));
  for (std::size_t j = 0; j < st.joints; ++j) {
    const auto& s = js[j];
    double vmax = 0.0;
    for (const double w : s.dq) vmax = std::max(vmax, std::fabs(w));
    const double band = std::max(1e-4, 0.005 * vmax);
    for (std::size_t r = 0; r < st.rows.size(); ++r) {
      const auto row = static_cast<Eigen::Index>(j * st.rows.size() + r);
      const std::size_t k = st.rows[r];
      const auto c = static_cast<Eigen::Index>(per_joint * static_cast<int>(j));
      X(row, c) = st.weight[j];
      X(row, c + 1) = st.weight[j] * soft_sign(s.dq[k], band);
      X(row, c + 2) = st.weight[j] * s.dq[k];
      if (with_acceleration) X(row, c + 3) = st.weight[j] * s.ddq[k];
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

/// A cause's evidence against the recording's own variation, and its uncertainty.
struct JackknifedCause {
  double z = 0.0;                 ///< its torque over the jackknife standard error of it
  double mass_sigma = 0.0;        ///< [kg]
  Eigen::Vector3d com_sigma = Eigen::Vector3d::Zero();  ///< of first moment / mass [m]
};

double jackknife_se(const std::vector<double>& v) {
  const double b = static_cast<double>(v.size());
  double mean = 0.0;
  for (const double x : v) mean += x / b;
  double ss = 0.0;
  for (const double x : v) ss += (x - mean) * (x - mean);
  return std::sqrt((b - 1.0) / b * ss);
}

/// Delete-one-block jackknife of the shared coefficients of `cs` (fit(cs, stack) returns
/// them, causes first, 4 per cause): contiguous blocks keep the residual's slow, correlated
/// part together, so the spread is what the recording's own variation gives. Per cause, z
/// is 1 over the standard error of each refit's torque projected on the full fit's.
template <class Fit>
std::vector<JackknifedCause> jackknife_causes(const std::vector<const ArmCandidate*>& cs, std::size_t n, int blocks, Fit fit,
                                              const Stack& all, const std::vector<double>& weight) {
  const VectorXd full_b = fit(cs, all);
  const auto count = static_cast<std::size_t>(std::max(blocks, 2));
  std::vector<VectorXd> reps;
  for (std::size_t blk = 0; blk < count; ++blk) {
    Stack st;
    st.joints = all.joints;
    st.weight = weight;
    for (std::size_t k = 0; k < n; ++k) {
      if (k * count / n != blk) st.rows.push_back(k);
    }
    reps.push_back(fit(cs, st));
  }
  std::vector<JackknifedCause> out;
  Eigen::Index at = 0;
  for (const auto* c : cs) {
    const auto p = static_cast<Eigen::Index>(c->columns.size());
    const MatrixXd X = shared(*c, all);
    const VectorXd full = X * full_b.segment(at, p);
    std::vector<double> proj, mass;
    std::vector<std::vector<double>> com(3);
    for (const auto& r : reps) {
      proj.push_back(full.squaredNorm() > 0.0 ? full.dot(X * r.segment(at, p)) / full.squaredNorm() : 0.0);
      mass.push_back(r(at));
      for (Eigen::Index a = 0; a < 3 && a + 1 < p; ++a) com[static_cast<std::size_t>(a)].push_back(r(at + 1 + a) / r(at));
    }
    JackknifedCause j;
    const double se = jackknife_se(proj);
    j.z = se > 0.0 ? 1.0 / se : 1e9;
    j.mass_sigma = jackknife_se(mass);
    for (int a = 0; a < 3; ++a) j.com_sigma(a) = com[static_cast<std::size_t>(a)].empty() ? 0.0 : jackknife_se(com[static_cast<std::size_t>(a)]);
    out.push_back(j);
    at += p;
  }
  return out;
}

/// A payload the fit asks for but the robot's description rules out, as a report.
Finding implausible_payload(double mass_kg, const Eigen::Vector3d& first_moment, double bound_kg, const std::string& why) {
  Finding f;
  f.effect = robot::Effect::payload;
  f.params["mass_kg"] = mass_kg;
  f.params["bound_kg"] = bound_kg;
  const Eigen::Vector3d com = first_moment / mass_kg;
  f.params["com_x_m"] = com.x();
  f.params["com_y_m"] = com.y();
  f.params["com_z_m"] = com.z();
  f.text = why;
  return f;
}

/// Payload: carried throughout, or picked up during the recording (a step at pickup_s,
/// on a 5 % grid of the recording): the model's sensitivities to the last link's mass
/// and first moment. Each also centred on the last joint's axis (the last link frame's z,
/// the DH convention every robot file is read into): the usual tool, mounted on the
/// flange. Its first moment across the axis is what a short motion resolves worst, and a
/// free fit of it lends the payload torque on the last joint that a centred one never has.
/// The order is the carried-throughout free fit first (predict_arm_causes relies on it).
std::vector<ArmCandidate> payload_candidates(const std::vector<JointSignals>& js, bool picked_up) {
  std::vector<ArmCandidate> out;
  const auto& t = js.front().t;
  const double t0 = t.front(), span = t.back() - t.front();
  for (const bool on_axis : {false, true}) {
    for (int i = 0; i <= (picked_up ? 17 : 0); ++i) {
      ArmCandidate c;
      c.effect = robot::Effect::payload;
      c.link = static_cast<int>(js.size());
      if (i > 0) {
        c.pickup_s = t0 + span * (0.05 + 0.05 * i);
        c.nonlinear_params = 1;
      }
      c.columns.assign(4, std::vector<std::vector<double>>(js.size()));
      for (std::size_t p = 0; p < 4; ++p) {
        for (std::size_t j = 0; j < js.size(); ++j) {
          auto col = js[j].payload_columns[p];
          if (on_axis && (p == 1 || p == 2)) {
            std::fill(col.begin(), col.end(), 0.0);
          } else if (c.pickup_s >= 0.0) {
            for (std::size_t k = 0; k < col.size(); ++k) col[k] = t[k] >= c.pickup_s ? col[k] : 0.0;
          }
          c.columns[p][j] = std::move(col);
        }
      }
      c.zeroed_columns = on_axis ? 2 : 0;
      out.push_back(std::move(c));
    }
  }
  return out;
}

/// A link's mass and first moment off (links before the last: the last one's error is a
/// payload), from the nominal model's sensitivities over the recorded motion.
ArmCandidate link_candidate(const std::vector<JointSignals>& js, const sim::ArmDynamics& arm, int link) {
  ArmCandidate c;
  c.effect = robot::Effect::link_inertial_error;
  c.link = link + 1;
  const std::size_t n = js.front().size(), nj = js.size();
  c.columns.assign(4, std::vector<std::vector<double>>(nj, std::vector<double>(n, 0.0)));
  sim::JointVector q(static_cast<Eigen::Index>(nj)), dq(static_cast<Eigen::Index>(nj)), ddq(static_cast<Eigen::Index>(nj));
  for (std::size_t k = 0; k < n; ++k) {
    for (std::size_t j = 0; j < nj; ++j) {
      q(static_cast<Eigen::Index>(j)) = js[j].q[k];
      dq(static_cast<Eigen::Index>(j)) = js[j].dq[k];
      ddq(static_cast<Eigen::Index>(j)) = js[j].ddq[k];
    }
    const auto cols = sim::mass_first_moment_sensitivity(arm, link, q, dq, ddq);
    for (std::size_t p = 0; p < 4; ++p) {
      for (std::size_t j = 0; j < nj; ++j) c.columns[p][j][k] = cols[p](static_cast<Eigen::Index>(j));
    }
  }
  return c;
}

/// A drive's current-to-torque constant off (current data only): the measured torque of
/// joint `j` (0-based) is (1 + k) times the true one. Its column is the robot file's torque
/// on that joint, zero on the others; the friction the file lacks is the nuisance's (offset,
/// Coulomb, viscous), so k scales the rigid body's torque. Against the robot file, before
/// the rigid-body refit: afterwards the refit's base parameters have taken most of it.
ArmCandidate torque_constant_candidate(const std::vector<JointSignals>& js, std::size_t j) {
  ArmCandidate c;
  c.effect = robot::Effect::torque_constant;
  c.joint = js[j].joint;
  c.columns.assign(1, std::vector<std::vector<double>>(js.size(), std::vector<double>(js[j].size(), 0.0)));
  c.columns[0][j] = js[j].tau_model;
  return c;
}

/// What a cause is called in notes: "payload", "link 3 mass error", "joint 2 torque constant".
std::string cause_label(const ArmCandidate& c) {
  if (c.effect == robot::Effect::payload) return c.zeroed_columns > 0 ? "payload (centred)" : "payload";
  if (c.effect == robot::Effect::torque_constant) return "joint " + std::to_string(c.joint) + " torque constant";
  return "link " + std::to_string(c.link) + " mass error";
}

MatrixXd hstack(const std::vector<MatrixXd>& parts) {
  Eigen::Index cols = 0;
  for (const auto& p : parts) cols += p.cols();
  MatrixXd X(parts.front().rows(), cols);
  Eigen::Index at = 0;
  for (const auto& p : parts) {
    X.middleCols(at, p.cols()) = p;
    at += p.cols();
  }
  return X;
}
/// The arm-level problem: training, held-out and all samples, each joint weighted by its
/// own error scale (residual RMS after its nuisance terms on the training blocks: a joint
/// with a large model error does not drown the others), and the targets.
struct ArmProblem {
  const std::vector<JointSignals>& js;
  std::size_t n = 0;
  Stack train, test, all;
  VectorXd y_train, y_test;

  /// The causes' shared columns beside every joint's nuisance terms, on `st`'s samples.
  [[nodiscard]] MatrixXd design(const std::vector<const ArmCandidate*>& cs, const Stack& st) const {
    std::vector<MatrixXd> parts;
    for (const auto* c : cs) parts.push_back(shared(*c, st));
    parts.push_back(nuisance(js, st));
    return hstack(parts);
  }
  /// Parameters a fit estimates: the nuisance terms, each cause's columns (not those held at
  /// zero) and its nonlinear settings.
  [[nodiscard]] int param_count(const std::vector<const ArmCandidate*>& cs) const {
    int k = static_cast<int>(kNuisance * js.size());
    for (const auto* c : cs) k += static_cast<int>(c->columns.size()) - c->zeroed_columns + c->nonlinear_params;
    return k;
  }
};

ArmProblem arm_problem(const std::vector<JointSignals>& js, const DiagnoseOptions& o) {
  ArmProblem p{js, 0, {}, {}, {}, {}, {}};
  p.n = js.front().size();
  const auto held = heldout_mask(p.n, o);
  for (std::size_t k = 0; k < p.n; ++k) (held[k] ? p.test : p.train).rows.push_back(k);
  p.train.joints = p.test.joints = p.all.joints = js.size();
  p.train.weight.assign(js.size(), 1.0);
  const MatrixXd N = nuisance(js, p.train);
  const VectorXd y = target(js, p.train);
  const auto r = joint_rms(y - N * lsq(N, y), p.train);
  for (std::size_t j = 0; j < js.size(); ++j) p.train.weight[j] = 1.0 / std::max(r[j], 1e-9);
  p.test.weight = p.all.weight = p.train.weight;
  p.y_train = target(js, p.train);
  p.y_test = target(js, p.test);
  for (std::size_t k = 0; k < p.n; ++k) p.all.rows.push_back(k);
  return p;
}

/// Candidate groups: the payload (its pick-up time on a grid), each inner link's error, each
/// drive's torque constant (current data against the robot file).
std::vector<std::vector<ArmCandidate>> candidate_groups(const std::vector<JointSignals>& js, const ArmDiagnosisOptions& o,
                                                        const sim::ArmDynamics* arm) {
  std::vector<std::vector<ArmCandidate>> groups{payload_candidates(js, o.payload_picked_up)};
  if (arm != nullptr && arm->joints() == static_cast<int>(js.size())) {
    for (int l = 0; l + 1 < arm->joints(); ++l) groups.push_back({link_candidate(js, *arm, l)});
  }
  if (o.torque_constants) {
    for (std::size_t j = 0; j < js.size(); ++j) groups.push_back({torque_constant_candidate(js, j)});
  }
  return groups;
}

/// The groups separable from what single joints add on their own (offset, friction, a rotor
/// inertia): at least min_separable of a cause's columns' norm outside their span. On a narrow
/// sinusoidal motion the acceleration is proportional to the displacement and a link's
/// gravity torque change is a smooth function of it: not separable (said in `notes`).
std::vector<std::vector<ArmCandidate>> separable_groups(std::vector<std::vector<ArmCandidate>> all_groups, const ArmProblem& p,
                                                        const ArmDiagnosisOptions& o, std::vector<std::string>& notes) {
  std::vector<std::vector<ArmCandidate>> groups;
  const MatrixXd Nsep = nuisance(p.js, p.train, true);
  Eigen::HouseholderQR<MatrixXd> qr(Nsep);
  const MatrixXd Q = qr.householderQ() * MatrixXd::Identity(Nsep.rows(), Nsep.cols());
  for (auto& g : all_groups) {
    const MatrixXd Xc = shared(g.front(), p.train);
    const double raw = Xc.norm();
    const double outside = (Xc - Q * (Q.transpose() * Xc)).norm();
    if (o.joint.trace) {
      std::fprintf(stderr, "  arm %s: %.2f outside per-joint effects\n", cause_label(g.front()).c_str(), outside / std::max(raw, 1e-300));
    }
    if (raw > 0.0 && outside >= o.min_separable * raw) {
      groups.push_back(std::move(g));
    } else {
      notes.push_back(cause_label(g.front()) + ": not separable from per-joint effects on this motion (" +
                      std::to_string(static_cast<int>(100.0 * outside / std::max(raw, 1e-300))) + " % of it outside them)");
    }
  }
  return groups;
}

/// A set of causes (one instance per group) fitted on the training blocks.
struct Subset {
  std::vector<const ArmCandidate*> cs;
  std::vector<std::size_t> groups;
  double bic = 0.0;
  VectorXd b;
};

void fit_subset(const ArmProblem& p, Subset& sub) {
  const MatrixXd X = p.design(sub.cs, p.train);
  sub.b = lsq(X, p.y_train);
  sub.bic = bic((p.y_train - X * sub.b).squaredNorm(), static_cast<std::size_t>(p.y_train.size()), p.param_count(sub.cs));
}

VectorXd heldout_error(const ArmProblem& p, const Subset& sub) { return p.y_test - p.design(sub.cs, p.test) * sub.b; }

/// Adds to `out` every subset that extends `base` by one instance of each of up to `left`
/// further groups after `from` (at most one instance per group), each fitted.
void extend_subsets(const std::vector<std::vector<ArmCandidate>>& groups, const Subset& base, std::size_t from, int left,
                    const ArmProblem& p, std::vector<Subset>& out) {
  if (left <= 0) return;
  for (std::size_t g = from; g < groups.size(); ++g) {
    for (const auto& c : groups[g]) {
      Subset more = base;
      more.cs.push_back(&c);
      more.groups.push_back(g);
      fit_subset(p, more);
      out.push_back(more);
      extend_subsets(groups, more, g + 1, left - 1, p, out);
    }
  }
}

/// Every subset of at most max_causes causes, best BIC first: a greedy choice would let one
/// cause imitating two (a payload at the next joint's axis for a link's mass) lock out the
/// right pair. The subsets point into `groups`.
std::vector<Subset> scored_subsets(const std::vector<std::vector<ArmCandidate>>& groups, int max_causes, const ArmProblem& p) {
  std::vector<Subset> subsets;
  extend_subsets(groups, Subset{}, 0, max_causes, p, subsets);
  std::stable_sort(subsets.begin(), subsets.end(), [](const Subset& a, const Subset& b) { return a.bic < b.bic; });
  return subsets;
}

/// The robot's own description bounds a payload: its rating, else its own mass.
struct PayloadBound {
  double kg = std::numeric_limits<double>::infinity();
  std::string name = "the arm's rated payload";
};

PayloadBound payload_bound(const ArmDiagnosisOptions& o, const sim::ArmDynamics* arm) {
  PayloadBound b;
  if (o.max_payload_kg > 0.0) {
    b.kg = o.max_payload_kg;
  } else if (arm != nullptr) {
    b.kg = 0.0;
    for (int l = 0; l < arm->joints(); ++l) b.kg += arm->link(l).mass;
    b.name = "the arm's own mass (no rated_payload_kg given)";
  }
  return b;
}

/// What the selection judges a subset against: the problem, the options, the robot's bounds,
/// the empty fit and every subset (a pair's members alone).
struct Judge {
  const ArmProblem& p;
  const ArmDiagnosisOptions& o;
  const sim::ArmDynamics* arm;
  PayloadBound bound;
  const Subset& none;
  const std::vector<Subset>& subsets;

  [[nodiscard]] const Subset& best_single(const ArmCandidate* c) const {
    for (const auto& sub : subsets) {
      if (sub.cs.size() == 1 && sub.cs.front() == c) return sub;
    }
    return none;
  }
};

/// Why one fitted cause is implausible by the robot's description (empty: plausible). A drive's
/// constant or a payload beyond the robot's bounds is also reported in `d.unexplained`, once.
std::string implausible_cause(const Judge& jd, const ArmCandidate& c, double mass, const Eigen::Vector3d& first, ArmDiagnosis& d) {
  const ArmDiagnosisOptions& o = jd.o;
  std::ostringstream why;
  why.precision(3);
  if (c.effect == robot::Effect::torque_constant) {  // `mass` holds the drive's scale error k
    if (std::fabs(mass) <= o.max_torque_constant_error) return {};
    why << cause_label(c) << " off by " << 100.0 * mass << " %, beyond the +/-" << 100.0 * o.max_torque_constant_error
        << " % a drive's constant is known to: implausible, not claimed; an unexplained mismatch of that size";
    Finding f;
    f.effect = robot::Effect::torque_constant;
    f.params["joint"] = c.joint;
    f.params["scale_error"] = mass;
    f.params["bound"] = o.max_torque_constant_error;
    f.text = why.str();
    // One drive, one report: the same joint's constant rejected again beside another cause adds nothing.
    const bool known = std::any_of(d.unexplained.begin(), d.unexplained.end(), [&](const Finding& u) {
      return u.effect == robot::Effect::torque_constant && u.params.count("joint") != 0 && u.params.at("joint") == c.joint;
    });
    if (!known) d.unexplained.push_back(f);
  } else if (c.effect == robot::Effect::payload && !(mass > o.min_mass_kg)) {
    why << "payload fit gives a mass of " << mass << " kg (must be positive): not claimed";
  } else if (c.effect == robot::Effect::payload && mass > jd.bound.kg) {
    why << "payload fit gives " << mass << " kg, above " << jd.bound.name << " (" << jd.bound.kg
        << " kg): implausible, not claimed; an unexplained mismatch of that size";
    if (d.unexplained.empty()) d.unexplained.push_back(implausible_payload(mass, first, jd.bound.kg, why.str()));
  } else if (c.effect == robot::Effect::payload && first.norm() > o.com_bound_m * mass) {
    why << "payload fit puts its centre of mass " << first.norm() / mass << " m from the last link's origin (bound "
        << o.com_bound_m << " m): not claimed";
  } else if (c.effect != robot::Effect::payload && jd.arm != nullptr) {
    const double m0 = jd.arm->link(c.link - 1).mass;
    if (std::fabs(mass) > o.max_link_mass_share * m0 || first.norm() > o.max_link_mass_share * m0 * o.com_bound_m) {
      why << cause_label(c) << " of " << mass << " kg (first moment " << first.norm() << " kg·m) beyond "
          << 100.0 * o.max_link_mass_share << " % of the link's " << m0 << " kg: not claimed";
    }
  }
  return why.str();
}

/// Each cause plausible, and each of a pair bringing its own evidence (empty: so).
std::string causes_rejected(const Judge& jd, const Subset& sub, const VectorXd& e, ArmDiagnosis& d) {
  const DiagnoseOptions& oj = jd.o.joint;
  Eigen::Index at = 0;
  for (std::size_t i = 0; i < sub.cs.size(); ++i) {
    const ArmCandidate& c = *sub.cs[i];
    const Eigen::Vector3d first = c.columns.size() >= 4 ? Eigen::Vector3d(sub.b(at + 1), sub.b(at + 2), sub.b(at + 3))
                                                        : Eigen::Vector3d::Zero();
    const std::string why = implausible_cause(jd, c, sub.b(at), first, d);
    at += static_cast<Eigen::Index>(c.columns.size());
    if (!why.empty()) return why;
    if (sub.cs.size() == 2) {
      const Subset& rest = jd.best_single(sub.cs[1 - i]);
      if (rest.bic - sub.bic < oj.min_delta_bic || e.norm() > heldout_error(jd.p, rest).norm() * (1.0 - oj.min_heldout_gain)) {
        return cause_label(c) + " adds no evidence beside " + cause_label(*sub.cs[1 - i]);
      }
    }
  }
  return {};
}

/// A payload loads the joints between it and the base through its weight: one that improves
/// fewer than two of the joints it loads is a single joint's effect (a rotor inertia, an
/// offset) in disguise (empty: it loads and improves two or more).
std::string payload_on_one_joint(const Judge& jd, const Subset& sub, const std::vector<double>& before_joint,
                                 const std::vector<double>& after_joint) {
  const auto& js = jd.p.js;
  const auto& rows = jd.p.test.rows;
  Eigen::Index at = 0;
  for (const auto* c : sub.cs) {
    const auto p = static_cast<Eigen::Index>(c->columns.size());
    if (c->effect == robot::Effect::payload && js.size() >= 2) {
      std::vector<double> load(js.size(), 0.0);
      for (std::size_t j = 0; j < js.size(); ++j) {
        double acc = 0.0;
        for (const std::size_t k : rows) {
          double v = 0.0;
          for (Eigen::Index i = 0; i < p; ++i) v += sub.b(at + i) * c->columns[static_cast<std::size_t>(i)][j][k];
          acc += v * v;
        }
        load[j] = std::sqrt(acc / static_cast<double>(std::max<std::size_t>(rows.size(), 1)));
      }
      const double peak = *std::max_element(load.begin(), load.end());
      int improved = 0;
      for (std::size_t j = 0; j < js.size(); ++j) {
        if (load[j] >= 0.25 * peak && after_joint[j] < before_joint[j] * (1.0 - jd.o.joint.min_heldout_gain)) ++improved;
      }
      if (improved < 2) return "payload fit improves fewer than two of the joints it loads: a single joint's effect, not claimed";
    }
    at += p;
  }
  return {};
}

/// Why a subset cannot be claimed (empty: it can; then `jack` holds its causes' evidence
/// against the null every cause must beat: the recording's own block-to-block variation,
/// a delete-one-block jackknife, judged last for the subset being judged, so that a pair
/// whose causes share the load fails it and the next subset, either cause alone, is judged).
std::string reject(const Judge& jd, const Subset& sub, ArmDiagnosis& d, std::vector<JackknifedCause>& jack) {
  const DiagnoseOptions& oj = jd.o.joint;
  const VectorXd e = heldout_error(jd.p, sub), e0 = heldout_error(jd.p, jd.none);
  if (jd.none.bic - sub.bic < oj.min_delta_bic) return "no arm-level cause (payload, link mass) with evidence on the training blocks";
  if (e.norm() > e0.norm() * (1.0 - oj.min_heldout_gain)) {
    return "the arm-level causes improved the training fit but not the held-out blocks: not claimed";
  }
  if (std::string why = causes_rejected(jd, sub, e, d); !why.empty()) return why;
  const auto before_joint = joint_rms(e0, jd.p.test), after_joint = joint_rms(e, jd.p.test);
  for (std::size_t j = 0; j < jd.p.js.size(); ++j) {
    // One cause explains every joint it loads: it must not make any joint worse.
    if (after_joint[j] > before_joint[j] * (1.0 + oj.min_heldout_gain)) {
      std::ostringstream why;
      why.precision(3);
      why << "the arm-level fit would worsen joint " << jd.p.js[j].joint << "'s held-out fit (" << before_joint[j] << " -> "
          << after_joint[j] << " N·m): not one cause, not claimed";
      return why.str();
    }
  }
  if (std::string why = payload_on_one_joint(jd, sub, before_joint, after_joint); !why.empty()) return why;
  const auto fit_shared = [&](const std::vector<const ArmCandidate*>& cs, const Stack& st) {
    return VectorXd(lsq(jd.p.design(cs, st), target(jd.p.js, st)));
  };
  jack = jackknife_causes(sub.cs, jd.p.n, oj.blocks, fit_shared, jd.p.all, jd.p.train.weight);
  for (std::size_t i = 0; i < sub.cs.size(); ++i) {
    if (jack[i].z >= oj.min_null_z) continue;
    std::ostringstream why;
    why.precision(3);
    why << cause_label(*sub.cs[i]) << " does not beat the recording's own block-to-block variation (jackknife z = " << jack[i].z
        << ", needs " << oj.min_null_z << "): not claimed";
    return why.str();
  }
  return {};
}

/// The first subset, best BIC first, that nothing rejects (empty: none); each reason a
/// subset was rejected kept in `d.notes` (up to 5, once each).
std::vector<const ArmCandidate*> select_causes(const Judge& jd, ArmDiagnosis& d, std::vector<JackknifedCause>& jack) {
  for (const auto& sub : jd.subsets) {
    if (jd.none.bic - sub.bic < jd.o.joint.min_delta_bic) break;
    const std::string why = reject(jd, sub, d, jack);
    if (jd.o.joint.trace) {
      std::fprintf(stderr, "  arm subset:");
      for (const auto* c : sub.cs) std::fprintf(stderr, " %s(pickup %.2f)", cause_label(*c).c_str(), c->pickup_s);
      std::fprintf(stderr, " dBIC %.1f %s\n", sub.bic - jd.none.bic, why.c_str());
    }
    if (why.empty()) return sub.cs;
    if (std::find(d.notes.begin(), d.notes.end(), why) == d.notes.end() && d.notes.size() < 5) d.notes.push_back(why);
  }
  if (d.notes.empty()) d.notes.push_back("no arm-level cause (payload, link mass) with evidence on the training blocks");
  return {};
}

/// A vector's three components as params `<before>x<after>`, `<before>y<after>`, `<before>z<after>`.
void put_xyz(Finding& f, const std::string& before, const std::string& after, const Eigen::Vector3d& v) {
  f.params[before + "x" + after] = v.x();
  f.params[before + "y" + after] = v.y();
  f.params[before + "z" + after] = v.z();
}

/// One chosen cause's parameters and sentence, from its coefficients on all samples: a
/// drive's scale error, or a mass `m` and first moment `h` (payload, a link's error).
Finding cause_finding(const ArmCandidate& c, double m, const Eigen::Vector3d& h, const JackknifedCause& jack, int last_joint) {
  Finding f;
  f.effect = c.effect;
  f.null_z = jack.z;
  std::ostringstream text;
  text.precision(3);
  if (c.effect == robot::Effect::torque_constant) {
    // tau_measured = (1 + k) tau_true (as the per-joint effect): true K_I = file's / (1 + k).
    f.params["joint"] = c.joint;
    f.params["scale_error"] = m;
    f.params["scale_error_sigma"] = jack.mass_sigma;
    f.params["torque_constant_ratio"] = 1.0 / (1.0 + m);
    text << "joint " << c.joint << "'s torque constant: the measured torque is " << 100.0 * m << " +/- " << 100.0 * jack.mass_sigma
         << " % off the robot file's (true K_I = file's x " << 1.0 / (1.0 + m) << ")";
  } else if (c.effect == robot::Effect::payload) {
    const Eigen::Vector3d com = h / m;
    f.params["link"] = c.link;
    f.params["mass_kg_sigma"] = jack.mass_sigma;
    f.params["mass_kg"] = m;
    put_xyz(f, "com_", "_m", com);
    put_xyz(f, "com_", "_m_sigma", jack.com_sigma);
    if (c.pickup_s >= 0.0) f.params["picked_up_at_s"] = c.pickup_s;
    text << "payload on the last link: " << m << " +/- " << jack.mass_sigma << " kg, centre of mass (" << com.x() << ", " << com.y()
         << ", " << com.z() << ") m in its frame";
    if (c.zeroed_columns > 0) {
      // The centred fit won the selection: its sideways offset is not resolved, not zero.
      f.params["centred_on_last_axis"] = 1.0;
      text << " (centred on joint " << last_joint << "'s axis: an offset across it does not beat the centred fit)";
    }
    if (c.pickup_s >= 0.0) text << ", picked up at t = " << c.pickup_s << " s";
  } else {
    f.params["link"] = c.link;
    f.params["mass_kg_sigma"] = jack.mass_sigma;
    f.params["delta_mass_kg"] = m;
    put_xyz(f, "delta_first_moment_", "_kg_m", h);
    text << "link " << c.link << "'s mass off by " << m << " kg, its first moment by (" << h.x() << ", " << h.y() << ", " << h.z()
         << ") kg·m";
  }
  f.text = text.str();
  return f;
}

/// The chosen causes fitted on all samples (nuisance alongside, not kept): their findings,
/// evidence (BIC increase when each is left out), the model for prediction and the torque
/// each explains per joint, strongest first.
void report_causes(const ArmProblem& p, const std::vector<const ArmCandidate*>& chosen, const std::vector<JackknifedCause>& jack,
                   const ArmDiagnosisOptions& o, ArmDiagnosis& d) {
  const auto& js = p.js;
  const VectorXd ya = target(js, p.all);
  const MatrixXd Xa = p.design(chosen, p.all);
  const VectorXd ba = lsq(Xa, ya);
  Eigen::Index at = 0;
  for (std::size_t ci = 0; ci < chosen.size(); ++ci) {
    const ArmCandidate& c = *chosen[ci];
    const auto np = static_cast<Eigen::Index>(c.columns.size());
    const Eigen::Vector3d h = np >= 4 ? Eigen::Vector3d(ba(at + 1), ba(at + 2), ba(at + 3)) : Eigen::Vector3d::Zero();
    Finding f = cause_finding(c, ba(at), h, jack[ci], js.back().joint);
    auto without = chosen;
    without.erase(without.begin() + static_cast<std::ptrdiff_t>(ci));
    const MatrixXd Xw = p.design(without, p.all);
    f.delta_bic = bic((ya - Xw * lsq(Xw, ya)).squaredNorm(), static_cast<std::size_t>(ya.size()), p.param_count(without)) -
                  bic((ya - Xa * ba).squaredNorm(), static_cast<std::size_t>(ya.size()), p.param_count(chosen));
    f.confidence = 1.0 / (1.0 + std::exp(-(f.delta_bic - o.joint.min_delta_bic) / 10.0));
    FittedEffect fe;
    fe.effect = c.effect;
    fe.setting[c.effect == robot::Effect::torque_constant ? "joint" : "link"] = c.effect == robot::Effect::torque_constant ? c.joint : c.link;
    if (c.pickup_s >= 0.0) fe.setting["picked_up_at_s"] = c.pickup_s;
    for (Eigen::Index i = 0; i < np; ++i) fe.coefficients.push_back(ba(at + i));
    std::ostringstream text;
    text.precision(3);
    text << "; torque it explains per joint (RMS):";
    for (std::size_t j = 0; j < js.size(); ++j) {
      double acc = 0.0;
      for (std::size_t k = 0; k < p.n; ++k) {
        double v = 0.0;
        for (Eigen::Index i = 0; i < np; ++i) v += ba(at + i) * c.columns[static_cast<std::size_t>(i)][j][k];
        d.explained[j][k] += v;
        acc += v * v;
      }
      const double r = std::sqrt(acc / static_cast<double>(p.n));
      f.params["torque_rms_joint" + std::to_string(js[j].joint)] = r;
      text << ' ' << r;
    }
    f.text += text.str() + " N·m";
    d.findings.push_back(f);
    d.model.push_back(fe);
    at += np;
  }
  for (std::size_t j = 0; j < js.size(); ++j) {
    double acc = 0.0;
    for (const double v : d.explained[j]) acc += v * v;
    d.explained_rms[j] = std::sqrt(acc / static_cast<double>(p.n));
  }
  std::sort(d.findings.begin(), d.findings.end(), [](const Finding& a, const Finding& b) { return a.delta_bic > b.delta_bic; });
}

/// Why the arm level is not fitted at all (empty: it is).
std::string arm_level_not_fitted(const std::vector<JointSignals>& js, const ArmDiagnosisOptions& o) {
  if (js.empty() || std::any_of(js.begin(), js.end(), [](const JointSignals& s) { return s.payload_columns.size() < 4; })) {
    return "no rigid-body model: arm-level causes (payload) not fitted";
  }
  const std::size_t n = js.front().size();
  if (n < 200 || std::any_of(js.begin(), js.end(), [n](const JointSignals& s) { return s.size() != n; })) {
    return "too few samples for the arm-level fit";
  }
  if (const std::string why = too_short_to_judge(js.front().t, o.joint); !why.empty()) return "arm: " + why;
  return {};
}

}  // namespace

ArmDiagnosis diagnose_arm(const std::vector<JointSignals>& js, const ArmDiagnosisOptions& o, const sim::ArmDynamics* arm) {
  ArmDiagnosis d;
  d.explained.assign(js.size(), {});
  d.explained_rms.assign(js.size(), 0.0);
  for (std::size_t j = 0; j < js.size(); ++j) d.explained[j].assign(js[j].size(), 0.0);
  if (const std::string why = arm_level_not_fitted(js, o); !why.empty()) {
    d.notes.push_back(why);
    return d;
  }
  const ArmProblem p = arm_problem(js, o.joint);
  const auto groups = separable_groups(candidate_groups(js, o, arm), p, o, d.notes);
  Subset none;
  fit_subset(p, none);
  const std::vector<Subset> subsets = scored_subsets(groups, o.max_causes, p);
  const Judge jd{p, o, arm, payload_bound(o, arm), none, subsets};
  std::vector<JackknifedCause> jack;
  const auto chosen = select_causes(jd, d, jack);
  if (!chosen.empty()) report_causes(p, chosen, jack, o, d);
  return d;
}

std::vector<std::vector<double>> predict_arm_causes(const std::vector<FittedEffect>& model,
                                                   const std::vector<JointSignals>& js, const sim::ArmDynamics* arm) {
  std::vector<std::vector<double>> out(js.size());
  for (std::size_t j = 0; j < js.size(); ++j) out[j].assign(js[j].size(), 0.0);
  for (const auto& m : model) {
    const auto at = [&](const char* key, double fallback) {
      const auto it = m.setting.find(key);
      return it == m.setting.end() ? fallback : it->second;
    };
    ArmCandidate c;
    if (m.effect == robot::Effect::payload) {
      for (const auto& s : js) {
        if (s.payload_columns.size() < 4) throw std::invalid_argument("a payload cannot be predicted without the model's payload columns");
      }
      const auto cs = payload_candidates(js, false);
      c = cs.front();
      // A payload carried throughout has no step (as payload_candidates: pickup_s < 0).
      const double pickup_s = at("picked_up_at_s", -1.0);
      for (auto& per_joint : c.columns) {
        if (pickup_s < 0.0) break;
        for (std::size_t j = 0; j < js.size(); ++j) {
          for (std::size_t k = 0; k < per_joint[j].size(); ++k) per_joint[j][k] = js[j].t[k] >= pickup_s ? per_joint[j][k] : 0.0;
        }
      }
    } else if (m.effect == robot::Effect::torque_constant) {
      const auto joint = static_cast<int>(at("joint", 0.0));
      const auto it = std::find_if(js.begin(), js.end(), [&](const JointSignals& s) { return s.joint == joint; });
      if (it == js.end()) throw std::invalid_argument("torque_constant: no joint " + std::to_string(joint) + " in the signals");
      c = torque_constant_candidate(js, static_cast<std::size_t>(it - js.begin()));
    } else if (m.effect == robot::Effect::link_inertial_error) {
      if (arm == nullptr) throw std::invalid_argument("a link's mass error cannot be predicted without the arm's model");
      c = link_candidate(js, *arm, static_cast<int>(at("link", 1.0)) - 1);
    } else {
      throw std::invalid_argument("arm-level effect '" + m.effect + "' cannot be predicted");
    }
    if (c.columns.size() != m.coefficients.size()) {
      throw std::invalid_argument("arm-level effect '" + m.effect + "': " + std::to_string(m.coefficients.size()) +
                                  " coefficients for " + std::to_string(c.columns.size()) + " columns");
    }
    for (std::size_t i = 0; i < c.columns.size(); ++i) {
      for (std::size_t j = 0; j < js.size(); ++j) {
        for (std::size_t k = 0; k < out[j].size(); ++k) out[j][k] += m.coefficients[i] * c.columns[i][j][k];
      }
    }
  }
  return out;
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
