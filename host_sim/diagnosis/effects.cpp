#include "diagnosis/effects.hpp"

#include <cmath>
#include <sstream>

namespace jg::diag {
namespace {
// Velocity sign with a small linear band so that noise around zero does not toggle it.
double soft_sign(double w, double band) { return std::fabs(w) >= band ? (w > 0.0 ? 1.0 : -1.0) : w / band; }

double velocity_band(const JointSignals& s) {
  double vmax = 0.0;
  for (const double w : s.dq) vmax = std::max(vmax, std::fabs(w));
  return std::max(1e-4, 0.005 * vmax);
}

std::vector<double> column(std::size_t n) { return std::vector<double>(n, 0.0); }
}  // namespace

std::vector<std::vector<Candidate>> build_candidates(const JointSignals& s) {
  const std::size_t n = s.size();
  const double band = velocity_band(s);
  std::vector<double> sgn(n);
  for (std::size_t k = 0; k < n; ++k) sgn[k] = soft_sign(s.dq[k], band);
  std::vector<std::vector<Candidate>> all;

  auto single = [&](const std::string& name, std::vector<double> col) {
    Candidate c;
    c.effect = name;
    c.columns.push_back(std::move(col));
    all.push_back({std::move(c)});
  };
  single("coulomb", sgn);
  single("viscous", s.dq);
  {  // stribeck: extra friction near zero velocity, decaying with w_s
    std::vector<Candidate> v;
    for (const double ws : {0.003, 0.006, 0.01, 0.02, 0.04, 0.07, 0.1, 0.15, 0.25, 0.4}) {
      Candidate c;
      c.effect = "stribeck";
      c.setting["w_s"] = ws;
      c.nonlinear_params = 1;
      auto col = column(n);
      for (std::size_t k = 0; k < n; ++k) col[k] = sgn[k] * std::exp(-(s.dq[k] / ws) * (s.dq[k] / ws));
      c.columns.push_back(std::move(col));
      v.push_back(std::move(c));
    }
    all.push_back(std::move(v));
  }
  {  // presliding: the bristles' smooth transition after a reversal (Dahl state minus sign)
    std::vector<Candidate> v;
    for (const double delta : {2e-5, 5e-5, 1e-4, 2e-4, 5e-4, 1e-3, 2e-3, 5e-3, 1e-2}) {
      Candidate c;
      c.effect = "presliding";
      c.setting["displacement_rad"] = delta;
      c.nonlinear_params = 1;
      auto col = column(n);
      double zeta = 0.0;
      for (std::size_t k = 0; k < n; ++k) {
        const double dx = s.dq[k] * s.dt;
        const double dir = dx > 0.0 ? 1.0 : (dx < 0.0 ? -1.0 : 0.0);
        if (dir != 0.0) zeta = dir + (zeta - dir) * std::exp(-std::fabs(dx) / delta);
        col[k] = zeta - sgn[k];
      }
      c.columns.push_back(std::move(col));
      v.push_back(std::move(c));
    }
    all.push_back(std::move(v));
  }
  {  // asymmetric friction: a level present while moving, either way
    auto col = column(n);
    for (std::size_t k = 0; k < n; ++k) col[k] = std::fabs(sgn[k]);
    single("asymmetric_friction", std::move(col));
  }
  {  // position ripple: sin/cos of k q for k periods per revolution
    std::vector<Candidate> v;
    for (int per_rev = 1; per_rev <= 200; ++per_rev) {
      Candidate c;
      c.effect = "position_ripple";
      c.setting["periods_per_rev"] = per_rev;
      c.nonlinear_params = 1;
      auto cs = column(n), sn = column(n);
      for (std::size_t k = 0; k < n; ++k) {
        sn[k] = std::sin(per_rev * s.q[k]);
        cs[k] = std::cos(per_rev * s.q[k]);
      }
      c.columns = {std::move(sn), std::move(cs)};
      v.push_back(std::move(c));
    }
    all.push_back(std::move(v));
  }
  {  // temperature drift: friction level changing with time (warm-up) or linearly
    std::vector<Candidate> v;
    const double span = s.t.back() - s.t.front();
    for (const double tau : {0.1, 0.25, 0.5, 1.0, 3.0}) {  // time constants as fractions of the span
      Candidate c;
      c.effect = "temperature_drift";
      c.setting["time_constant_s"] = tau * span;
      c.nonlinear_params = 1;
      auto col = column(n);
      for (std::size_t k = 0; k < n; ++k) col[k] = sgn[k] * (1.0 - std::exp(-(s.t[k] - s.t.front()) / (tau * span)));
      c.columns.push_back(std::move(col));
      v.push_back(std::move(c));
    }
    all.push_back(std::move(v));
  }
  if (!s.load.empty()) {
    auto col = column(n);
    for (std::size_t k = 0; k < n; ++k) col[k] = sgn[k] * std::fabs(s.load[k]);
    single("load_dependent_friction", std::move(col));
  }
  if (!s.payload_columns.empty()) {
    Candidate c;
    c.effect = "payload";
    c.columns = s.payload_columns;
    all.push_back({std::move(c)});
  }
  single("inertia_error", s.ddq);
  single("torque_constant", s.tau_real);
  single("current_offset", std::vector<double>(n, 1.0));
  single("time_delay", derivative(s.tau_model, s.dt));
  if (!s.load.empty()) {  // backlash: after a reversal the link is not driven until the gap closes
    std::vector<Candidate> v;
    for (const double gap : {0.0005, 0.001, 0.002, 0.004, 0.008, 0.016}) {
      Candidate c;
      c.effect = "backlash";
      c.setting["gap_rad"] = gap;
      c.nonlinear_params = 1;
      auto col = column(n);
      double travelled = 1e9, last_dir = 0.0;
      for (std::size_t k = 0; k < n; ++k) {
        const double dir = s.dq[k] > band ? 1.0 : (s.dq[k] < -band ? -1.0 : last_dir);
        if (dir != last_dir && last_dir != 0.0) travelled = 0.0;
        last_dir = dir;
        travelled += std::fabs(s.dq[k]) * s.dt;
        col[k] = travelled < gap ? -s.load[k] : 0.0;
      }
      c.columns.push_back(std::move(col));
      v.push_back(std::move(c));
    }
    all.push_back(std::move(v));
  }
  return all;
}

std::map<std::string, double> describe(const Candidate& c, const std::vector<double>& b, const JointSignals& s,
                                       std::string& text) {
  std::ostringstream os;
  os.precision(3);
  std::map<std::string, double> p;
  const std::string& e = c.effect;
  if (e == "coulomb") {
    p["delta_tau_c"] = b[0];
    os << "Coulomb friction level off by " << b[0] << " N·m";
  } else if (e == "viscous") {
    p["delta_sigma2"] = b[0];
    os << "viscous friction off by " << b[0] << " N·m·s/rad";
  } else if (e == "stribeck") {
    p["amplitude"] = b[0];
    p["w_s"] = c.setting.at("w_s");
    os << "Stribeck effect missing: " << b[0] << " N·m extra friction at low speed, w_s " << p["w_s"] << " rad/s";
  } else if (e == "presliding") {
    p["level"] = -b[0];
    p["displacement_rad"] = c.setting.at("displacement_rad");
    p["sigma0"] = std::fabs(b[0]) / p["displacement_rad"];
    os << "presliding (bristle) dynamics missing: friction builds up over " << p["displacement_rad"]
       << " rad after each reversal (stiffness ~" << p["sigma0"] << " N·m/rad)";
  } else if (e == "asymmetric_friction") {
    p["tau_c_positive_minus_negative"] = 2.0 * b[0];
    os << "friction differs with direction: positive minus negative Coulomb level " << 2.0 * b[0] << " N·m";
  } else if (e == "position_ripple") {
    const double k = c.setting.at("periods_per_rev");
    p["periods_per_rev"] = k;
    p["period_rad"] = 2.0 * M_PI / k;
    p["amplitude"] = std::hypot(b[0], b[1]);
    p["phase_rad"] = std::atan2(b[1], b[0]);
    os << "position ripple (cogging or gear meshing): period " << p["period_rad"] << " rad (" << k
       << " per turn), amplitude " << p["amplitude"] << " N·m";
  } else if (e == "temperature_drift") {
    p["level_change"] = b[0];
    p["time_constant_s"] = c.setting.at("time_constant_s");
    os << "friction drifts with time (temperature): level changes by " << b[0] << " N·m with time constant "
       << p["time_constant_s"] << " s";
  } else if (e == "load_dependent_friction") {
    p["coefficient"] = b[0];
    os << "friction grows with the joint load: " << b[0] << " N·m per N·m of load";
  } else if (e == "payload") {
    const double m = b[0];
    p["mass_kg"] = m;
    if (std::fabs(m) > 1e-6) {
      p["com_x_m"] = b[1] / m;
      p["com_y_m"] = b[2] / m;
      p["com_z_m"] = b[3] / m;
    }
    os << "payload / last-link mass error: " << m << " kg";
  } else if (e == "inertia_error") {
    p["delta_inertia"] = b[0];
    os << "inertia (reflected rotor or link) off by " << b[0] << " kg·m²";
  } else if (e == "torque_constant") {
    p["scale_error"] = -b[0];
    p["torque_constant_ratio"] = 1.0 - b[0];
    os << "torque constant (current to torque) off: true/nominal " << 1.0 - b[0];
  } else if (e == "current_offset") {
    p["offset_nm"] = b[0];
    os << "current sensor offset worth " << b[0] << " N·m";
  } else if (e == "time_delay") {
    p["delay_s"] = -b[0];
    os << "measurement delay of " << -b[0] * 1000.0 << " ms between motion and torque";
  } else if (e == "backlash") {
    p["gap_rad"] = c.setting.at("gap_rad");
    p["fraction"] = b[0];
    os << "backlash: the load is not driven for " << p["gap_rad"] << " rad after reversals";
  } else if (e == "joint_elasticity") {
    p["stiffness_nm_per_rad"] = b.empty() || b[0] == 0.0 ? 0.0 : 1.0 / b[0];
    os << "joint elasticity: stiffness ~" << p["stiffness_nm_per_rad"] << " N·m/rad";
  }
  (void)s;
  text = os.str();
  return p;
}

}  // namespace jg::diag
