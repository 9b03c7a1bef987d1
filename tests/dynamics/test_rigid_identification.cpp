// Whole-arm rigid-body identification (host_sim/dynamics/): the regressor equals the
// inverse dynamics, the acceleration filter, physical consistency, the robot writer, and
// recovery of a changed link mass plus a payload on a simulated recording.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

#include "arm_identification/base_parameters.hpp"
#include "arm_identification/constrained_fit.hpp"
#include "arm_identification/physical_consistency.hpp"
#include "arm_identification/rigid_body_identification.hpp"
#include "dynamics/acceleration.hpp"
#include "dynamics/regressor.hpp"
#include "dynamics/uniform_grid.hpp"
#include "robot/robot_model.hpp"
#include "robot/robot_writer.hpp"
#include "sim/scenario.hpp"
#include "sim/simulation.hpp"

using namespace jg;

namespace {

const std::string kSource = JG_SOURCE_DIR;

sim::ArmDynamics arm_of(const robot::RobotModel& m) {
  return sim::ArmDynamics(m.plant_links(), Eigen::Vector3d(m.gravity[0], m.gravity[1], m.gravity[2]));
}

sim::JointVector random_vector(std::mt19937_64& rng, int n, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  sim::JointVector v(n);
  for (int i = 0; i < n; ++i) v(i) = u(rng);
  return v;
}

}  // namespace

TEST(Regressor, EqualsInverseDynamics) {
  for (const char* file : {"/models/ref3.yaml", "/models/panda.yaml"}) {
    const auto model = robot::load_robot(kSource + file);
    const sim::ArmDynamics arm = arm_of(model);
    const int n = arm.joints();
    const Eigen::VectorXd pi = dyn::arm_params(arm);
    std::mt19937_64 rng(3);
    for (int trial = 0; trial < 50; ++trial) {
      const auto q = random_vector(rng, n, 3.0), qd = random_vector(rng, n, 2.0), qdd = random_vector(rng, n, 5.0);
      const Eigen::MatrixXd Y = dyn::link_regressor(arm, q, qd, qdd);
      ASSERT_EQ(Y.cols(), dyn::kLinkParams * n);
      Eigen::VectorXd tau = Y * pi;
      for (int j = 0; j < n; ++j) tau(j) += arm.link(j).rotor_inertia * qdd(j);  // the rotor column
      const sim::JointVector ref = arm.inverse_dynamics(q, qd, qdd);
      for (int j = 0; j < n; ++j) EXPECT_NEAR(tau(j), ref(j), 1e-10 * (1.0 + std::abs(ref(j)))) << file << " joint " << j;
    }
  }
}

TEST(Regressor, ParameterRoundTrip) {
  const auto model = robot::load_robot(kSource + "/models/panda.yaml");
  for (const auto& l : model.plant_links()) {
    const sim::PlantLink back = dyn::with_params(l, dyn::link_params(l));
    EXPECT_NEAR(back.mass, l.mass, 1e-14);
    EXPECT_LT((back.com - l.com).norm(), 1e-14);
    EXPECT_LT((back.inertia_com - l.inertia_com).norm(), 1e-14);
  }
}

TEST(BaseParameters, CountsIdentifiableCombinations) {
  // One horizontal-axis link: only m c_x, m c_y and I_zz (about the origin) act on its
  // torque; its mass alone and the other inertias do not.
  robot::RobotModel m = robot::load_robot(kSource + "/models/ref3.yaml");
  m.joints.resize(1);
  m.joints[0].link.alpha_prev = 1.5707963267948966;
  const sim::ArmDynamics arm = arm_of(m);
  std::mt19937_64 rng(5);
  Eigen::MatrixXd W(200, dyn::kLinkParams);
  for (int k = 0; k < 200; ++k) {
    W.row(k) = dyn::link_regressor(arm, random_vector(rng, 1, 3.0), random_vector(rng, 1, 2.0), random_vector(rng, 1, 5.0));
  }
  EXPECT_EQ(dyn::base_parameters(W, Eigen::VectorXd::Ones(dyn::kLinkParams)).rank, 3);
}

TEST(Acceleration, GaussianDerivativeOfASine) {
  const double dt = 1e-3, f = 0.5, w = 2.0 * M_PI * f;
  std::vector<double> x(4000);
  for (std::size_t k = 0; k < x.size(); ++k) x[k] = std::sin(w * static_cast<double>(k) * dt);
  const double sigma = 0.02;
  const auto d = dyn::smooth_derivative(x, dt, sigma);
  // Interior: the Gaussian's gain exp(-(w sigma)^2 / 2) on the exact derivative, no phase.
  const double gain = std::exp(-0.5 * w * w * sigma * sigma);
  for (std::size_t k = 200; k < 3800; k += 97) EXPECT_NEAR(d[k], gain * w * std::cos(w * static_cast<double>(k) * dt), 1e-4);
  // Ends: the local line fit stays close (no edge collapse).
  EXPECT_NEAR(d[0], w, 0.05 * w);
  // A linear ramp is differentiated exactly everywhere, ends included.
  std::vector<double> r(500);
  for (std::size_t k = 0; k < r.size(); ++k) r[k] = 2.0 + 3.0 * static_cast<double>(k) * dt;
  for (double v : dyn::smooth_derivative(r, dt, 0.03)) EXPECT_NEAR(v, 3.0, 1e-9);
}

TEST(Acceleration, WidthFollowsTheSignalBand) {
  // Slow motion with white noise: a wide filter; faster motion: a narrower one.
  const double dt = 1e-3;
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 0.01);
  auto series = [&](double f) {
    std::vector<double> v(20000);
    for (std::size_t k = 0; k < v.size(); ++k) v[k] = std::sin(2.0 * M_PI * f * static_cast<double>(k) * dt) + noise(rng);
    return v;
  };
  const auto slow = dyn::choose_sigma_detail({series(0.3)}, dt);
  const auto fast = dyn::choose_sigma_detail({series(3.0)}, dt);
  EXPECT_GT(slow.sigma_s, fast.sigma_s * 3.0);
  EXPECT_GT(fast.cutoff_hz, 3.0);
  EXPECT_LT(fast.cutoff_hz, 30.0);
  // The chosen filter passes the motion itself nearly unchanged.
  EXPECT_LT(2.0 * M_PI * 3.0 * fast.sigma_s, 0.5);
}

TEST(PhysicalConsistency, RejectsAndSteps) {
  const auto model = robot::load_robot(kSource + "/models/ref3.yaml");
  const sim::PlantLink l = model.plant_links()[1];
  dyn::LinkBounds b;
  b.com_radius_m = 0.5;
  const dyn::LinkParams p = dyn::link_params(l);
  EXPECT_TRUE(dyn::check_link(p, b).ok);
  sim::PlantLink bad = l;
  bad.inertia_com(0, 0) = bad.inertia_com(1, 1) + bad.inertia_com(2, 2) + 0.01;  // triangle inequality broken
  const dyn::LinkParams pb = dyn::link_params(bad);
  EXPECT_FALSE(dyn::check_link(pb, b).ok);
  const double s = dyn::feasible_step(p, pb, b);
  EXPECT_GT(s, 0.0);
  EXPECT_LT(s, 1.0);
  EXPECT_TRUE(dyn::check_link(p + s * (pb - p), b).ok);
  EXPECT_FALSE(dyn::check_link(p + std::min(1.0, s + 1e-6) * (pb - p), b).ok);
  dyn::LinkParams far = p;
  far.segment<3>(1) *= 10.0;  // CoM 2 m away
  EXPECT_FALSE(dyn::check_link(far, b).ok);
  dyn::LinkParams neg = p;
  neg(0) = -1.0;
  EXPECT_FALSE(dyn::check_link(neg, b).ok);
}

TEST(ConstrainedFit, NearestFeasiblePointBeatsTheLineSearch) {
  // Minimise |x - target|^2 (scaled) for one link whose target breaks the triangle
  // inequality and puts the CoM outside its sphere: the barrier's optimum must be feasible,
  // on the boundary, and no farther than the line-search point from the prior.
  const auto model = robot::load_robot(kSource + "/models/ref3.yaml");
  const sim::PlantLink l = model.plant_links()[1];
  dyn::LinkBounds b;
  b.com_radius_m = 0.3;
  const dyn::LinkParams p0 = dyn::link_params(l);
  dyn::LinkParams target = p0;
  target(4) += 0.2;                 // I_xx far above I_yy + I_zz
  target.segment<3>(1) *= 1.8;      // CoM 0.36 m out
  ASSERT_FALSE(dyn::check_link(target, b).ok);
  ASSERT_TRUE(dyn::strictly_feasible(p0, b));
  Eigen::VectorXd w(dyn::kLinkParams);
  w << 1.0, 10.0, 10.0, 10.0, 100.0, 100.0, 100.0, 100.0, 100.0, 100.0;  // per-unit scaling
  const Eigen::MatrixXd Q = w.cwiseProduct(w).asDiagonal();
  const Eigen::VectorXd c = Q * target;
  const auto r = dyn::constrained_minimize(Q, c, p0, std::vector<bool>(dyn::kLinkParams, true), {{0, b}}, {});
  EXPECT_TRUE(r.converged);
  const dyn::LinkParams x = r.x;
  EXPECT_TRUE(dyn::check_link(x, b).ok) << dyn::check_link(x, b).reason;
  const auto cost = [&](const dyn::LinkParams& v) { return (w.cwiseProduct(v - target)).squaredNorm(); };
  const double s = dyn::feasible_step(p0, target, b);
  EXPECT_LT(cost(x), cost(p0 + s * (target - p0)));
  // On the boundary: a small step towards the target leaves the feasible set.
  EXPECT_FALSE(dyn::check_link(x + 0.01 * (target - x), b).ok);
}

TEST(RobotWriter, WritesWhatTheReaderReadsBack) {
  for (const char* file : {"/models/ref3.yaml", "/models/panda.yaml"}) {
    robot::RobotModel m = robot::load_robot(kSource + file);
    m.joints[0].link.inertia_com[3] = -1.234567890123e-3;  // an off-diagonal entry, full precision
    const std::string out = (std::filesystem::temp_directory_path() / "jg_writer_roundtrip.yaml").string();
    robot::write_robot(out, m, "round trip\nsecond line");
    const robot::RobotModel r = robot::load_robot(out);
    std::filesystem::remove(out);
    ASSERT_EQ(r.joints.size(), m.joints.size());
    EXPECT_EQ(r.name, m.name);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(r.gravity[k], m.gravity[k], 1e-12);
    for (std::size_t j = 0; j < m.joints.size(); ++j) {
      const auto &a = m.joints[j], &c = r.joints[j];
      EXPECT_EQ(a.name, c.name);
      const double va[] = {a.link.a_prev, a.link.alpha_prev, a.link.d, a.link.theta_offset, a.link.mass,
                           a.link.com[0], a.link.com[1], a.link.com[2], a.link.inertia_com[0], a.link.inertia_com[1],
                           a.link.inertia_com[2], a.link.inertia_com[3], a.link.inertia_com[4], a.link.inertia_com[5],
                           a.link.rotor_inertia, a.link.torque_constant, a.link.current_limit, a.gear_ratio,
                           a.lower_rad, a.upper_rad, a.reach_m};
      const double vc[] = {c.link.a_prev, c.link.alpha_prev, c.link.d, c.link.theta_offset, c.link.mass,
                           c.link.com[0], c.link.com[1], c.link.com[2], c.link.inertia_com[0], c.link.inertia_com[1],
                           c.link.inertia_com[2], c.link.inertia_com[3], c.link.inertia_com[4], c.link.inertia_com[5],
                           c.link.rotor_inertia, c.link.torque_constant, c.link.current_limit, c.gear_ratio,
                           c.lower_rad, c.upper_rad, c.reach_m};
      for (std::size_t k = 0; k < std::size(va); ++k) EXPECT_NEAR(va[k], vc[k], 1e-12) << file << " joint " << j << " field " << k;
    }
  }
}

TEST(RobotWriter, FrictionBaselineReadsBackAndABadOneIsRefusedNamingTheField) {
  robot::RobotModel m = robot::load_robot(kSource + "/models/ref3.yaml");
  ASSERT_TRUE(m.friction_baseline.empty());
  for (std::size_t j = 0; j < m.joints.size(); ++j) {
    const double k = static_cast<double>(j) + 1.0;
    m.friction_baseline.push_back({0.5 * k, 0.4 * k, -0.1 * k, 0.01 * k, 0.003});
  }
  const std::string out = (std::filesystem::temp_directory_path() / "jg_writer_baseline.yaml").string();
  robot::write_robot(out, m, "baseline");
  const robot::RobotModel r = robot::load_robot(out);
  ASSERT_EQ(r.friction_baseline.size(), m.joints.size());
  for (std::size_t j = 0; j < m.joints.size(); ++j) {
    const auto &a = m.friction_baseline[j], &c = r.friction_baseline[j];
    EXPECT_DOUBLE_EQ(a.coulomb_pos_nm, c.coulomb_pos_nm);
    EXPECT_DOUBLE_EQ(a.coulomb_neg_nm, c.coulomb_neg_nm);
    EXPECT_DOUBLE_EQ(a.viscous_nms_rad, c.viscous_nms_rad);
    EXPECT_DOUBLE_EQ(a.offset_nm, c.offset_nm);
    EXPECT_DOUBLE_EQ(a.eps_rad_s, c.eps_rad_s);
  }
  // One entry per joint, and a tanh scale > 0: else refused, naming the field.
  const auto refused = [&](const robot::RobotModel& bad, const std::string& field) {
    robot::write_robot(out, bad, "bad baseline");
    try {
      (void)robot::load_robot(out);
      ADD_FAILURE() << "accepted a friction_baseline that should name " << field;
    } catch (const io::FormatError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  robot::RobotModel short_list = m;
  short_list.friction_baseline.pop_back();
  refused(short_list, "friction_baseline");
  robot::RobotModel zero_eps = m;
  zero_eps.friction_baseline[1].eps_rad_s = 0.0;
  refused(zero_eps, "eps_rad_s");
  std::filesystem::remove(out);
}

TEST(RobotWriter, FailureLeavesNothing) {
  const auto m = robot::load_robot(kSource + "/models/ref3.yaml");
  const std::string out = "/nonexistent_dir_jg/model.yaml";
  EXPECT_THROW(robot::write_robot(out, m), io::FormatError);
  EXPECT_FALSE(std::filesystem::exists(out));
}

namespace {

/// Every joint on its own sum of sines (distinct frequencies), from rest at q0.
class MultiSine final : public sim::Trajectory {
 public:
  MultiSine(sim::JointVector q0, double duration) : q0_(std::move(q0)), duration_(duration) {}
  [[nodiscard]] sim::TrajectorySample at(double t) const override {
    const int n = joints();
    sim::TrajectorySample s;
    s.q = q0_;
    s.dq = sim::JointVector::Zero(n);
    s.ddq = sim::JointVector::Zero(n);
    for (int j = 0; j < n; ++j) {
      for (int h = 0; h < 3; ++h) {
        const double w = 2.0 * M_PI * (0.11 + 0.07 * j + 0.19 * h), a = 0.35 / (1.0 + h);
        // a (1 - cos) starts at rest.
        s.q(j) += a * (1.0 - std::cos(w * t));
        s.dq(j) += a * w * std::sin(w * t);
        s.ddq(j) += a * w * w * std::cos(w * t);
      }
    }
    return s;
  }
  [[nodiscard]] double duration() const override { return duration_; }
  [[nodiscard]] int joints() const override { return static_cast<int>(q0_.size()); }

 private:
  sim::JointVector q0_;
  double duration_;
};

}  // namespace

TEST(RigidBodyIdentification, RecoversLinkMassAndPayload) {
  const std::string model_path = kSource + "/models/ref3.yaml";
  const robot::RobotModel prior = robot::load_robot(model_path);
  sim::Scenario sc = sim::load_scenario(kSource + "/scenarios/free_motion.yaml");
  sim::SimulationSetup& st = sc.setup;
  sim::JointVector q0(3);
  q0 << -0.6, 0.1, -1.6;
  st.trajectory = std::make_shared<MultiSine>(q0, 60.0);
  st.duration_s = 60.0;
  st.nominal_links = prior.plant_links();
  // Truth: link 2 (shoulder) 20 % heavier (same shape: inertia scales too) and a 1.5 kg
  // payload (a 6 cm cube) fixed to the last link.
  auto& links = st.plant.links;
  links[1].mass *= 1.2;
  links[1].inertia_com *= 1.2;
  const double mp = 1.5;
  const Eigen::Vector3d cp(0.32, 0.02, 0.03);
  const Eigen::Matrix3d Ip = Eigen::Matrix3d::Identity() * mp * 0.06 * 0.06 / 6.0;
  {
    dyn::LinkParams p3 = dyn::link_params(links[2]);
    sim::PlantLink payload;
    payload.mass = mp;
    payload.com = cp;
    payload.inertia_com = Ip;
    p3 += dyn::link_params(payload);
    links[2] = dyn::with_params(links[2], p3);
  }
  // Friction without a Stribeck dip: Coulomb + viscous (+ bristles), as the model assumes.
  for (auto& f : st.plant.friction) f.lugre.tau_s = f.lugre.tau_c;
  const io::Recording rec = sim::run_simulation(st).recording;
  ASSERT_GT(rec.samples(), 50000u);

  dyn::RigidBodyIdOptions opt;
  opt.joint_torque_sensor = false;
  const dyn::RigidBodyIdResult r = dyn::identify_rigid_body(rec, prior, opt);
  const double noise = 0.01 * 12.0;  // current noise x K_I [N·m]
  std::printf("base parameters %d of %d, sigma %.1f ms, step %.3f\n", r.base_parameters, r.free_parameters,
              r.acceleration.sigma_s * 1e3, r.feasibility_step);
  for (std::size_t j = 0; j < 3; ++j) {
    std::printf("joint %zu held-out RMS: prior rigid %.3f, prior+friction %.3f, identified %.3f (noise %.3f); moving rows: %.3f -> %.3f\n", j + 1,
                r.heldout_rms_prior_rigid[j], r.heldout_rms_prior[j], r.heldout_rms_after[j], noise, r.heldout_moving_rms_prior[j], r.heldout_moving_rms_after[j]);
    // Rows where the joint moves (the truth's LuGre friction sticks near zero speed, which
    // no function of the state predicts): near the noise floor.
    EXPECT_LT(r.heldout_moving_rms_after[j], 2.5 * noise) << "joint " << j + 1;
    // All held-out rows: far below the prior rigid body's.
    EXPECT_LT(3.0 * r.heldout_rms_after[j], r.heldout_rms_prior_rigid[j]) << "joint " << j + 1;
  }
  // The joints that carry the changed mass and the payload: >= 3x below the prior with its
  // friction re-fitted.
  for (std::size_t j = 1; j < 3; ++j) EXPECT_LT(3.0 * r.heldout_moving_rms_after[j], r.heldout_moving_rms_prior[j]);
  for (std::size_t i = 0; i < r.links.size(); ++i) EXPECT_TRUE(r.links[i].consistency.ok) << r.links[i].consistency.reason;
  EXPECT_TRUE(r.accepted);
  std::printf("payload %.3f kg at (%.3f %.3f %.3f) claimed %d %s\n", r.payload.mass, r.payload.com.x(), r.payload.com.y(),
              r.payload.com.z(), r.payload.claimed ? 1 : 0, r.payload.reason.c_str());
  for (const auto& n : r.notes) std::printf("note: %s\n", n.c_str());
  // The identified robot file predicts the truth's torques: compare with the truth's own
  // inverse dynamics over the motion (no noise, no friction).
  const sim::ArmDynamics truth(links), ident = arm_of(r.model);
  double se = 0.0, se_prior = 0.0;
  const sim::ArmDynamics prior_arm = arm_of(prior);
  long cnt = 0;
  for (double t = 1.0; t < 59.0; t += 0.05) {
    const auto s = st.trajectory->at(t);
    const auto a = truth.inverse_dynamics(s.q, s.dq, s.ddq);
    se += (ident.inverse_dynamics(s.q, s.dq, s.ddq) - a).squaredNorm();
    se_prior += (prior_arm.inverse_dynamics(s.q, s.dq, s.ddq) - a).squaredNorm();
    ++cnt;
  }
  std::printf("rigid-body torque error vs truth: identified %.3f, prior %.3f N·m RMS\n", std::sqrt(se / (3.0 * cnt)),
              std::sqrt(se_prior / (3.0 * cnt)));
  EXPECT_LT(std::sqrt(se / (3.0 * cnt)), 0.01 * std::sqrt(se_prior / (3.0 * cnt)));
  // Link 3's own mass is not separable from link 2's first moment on this arm (only
  // m c_x2 + a_2 m_3 acts), so the payload's mass is not claimed unless the split lands
  // inside the bound; its first moment (the identifiable part) must be right.
  const double first_moment = r.payload.mass * r.payload.com.x();
  EXPECT_NEAR(first_moment, mp * cp.x(), 0.05 * mp * cp.x());
}

TEST(RigidBodyIdentification, PayloadOnlyRecoversThePayload) {
  const robot::RobotModel prior = robot::load_robot(kSource + "/models/ref3.yaml");
  sim::Scenario sc = sim::load_scenario(kSource + "/scenarios/free_motion.yaml");
  sim::SimulationSetup& st = sc.setup;
  sim::JointVector q0(3);
  q0 << -0.6, 0.1, -1.6;
  st.trajectory = std::make_shared<MultiSine>(q0, 40.0);
  st.duration_s = 40.0;
  st.nominal_links = prior.plant_links();
  const double mp = 1.5;
  const Eigen::Vector3d cp(0.30, -0.02, 0.04);
  {
    sim::PlantLink payload;
    payload.mass = mp;
    payload.com = cp;
    payload.inertia_com = Eigen::Matrix3d::Identity() * 1e-3;
    dyn::LinkParams p3 = dyn::link_params(st.plant.links[2]) + dyn::link_params(payload);
    st.plant.links[2] = dyn::with_params(st.plant.links[2], p3);
  }
  for (auto& f : st.plant.friction) f.lugre.tau_s = f.lugre.tau_c;
  const io::Recording rec = sim::run_simulation(st).recording;
  dyn::RigidBodyIdOptions opt;
  opt.payload_only = true;
  const dyn::RigidBodyIdResult r = dyn::identify_rigid_body(rec, prior, opt);
  std::printf("payload-only: %.3f kg at (%.3f %.3f %.3f), claimed %d\n", r.payload.mass, r.payload.com.x(),
              r.payload.com.y(), r.payload.com.z(), r.payload.claimed ? 1 : 0);
  EXPECT_EQ(r.free_parameters, dyn::kLinkParams);
  EXPECT_TRUE(r.payload.claimed) << r.payload.reason;
  EXPECT_NEAR(r.payload.mass, mp, 0.05 * mp);
  EXPECT_LT((r.payload.com - cp).norm(), 0.03);
  // The arm before the last link is untouched.
  for (std::size_t i = 0; i + 1 < prior.joints.size(); ++i) EXPECT_EQ(r.model.joints[i].link.mass, prior.joints[i].link.mass);
}

TEST(UniformGrid, DropsRepeatsAndInterpolatesByTime) {
  io::Recording rec;
  rec.resize(1, 6, false, true, false, false);
  const double t[] = {0.0, 0.001, 0.001, 0.0035, 0.004, 0.005};
  const double q[] = {0.0, 1.0, 1.0, 3.5, 4.0, 5.0};
  for (int k = 0; k < 6; ++k) {
    rec.t[static_cast<std::size_t>(k)] = t[k];
    rec.q[0][static_cast<std::size_t>(k)] = q[k];
    rec.dq[0][static_cast<std::size_t>(k)] = 1000.0;
    rec.tau_m[0][static_cast<std::size_t>(k)] = 2.0 * q[k];
  }
  rec.dq[0][3] = 999.0;  // distinct state
  std::string note;
  const io::Recording u = dyn::to_uniform_grid(rec, 0.001, &note);
  ASSERT_EQ(u.samples(), 6u);
  EXPECT_TRUE(dyn::is_uniform(u));
  for (std::size_t k = 0; k < u.samples(); ++k) {
    EXPECT_NEAR(u.q[0][k], static_cast<double>(k), 1e-12);
    EXPECT_NEAR(u.tau_m[0][k], 2.0 * static_cast<double>(k), 1e-12);
  }
  EXPECT_NE(note.find("1 repeated"), std::string::npos) << note;
}

TEST(RigidBodyIdentification, RealPandaBeatsThePublishedModel) {
  const std::string file = kSource + "/../shared/data/real/panda-excitation/panda_excitation.csv";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << "real data not found: " << file;
  const robot::RobotModel prior = robot::load_robot(kSource + "/models/panda.yaml");
  const io::Recording raw = io::read_recording(file);
  std::string note;
  const io::Recording rec = dyn::to_uniform_grid(raw, 0.001, &note);
  dyn::RigidBodyIdOptions opt;
  opt.joint_torque_sensor = true;
  const dyn::RigidBodyIdResult r = dyn::identify_rigid_body(rec, prior, opt);
  std::printf("%s\nbase parameters %d of %d, sigma %.1f ms (band %.2f Hz), step %.3f\n", note.c_str(), r.base_parameters,
              r.free_parameters, r.acceleration.sigma_s * 1e3, r.acceleration.cutoff_hz, r.feasibility_step);
  const double published[] = {0.342, 0.847, 0.300, 0.456, 0.153, 0.129, 0.061};
  for (std::size_t j = 0; j < 7; ++j) {
    std::printf("J%zu held-out RMS: prior rigid %.3f, prior+friction %.3f, identified %.3f (published %.3f)\n", j + 1,
                r.heldout_rms_prior_rigid[j], r.heldout_rms_prior[j], r.heldout_rms_after[j], published[j]);
    EXPECT_LT(r.heldout_rms_after[j], published[j]) << "J" << j + 1;
    EXPECT_TRUE(r.links[j].consistency.ok) << r.links[j].consistency.reason;
  }
  for (const auto& n : r.notes) std::printf("note: %s\n", n.c_str());
}
