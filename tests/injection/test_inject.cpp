// host_sim/injection/: what `jointguard inject` changes in a recording's text and what it
// refuses. The physics against the plant and an independent point mass: tests/cli/inject.sh.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "injection/csv_edit.hpp"
#include "injection/effects_file.hpp"
#include "injection/inject.hpp"
#include "io/regularize.hpp"
#include "io/sha256.hpp"
#include "robot/effect_catalogue.hpp"
#include "robot/robot_model.hpp"

namespace {
using jg::inject::Channel;
using jg::robot::PlantEffect;

TEST(Sha256, KnownDigests) {
  EXPECT_EQ(jg::io::sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(jg::io::sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  // 56 bytes: the length no longer fits the first block's padding.
  EXPECT_EQ(jg::io::sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

TEST(InjectFormat, NineDigitsOrTheSourcesWhenMore) {
  EXPECT_EQ(jg::inject::format_like(12.5781374123, "12.468"), "12.5781374");
  EXPECT_EQ(jg::inject::format_like(0.1 + 0.2, "0.30000000000000004"), "0.30000000000000004");
  EXPECT_EQ(jg::inject::format_like(-1.5e-7, "-0.000"), "-1.5e-07");
}

/// Adds 1 to every reading of rows with t <= 0.0025 s; later rows are "outside".
bool add_one_early(double t, const std::vector<double>& old, std::vector<double>& out) {
  if (t > 0.0025) return false;
  for (std::size_t j = 0; j < old.size(); ++j) out[j] = old[j] + 1.0;
  return true;
}

TEST(InjectCsv, OnlyTheTorqueFieldsChange) {
  // CRLF line ends, spaces around a field, a blank line, an extra column, q01-style names,
  // a tau_m column of another joint and no newline at the end: all kept.
  const std::string in =
      "t,q01,dq01,tau_m01,tau_m7,note\r\n"
      "0.000,0.1,0.0, 2.5 ,9,x1\r\n"
      "\r\n"
      "0.001,0.1,0.0,-0.25,9,7\r\n"
      "0.004,0.2,0.1,3,9,7";
  const auto e = jg::inject::edit_torque_columns(in, "a.csv", {1}, "tau_m", false, add_one_early);
  EXPECT_EQ(e.text,
            "t,q01,dq01,tau_m01,tau_m7,note\r\n"
            "0.000,0.1,0.0, 3.5 ,9,x1\r\n"
            "\r\n"
            "0.001,0.1,0.0,0.75,9,7\r\n"
            "0.004,0.2,0.1,3,9,7");
  EXPECT_EQ(e.columns, std::vector<std::string>{"tau_m01"});
  EXPECT_EQ(e.data_rows, 3U);
  EXPECT_EQ(e.rows_outside, 1U);
  EXPECT_EQ(e.rows_changed[0], 2U);
  EXPECT_DOUBLE_EQ(e.max_abs_change[0], 1.0);
}

TEST(InjectCsv, RepeatedStatesStayRepeats) {
  // Row 3 repeats row 2's state at a later (jittered) time stamp: it gets row 2's new text
  // even though the rule would give it another value at its own time.
  const std::string in = "t,q1,dq1,i1\n0,0,0,1\n0.001,0.5,1,2\n0.0017,0.5,1,2\n0.002,0.6,1,2\n";
  auto by_time = [](double t, const std::vector<double>& old, std::vector<double>& out) {
    out[0] = old[0] + 1000.0 * t;
    return true;
  };
  const auto e = jg::inject::edit_torque_columns(in, "a.csv", {1}, "i", true, by_time);
  EXPECT_EQ(e.text, "t,q1,dq1,i1\n0,0,0,1\n0.001,0.5,1,3\n0.0017,0.5,1,3\n0.002,0.6,1,4\n");
  const auto plain = jg::inject::edit_torque_columns(in, "a.csv", {1}, "i", false, by_time);
  EXPECT_EQ(plain.text, "t,q1,dq1,i1\n0,0,0,1\n0.001,0.5,1,3\n0.0017,0.5,1,3.7\n0.002,0.6,1,4\n");
}

TEST(InjectCsv, RefusesWhatItCannotEdit) {
  auto nan_rule = [](double, const std::vector<double>&, std::vector<double>& out) {
    out[0] = std::nan("");
    return true;
  };
  try {
    (void)jg::inject::edit_torque_columns("t,q1,dq1,i1\n0,0,0,1\n", "a.csv", {1}, "i", false, nan_rule);
    FAIL() << "a non-finite value was written";
  } catch (const jg::io::FormatError& err) {
    EXPECT_NE(std::string(err.what()).find("a.csv:2: field 'i1': the injected value is not finite"), std::string::npos) << err.what();
  }
  EXPECT_THROW((void)jg::inject::edit_torque_columns("t,q1,dq1,i1\n0,0,0,1\n", "a.csv", {1}, "tau_m", false, add_one_early),
               jg::io::FormatError);
}

TEST(InjectEffects, WhatATorqueColumnCannotCarry) {
  jg::inject::InjectTarget motor{3, jg::io::TorqueKind::tau_m, false, {4.0, 3.5, 2.0}};
  jg::inject::InjectTarget sensor = motor;
  sensor.torque = jg::io::TorqueKind::tau_j;
  auto field = [](const PlantEffect& e, const jg::inject::InjectTarget& t) { return jg::inject::injection_problem(e, t).field; };
  EXPECT_EQ(field({jg::robot::Effect::payload, 0, {{"link", 3}}, {0.5, 0.1, 0, 0}, {}}, motor), "");
  EXPECT_EQ(field({jg::robot::Effect::payload, 0, {{"link", 2}}, {0.5, 0.1, 0, 0}, {}}, motor), "setting.link");
  EXPECT_EQ(field({jg::robot::Effect::payload, 0, {}, {0.0, 0, 0, 0}, {}}, motor), "coefficients");
  EXPECT_EQ(field({jg::robot::Effect::payload, 0, {}, {0.5, 0, 0, 0}, {{"mass_kg", 0.6}}}, motor), "params.mass_kg");
  EXPECT_EQ(field({jg::robot::Effect::payload, 2, {}, {0.5, 0, 0, 0}, {}}, motor), "joint");
  EXPECT_EQ(field({jg::robot::Effect::link_inertial_error, 0, {{"link", 2}}, {-3.5, 0, 0, 0}, {}}, motor), "coefficients");
  EXPECT_EQ(field({jg::robot::Effect::joint_elasticity, 2, {}, {}, {{"stiffness_nm_per_rad", 1e4}}}, motor), "effect");
  EXPECT_EQ(field({jg::robot::Effect::backlash, 2, {{"gap_rad", 1e-3}}, {0.1}, {}}, motor), "effect");
  EXPECT_EQ(field({jg::robot::Effect::coulomb, 2, {{"model_curve", 1}}, {0.6}, {}}, motor), "setting");
  EXPECT_EQ(field({jg::robot::Effect::stribeck, 2, {{"w_s", 0.0}}, {0.6}, {}}, motor), "setting.w_s");
  EXPECT_EQ(field({jg::robot::Effect::asymmetric_friction, 1, {}, {0.1}, {}}, motor), "");
  EXPECT_EQ(field({jg::robot::Effect::asymmetric_friction, 1, {}, {0.1, 0.2, 0.3}, {}}, motor), "coefficients");
  EXPECT_EQ(field({jg::robot::Effect::torque_constant, 1, {}, {-1.0}, {}}, motor), "coefficients");
  EXPECT_EQ(field({jg::robot::Effect::torque_constant, 1, {}, {0.05}, {}}, sensor), "effect");
  EXPECT_EQ(field({jg::robot::Effect::current_offset, 1, {}, {0.3}, {}}, sensor), "effect");
  EXPECT_EQ(field({jg::robot::Effect::inertia_error, 1, {}, {0.01}, {}}, sensor), "effect");
  EXPECT_EQ(field({jg::robot::Effect::time_delay, 1, {}, {-0.002}, {}}, sensor), "");
  EXPECT_EQ(field({jg::robot::Effect::none, 1, {}, {}, {}}, motor), "effect");
}

/// Inject takes each effect's scope and coefficient count from the catalogue: every effect
/// a torque column can carry (not the gear's deflection, not "none") is known to inject, at
/// its scope's joint, with the catalogue's count and setting; one coefficient fewer is refused.
TEST(InjectEffects, EveryTorqueEffectOfTheCatalogue) {
  jg::inject::InjectTarget motor{3, jg::io::TorqueKind::tau_m, false, {4.0, 3.5, 2.0}};
  for (const auto& row : jg::robot::effect_catalogue()) {
    if (row.channel == jg::robot::EffectChannel::deflection || row.channel == jg::robot::EffectChannel::none) continue;
    PlantEffect e{row.effect, row.scope == jg::robot::EffectScope::arm ? 0 : 2, {}, std::vector<double>(row.coefficients, 0.1), {}};
    if (row.effect == jg::robot::Effect::payload) e.setting["link"] = 3;
    if (!row.setting.empty()) e.setting[std::string(row.setting)] = 2.0;
    SCOPED_TRACE(row.name);
    EXPECT_EQ(jg::inject::injection_problem(e, motor).field, "");
    e.coefficients.pop_back();
    EXPECT_EQ(jg::inject::injection_problem(e, motor).field, "coefficients");
  }
}

/// A 3-joint recording of ref3 (2 s at 1 kHz): joints 1 and 2 swing, tau_m1 = sin(pi t).
std::string write_recording(const std::string& name) {
  const auto path = (std::filesystem::temp_directory_path() / name).string();
  std::ofstream out(path);
  out << "t,q1,q2,q3,dq1,dq2,dq3,tau_m1,tau_m2,tau_m3\n";
  char row[256];
  for (int k = 0; k <= 2000; ++k) {
    const double t = 0.001 * k, w = 2.0 * M_PI * 0.5;
    std::snprintf(row, sizeof row, "%.3f,%.9g,%.9g,-0.8,%.9g,%.9g,0,%.9g,%.9g,0.5\n", t, 0.3 * std::sin(w * t), 0.6 + 0.3 * std::sin(w * t),
                  0.3 * w * std::cos(w * t), 0.3 * w * std::cos(w * t), std::sin(M_PI * t), 10.0 + std::cos(w * t));
    out << row;
  }
  return path;
}

struct Injected {
  std::vector<std::vector<double>> before, after;  ///< rows of numbers
};

/// The request both tests build: ref3 with a torque constant of 12 N·m/A on every joint.
jg::inject::InjectRequest ref3_request(const std::string& path, const jg::io::Regularized& data,
                                       const jg::robot::RobotModel& model, const std::vector<PlantEffect>& effects) {
  jg::inject::InjectRequest r;
  r.recording_path = path;
  r.data = &data;
  r.model.model = &model;
  r.model.torque_constant = {12.0, 12.0, 12.0};
  r.effects = effects;
  return r;
}

/// `name`: a file of its own per test (ctest runs the tests in parallel).
Injected run(const std::vector<PlantEffect>& effects, const std::string& name) {
  const std::string path = write_recording(name);
  const jg::io::Regularized data = jg::io::regularize(jg::io::read_recording(path));
  const jg::robot::RobotModel model = jg::robot::load_robot(std::string(JG_SOURCE_DIR) + "/models/ref3.yaml");
  const auto res = jg::inject::inject(ref3_request(path, data, model, effects));
  auto numbers = [](const std::string& text) {
    std::vector<std::vector<double>> rows;
    std::istringstream in(text);
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) {
      std::vector<double> row;
      std::istringstream fields(line);
      for (std::string f; std::getline(fields, f, ',');) row.push_back(std::stod(f));
      rows.push_back(row);
    }
    return rows;
  };
  std::ifstream in(path);
  const std::string original((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::filesystem::remove(path);
  return {numbers(original), numbers(res.text)};
}

TEST(InjectSensor, TimeDelayShiftsTheReading) {
  // time_delay's coefficient is the diagnosis's (b dtau/dt): b = -0.02 is a 20 ms lag.
  const Injected x = run({{jg::robot::Effect::time_delay, 1, {}, {-0.02}, {}}}, "jg_inject_delay.csv");
  for (std::size_t k = 0; k < x.after.size(); ++k) {
    const double t = x.before[k][0];
    const double want = t >= 0.02 ? std::sin(M_PI * (t - 0.02)) : 0.0;  // held at the first sample before
    ASSERT_NEAR(x.after[k][7], want, 1e-7) << "t = " << t;
    ASSERT_EQ(x.after[k][8], x.before[k][8]);
  }
}

TEST(InjectSensor, TimeLeadReadsAhead) {
  // b = +0.02: the torque leads the motion by 20 ms (the motion signals older than it).
  const Injected x = run({{jg::robot::Effect::time_delay, 1, {}, {0.02}, {}}}, "jg_inject_lead.csv");
  const double t_end = x.before.back()[0];
  for (std::size_t k = 0; k < x.after.size(); ++k) {
    const double t = x.before[k][0];
    const double want = std::sin(M_PI * std::min(t + 0.02, t_end));  // held at the last sample after
    ASSERT_NEAR(x.after[k][7], want, 1e-7) << "t = " << t;
    ASSERT_EQ(x.after[k][8], x.before[k][8]);
  }
}

/// inject's figure for a delay as a model sees it (delay x d tau_model/dt, RMS): linear in
/// the delay, the same for a lead, on the delayed joint only, absent without a delay.
TEST(InjectSensor, TimeDelayReportsWhatTheModelSees) {
  const std::string path = write_recording("jg_inject_delay_model.csv");
  const jg::io::Regularized data = jg::io::regularize(jg::io::read_recording(path));
  const jg::robot::RobotModel model = jg::robot::load_robot(std::string(JG_SOURCE_DIR) + "/models/ref3.yaml");
  auto on_model = [&](const std::vector<PlantEffect>& effects) {
    std::vector<double> out;
    for (const auto& c : jg::inject::inject(ref3_request(path, data, model, effects)).joints) out.push_back(c.delay_on_model_rms);
    return out;
  };
  const auto twenty = on_model({{jg::robot::Effect::time_delay, 2, {}, {-0.02}, {}}});
  const auto ten = on_model({{jg::robot::Effect::time_delay, 2, {}, {-0.01}, {}}});
  const auto lead = on_model({{jg::robot::Effect::time_delay, 2, {}, {0.02}, {}}});
  ASSERT_EQ(twenty.size(), 3U);
  EXPECT_GT(twenty[1], 1e-3) << "joint 2 swings: its model torque changes";
  EXPECT_NEAR(twenty[1], 2.0 * ten[1], 1e-12 * twenty[1]);
  EXPECT_DOUBLE_EQ(lead[1], twenty[1]);
  EXPECT_EQ(twenty[0], 0.0);
  EXPECT_EQ(twenty[2], 0.0);
  for (const double v : on_model({{jg::robot::Effect::coulomb, 2, {}, {0.3}, {}}})) EXPECT_EQ(v, 0.0);
  std::filesystem::remove(path);
}

// An effect of one row's own state acts at each row as recorded: on rows sampled off the
// uniform grid (steps of 9-11 ms), the Stribeck excess each row gets is the one of its own
// velocity, not the grid's value interpolated back (which flattens what is sharp in velocity).
TEST(InjectRows, AnEffectOfTheRowsStateActsAtEachRow) {
  const auto path = (std::filesystem::temp_directory_path() / "jg_inject_rows.csv").string();
  {
    std::ofstream out(path);
    out << "t,q1,q2,q3,dq1,dq2,dq3,tau_m1,tau_m2,tau_m3\n";
    char row[256];
    unsigned x = 7;
    for (double t = 0.0; t < 6.0;) {
      const double w = 2.0 * M_PI * 0.5;
      std::snprintf(row, sizeof row, "%.6f,%.9g,0.6,-0.8,%.9g,0,0,%.9g,10,0.5\n", t, 0.3 * std::sin(w * t), 0.3 * w * std::cos(w * t), std::sin(M_PI * t));
      out << row;
      x = x * 1103515245U + 12345U;
      t += 0.009 + 0.002 * static_cast<double>((x >> 8) & 0xffffU) / 65535.0;
    }
  }
  const jg::io::Recording as_read = jg::io::read_recording(path);
  const jg::io::Regularized data = jg::io::regularize(as_read);
  ASSERT_EQ(data.report.method, "linear by time stamp");
  const jg::robot::RobotModel model = jg::robot::load_robot(std::string(JG_SOURCE_DIR) + "/models/ref3.yaml");
  auto r = ref3_request(path, data, model, {{jg::robot::Effect::stribeck, 1, {{"w_s", 0.05}}, {2.0}, {}}});
  r.rows = &as_read;
  const auto res = jg::inject::inject(r);
  std::istringstream in(res.text);
  std::string line;
  std::getline(in, line);
  const double band = std::max(1e-4, 0.005 * 0.3 * 2.0 * M_PI * 0.5);  // the diagnosis's soft sign: 0.5 % of the largest speed
  std::size_t k = 0, checked = 0;
  double largest = 0.0;
  for (; std::getline(in, line); ++k) {
    std::vector<double> f;
    std::istringstream fields(line);
    for (std::string v; std::getline(fields, v, ',');) f.push_back(std::stod(v));
    ASSERT_LT(k, as_read.t.size());
    const double dq = as_read.dq[0][k];
    if (std::fabs(dq) < 2.0 * band) continue;  // the soft sign's ramp
    const double want = 2.0 * (dq > 0.0 ? 1.0 : -1.0) * std::exp(-(dq / 0.05) * (dq / 0.05));
    ASSERT_NEAR(f[7] - as_read.tau_m[0][k], want, 1e-6) << "row " << k << ", t = " << f[0];
    largest = std::max(largest, std::fabs(want));
    ++checked;
  }
  EXPECT_EQ(k, as_read.t.size());
  EXPECT_GT(checked, 500U);
  EXPECT_GT(largest, 1.0) << "no row near the low speeds: the sharp part is not what this tests";
  std::filesystem::remove(path);
}

TEST(InjectArm, PayloadPickedUpActsFromThen) {
  const Injected x = run({{jg::robot::Effect::payload, 0, {{"picked_up_at_s", 1.0}}, {1.0, 0.2, 0.0, 0.0}, {}}}, "jg_inject_pickup.csv");
  for (std::size_t k = 0; k < x.after.size(); ++k) {
    const double t = x.before[k][0];
    if (t < 1.0) {
      ASSERT_EQ(x.after[k], x.before[k]) << "t = " << t;
    } else {
      // Joint 2 holds the payload's weight: about 1 kg x 9.81 x its lever (>= 0.4 m here).
      ASSERT_GT(std::fabs(x.after[k][8] - x.before[k][8]), 1.0) << "t = " << t;
    }
  }
}

}  // namespace
