// `jointguard demo`: the main job. Simulate the reference arm, identify its friction from
// observer output, calibrate the thresholds, run the paper's three collisions and a random
// campaign in float and Q16.16 at 1 kHz and 125 Hz, and write a single HTML report.
#include "cli/demo.hpp"

#include <memory>

#include "cli/commands.hpp"
#include "cli/mcu_cost.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <algorithm>
#include <chrono>
#include <sstream>

#include "diagnosis/testset.hpp"
#include "io/atomic_write.hpp"
#include "eval/experiments.hpp"
#include "report/contact_report.hpp"
#include "report/safety_report.hpp"
#include "report/svg_plot.hpp"
#include "robot/robot_model.hpp"
#include "tuning/observer_tuning.hpp"

#include "jointguard/friction/lugre.hpp"
#include "models/paper_friction.hpp"
#include "motion/excitation.hpp"

namespace jg::cli {
namespace {

template <class S>
LuGreDiscrete<S> must_discretize(const LuGreParams<double>& p, double dt) {
  LuGreDiscrete<S> d{};
  if (const Error e = discretize(p, dt, d); e != Error::ok) {
    throw std::runtime_error(std::string("LuGre parameters do not fit the scalar: ") + to_string(e));
  }
  return d;
}

struct Comparison {
  double max_err_float = 0.0, max_err_q = 0.0, max_err_q_arith = 0.0, rms_friction = 0.0;
};

Comparison compare_joint(const LuGreParams<double>& p, double dt, std::ofstream* csv) {
  const auto cd = must_discretize<double>(p, dt);
  const auto cf = must_discretize<float>(p, dt);
  const auto cq = must_discretize<q16>(p, dt);
  LuGreState<double> sd{};
  LuGreState<float> sf{};
  LuGreState<q16> sq{};
  LuGreState<double> sdq{};  // double fed the Q16.16-quantised velocity
  const sim::PaperExcitation traj;
  Comparison c;
  double sum_sq = 0.0;
  long n = 0;
  NumericStatus status{};
  for (long k = 0;; ++k) {
    const double t = static_cast<double>(k) * dt;
    if (t > traj.duration()) {
      break;
    }
    const double w = traj.at(t).dq;
    const double fd = lugre_step(cd, sd, w);
    const float ff = lugre_step(cf, sf, static_cast<float>(w));
    const q16 wq = q16::from_double(w, status);
    const q16 fq = lugre_step(cq, sq, wq);
    const double fdq = lugre_step(cd, sdq, wq.to_double());
    c.max_err_q_arith = std::max(c.max_err_q_arith, std::fabs(fq.to_double() - fdq));
    c.max_err_float = std::max(c.max_err_float, std::fabs(static_cast<double>(ff) - fd));
    c.max_err_q = std::max(c.max_err_q, std::fabs(fq.to_double() - fd));
    sum_sq += fd * fd;
    ++n;
    if (csv != nullptr) {
      *csv << t << ',' << w << ',' << fd << ',' << ff << ',' << fq.to_double() << '\n';
    }
  }
  c.rms_friction = std::sqrt(sum_sq / static_cast<double>(n));
  return c;
}

}  // namespace

namespace {
std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

struct PaperRow {
  std::string config;
  std::vector<eval::RunResult> runs;
};

report::Plot trace_plot(const eval::RunResult& comp, const eval::RunResult& uncomp, int joint, double thr, double thr_uncomp) {
  report::Plot p;
  p.title = comp.name + ": external torque on joint " + std::to_string(joint + 1);
  p.x_label = "t [s]";
  p.y_label = "torque [N·m]";
  const auto j = static_cast<std::size_t>(joint);
  p.series.push_back({"without compensation", uncomp.trace.t, uncomp.trace.mu[j], "#ff7f0e", 1.0});
  p.series.push_back({"with LuGre compensation", comp.trace.t, comp.trace.mu[j], "#1f77b4", 1.2});
  p.series.push_back({"true external torque", comp.trace.t, comp.trace.tau_ext[j], "#2ca02c", 1.0, true});
  p.hlines = {{thr, "threshold (compensated)", "#1f77b4"}, {-thr, "", "#1f77b4"}, {thr_uncomp, "threshold (uncompensated)", "#ff7f0e"}, {-thr_uncomp, "", "#ff7f0e"}};
  p.markers.push_back({comp.t_collision, "collision", "#d62728"});
  if (comp.t_detected) p.markers.push_back({*comp.t_detected, "detected", "#9467bd"});
  p.x_lo = comp.t_collision - 3.0;
  p.x_hi = comp.t_collision + 1.0;
  return p;
}
}  // namespace

// Threshold margin above the calibrated collision-free band (the paper adds one too).
constexpr double kMarginNm = 0.5;

// run_demo's report sections, in its order: each writes its part of the HTML page.
namespace {

void write_head(std::ostream& html) {
  html << "<!doctype html><html><head><meta charset=\"utf-8\"><title>jointguard report</title><style>"
          "body{font-family:sans-serif;max-width:980px;margin:24px auto;color:#222}table{border-collapse:collapse;margin:8px 0}"
          "td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}th{background:#f3f3f3}h2{margin-top:32px}"
          ".note{color:#555;font-size:90%}</style></head><body>\n";
  html << "<h1>jointguard: sensorless collision detection, demo report</h1>\n";
  html << "<p class=\"note\">Reference arm <code>models/ref3.yaml</code> simulated with the paper's Table 1 LuGre friction as truth, "
          "encoder and current quantisation, 0.01 A current noise. The firmware core (momentum recursion, observer, LuGre, detector) "
          "runs in the loop in float and Q16.16. Reproduce: <code>bash scripts/demo.sh</code> "
          "(or <code>build/host/jointguard demo --out out</code>).</p>\n";
}

/// 1. The friction identified from the observer's output against the truth, and the thresholds.
void write_identification(std::ostream& html, const eval::ExperimentConfig& c, const eval::Preparation& prep) {
  html << "<h2>Friction identified from the observer's output</h2>\n<table><tr><th>joint</th><th>parameter</th><th>identified</th><th>truth</th><th>error</th><th>identifiable</th></tr>\n";
  for (std::size_t j = 0; j < prep.identification.size(); ++j) {
    const auto& r = prep.identification[j];
    const auto& truth = sim::kPaperTable1[std::min<std::size_t>(j, 2)];
    const double id[6] = {r.params.sigma0, r.params.sigma1, r.params.sigma2, r.params.tau_c, r.params.tau_s, r.params.w_s};
    const double tr[6] = {truth.sigma0, truth.sigma1, truth.sigma2, truth.tau_c, truth.tau_s, truth.w_s};
    for (int k = 0; k < 6; ++k) {
      html << "<tr><td>" << j + 1 << "</td><td>" << ident::kParamNames[static_cast<std::size_t>(k)] << "</td><td>" << fmt("%.4g", id[k])
           << "</td><td>" << fmt("%.4g", tr[k]) << "</td><td>" << fmt("%+.1f %%", 100.0 * (id[k] - tr[k]) / tr[k]) << "</td><td>"
           << (r.report[static_cast<std::size_t>(k)].identifiable ? "yes" : "no") << "</td></tr>\n";
    }
  }
  html << "</table>\n";
  html << "<h2>Thresholds: collision-free band with and without friction compensation</h2>\n<table><tr><th>joint</th>"
          "<th>band without [N·m]</th><th>band with, moving [N·m]</th><th>shrink</th><th>threshold (moving) [N·m]</th><th>+ near standstill [N·m]</th></tr>\n";
  for (std::size_t j = 0; j < c.thresholds.size(); ++j) {
    const double moving_band = c.thresholds[j] - prep.thresholds.margin;
    html << "<tr><td>" << j + 1 << "</td><td>" << fmt("%.2f", prep.thresholds.band_uncompensated[j]) << "</td><td>" << fmt("%.2f", moving_band)
         << "</td><td>" << fmt("%.1fx", prep.thresholds.band_uncompensated[j] / moving_band) << "</td><td>" << fmt("%.2f", c.thresholds[j])
         << "</td><td>" << fmt("%.2f", c.low_speed_extra[j]) << "</td></tr>\n";
  }
  html << "</table><p class=\"note\">Paper: one threshold of 7.80 N·m. Near standstill the friction is stiction, which no velocity-driven "
          "model predicts; the band widens there by the amount observed.</p>\n";
}

/// 2. The paper's three collisions at 1 kHz and 125 Hz, float and Q16.16: the rows, also
/// printed at the end.
std::vector<PaperRow> write_paper_collisions(std::ostream& html, const eval::ExperimentConfig& c) {
  std::vector<PaperRow> rows;
  eval::ExperimentConfig c125 = c;
  c125.rate_hz = 125.0;
  c125.gains = tuning::default_gains(c125.rate_hz);
  eval::prepare(c125, kMarginNm);
  const eval::ExperimentConfig& c125_prepared = c125;
  for (const auto* cfg : {&c, &c125_prepared}) {
    for (const char* scalar : {"float", "q"}) {
      eval::ExperimentConfig x = *cfg;
      x.scalar = scalar;
      rows.push_back({fmt("%.0f Hz, ", x.rate_hz) + (x.scalar == "q" ? "Q16.16" : "float"), eval::paper_experiments(x, false)});
    }
  }
  const double paper_delay[3] = {0.080, 0.088, 0.096};
  html << "<h2>The paper's three collisions</h2>\n<table><tr><th>configuration</th><th>collision</th><th>occurred [s]</th><th>detected [s]</th>"
          "<th>delay [ms]</th><th>paper delay [ms]</th><th>isolated link</th><th>peak force [N]</th></tr>\n";
  for (const auto& row : rows) {
    for (std::size_t i = 0; i < row.runs.size(); ++i) {
      const auto& r = row.runs[i];
      html << "<tr><td>" << row.config << "</td><td>" << r.name << "</td><td>" << fmt("%.3f", r.t_collision) << "</td><td>"
           << (r.t_detected ? fmt("%.3f", *r.t_detected) : "missed") << "</td><td>"
           << (r.t_detected ? fmt("%.0f", 1e3 * (*r.t_detected - r.t_collision)) : "-") << "</td><td>" << fmt("%.0f", 1e3 * paper_delay[i])
           << "</td><td>" << r.link_isolated << " (true " << r.link_true << ")</td><td>" << fmt("%.0f", r.peak_force_n) << "</td></tr>\n";
    }
  }
  html << "</table>\n";
  return rows;
}

/// 3. Figures in the spirit of the paper's Figures 5-7: with and without compensation.
void write_traces(std::ostream& html, const eval::ExperimentConfig& c, const eval::Preparation& prep) {
  eval::ExperimentConfig trace_cfg = c;
  trace_cfg.reaction = Reaction::none;
  const auto comp = eval::paper_experiments(trace_cfg, true);
  eval::ExperimentConfig unc = trace_cfg;
  unc.friction.clear();
  const auto uncomp = eval::paper_experiments(unc, true);
  for (std::size_t i = 0; i < comp.size() && i < uncomp.size(); ++i) {
    const int joint = comp[i].link_true - 1;
    html << report::render_svg(trace_plot(comp[i], uncomp[i], joint, c.thresholds[static_cast<std::size_t>(joint)],
                                          prep.thresholds.threshold_uncompensated[static_cast<std::size_t>(joint)]));
  }
}

/// 4. What the campaign and the collision-free run give, also printed at the end.
struct CampaignFigures {
  std::size_t collisions = 0;
  eval::Summary sum;
  int alarms = 0;
  double free_s = 0.0, per_hour = 0.0;
};

CampaignFigures write_campaign(std::ostream& html, const eval::ExperimentConfig& c) {
  const auto camp = eval::campaign(c, 50, {2, 3});
  const eval::Summary sum = eval::summarize(camp);
  int alarms = 0;
  const double free_s = 600.0;
  const double per_hour = eval::false_alarms_per_hour(c, free_s, alarms);
  html << "<h2>Random campaign and false alarms (1 kHz, float)</h2>\n<table><tr><th>collisions</th><th>detected</th><th>detected, true torque &gt; 1.5x threshold in effect</th><th>&gt; 1.5x moving threshold</th>"
          "<th>isolated correctly</th><th>delay min / median / max [ms]</th><th>false alarms</th></tr>\n<tr><td>"
       << camp.size() << "</td><td>" << sum.detected << "</td><td>" << sum.detectable_found << " / " << sum.detectable << "</td><td>" << sum.detectable_moving_found << " / "
       << sum.detectable_moving << "</td><td>" << sum.isolated << "</td><td>"
       << (sum.detected == 0 ? std::string("-") : fmt("%.0f", 1e3 * sum.delay_min) + " / " + fmt("%.0f", 1e3 * sum.delay_median) + " / " + fmt("%.0f", 1e3 * sum.delay_max))
       << "</td><td>" << alarms << " in " << fmt("%.0f", free_s) << " s</td></tr></table>\n"
       << "<p class=\"note\">Paper: 50 random collisions on links 2-3, 100 % detected, delays 64-96 ms. Campaign collisions include clamps "
          "the arm moves away from (no force builds up) and forces through a joint axis; the third column counts those whose torque clears the threshold in effect (the band at the joint's velocity, "
          "with the standstill allowance at rest, where the friction held is not predicted); the fourth column counts against "
          "the moving threshold alone. "
          "Isolation names the highest joint over threshold at the detection cycle (paper's signature).</p>\n";

  html << report::contact_section(camp);  // the campaign's contact estimates, as sets where undetermined
  return {camp.size(), sum, alarms, free_s, per_hour};
}

/// 4b. Model-mismatch diagnosis: concealed effects named, fitted, written back.
void write_diagnosis(std::ostream& html) {
  html << "<h2>Diagnosis: what the simulation left out, named and written back</h2>\n<table><tr><th>concealed in the \"real\" arm</th>"
          "<th>named by <code>jointguard diagnose</code></th><th>held-out RMS on its joint, before &rarr; after [N·m]</th>"
          "<th>re-simulated with the findings (<code>--model-out</code>) [N·m]</th><th>noise [N·m]</th></tr>\n";
  {
    const auto arm = diag::default_test_arm();
    const std::vector<diag::ConcealedCase> cases = {
        {robot::Effect::payload, 3, 0.45, "partial", 910001ULL},
        {robot::Effect::link_inertial_error, 2, 0.40, "low_amplitude", 910002ULL},
        {robot::Effect::position_ripple, 2, 0.35, "mixed", 910003ULL},
        {robot::Effect::none, 1, 0.0, "matched", 910004ULL}};
    for (const auto& cc : cases) {
      const diag::CaseOutcome out = diag::run_case(cc, arm);
      std::string named;
      for (const auto& f : out.arm.findings) named += (named.empty() ? "" : ", ") + std::string("arm: ") + f.effect;
      for (const auto& jd : out.joints) {
        for (const auto& f : jd.findings) named += (named.empty() ? "" : ", ") + ("joint " + std::to_string(jd.joint) + ": " + f.effect);
      }
      const std::string what = cc.effect == robot::Effect::none ? std::string("nothing (two runs of the same arm)")
                                                    : cc.effect + " on joint " + std::to_string(cc.joint) + " (" + cc.concealment + ", " +
                                                          fmt("%.2f", cc.amplitude_nm) + " N·m)";
      html << "<tr><td>" << report::escape(what) << "</td><td>" << report::escape(named.empty() ? "nothing" : named) << "</td><td>"
           << fmt("%.3f", out.heldout_raw) << " &rarr; " << fmt("%.3f", out.heldout_after) << "</td><td>" << fmt("%.3f", out.resim_heldout)
           << "</td><td>" << fmt("%.3f", out.noise) << "</td></tr>\n";
    }
  }
  html << "</table><p class=\"note\">Each case simulates a \"real\" and a nominal recording of the same motion with independent sensor noise; "
          "the diagnosis names what differs (a payload and a link's mass once for the arm, the rest per joint, only with strong evidence, "
          "held-out gain and physically plausible parameters), writes it back into the simulation, and the re-simulation is compared "
          "with the real recording again. Figures over 300 cases: docs/results.md (Diagnosis); the real Panda and UR10e: docs/results.md (Real arms).</p>\n";
}

/// 5. Fixed point against double.
void write_arithmetic(std::ostream& html) {
  html << "<h2>Firmware arithmetic: LuGre friction in float and Q16.16 against double</h2>\n<table><tr><th>joint</th><th>dT [s]</th>"
          "<th>max |float - double| [N·m]</th><th>max |Q16.16 - double| [N·m]</th><th>Q16.16 arithmetic alone [N·m]</th></tr>\n";
  for (const double dt : {0.008, 0.001}) {
    for (std::size_t j = 0; j < sim::kPaperTable1.size(); ++j) {
      const Comparison cmp = compare_joint(sim::kPaperTable1[j], dt, nullptr);
      html << "<tr><td>" << j + 1 << "</td><td>" << dt << "</td><td>" << fmt("%.2e", cmp.max_err_float) << "</td><td>" << fmt("%.2e", cmp.max_err_q)
           << "</td><td>" << fmt("%.2e", cmp.max_err_q_arith) << "</td></tr>\n";
    }
  }
  html << "</table>\n";
}

/// 6. What one joint's cycle costs on the drive's MCU.
void write_mcu_cost(std::ostream& html) {
  const McuFigures mcu = measure_mcu(mcu_build_dir() + "/toolchain/mcu/jg_cycle_bench.elf", mcu_build_dir() + "/firmware/libjg_core.a");
  html << "<h2>Firmware cost per cycle (Cortex-M4F)</h2>\n";
  if (mcu.ok) {
    html << "<table><tr><th>scalar</th><th>estimator cycle [instructions]</th><th>drive cycle, mean (worst) [instructions]</th>"
            "<th>drive cycle stack [B]</th></tr>\n<tr><td>float</td><td>"
         << fmt("%.0f", mcu.float_insns) << "</td><td>" << fmt("%.0f", mcu.float_drive_insns) << " (" << fmt("%.0f", mcu.float_drive_max)
         << ")</td><td>" << mcu.float_stack << "</td></tr>\n<tr><td>Q16.16</td><td>" << fmt("%.0f", mcu.q_insns) << "</td><td>"
         << fmt("%.0f", mcu.q_drive_insns) << " (" << fmt("%.0f", mcu.q_drive_max) << ")</td><td>" << mcu.q_stack
         << "</td></tr></table>\n<p class=\"note\">Estimator cycle: one joint's outward and inward recursion step, LuGre, observer, "
            "detector. Drive cycle: <code>JointDrive::poll</code> with the sync, both neighbours' frames checked and decoded, the "
            "estimator, both frames encoded, the status frame and once the collision event. Counted instruction by instruction "
            "under <code>qemu-system-arm -M mps2-an386</code> (qemu has no cycle model); stack by painting; budgets in docs/mcu.md. "
            "Core library: text "
         << mcu.text << " B, data " << mcu.data << " B, bss " << mcu.bss
         << " B. Reproduce: <code>build/host/jointguard bench --firmware-only</code>.</p>\n";
  } else {
    html << "<p class=\"note\">Not measured: " << report::escape(mcu.note) << "</p>\n";
  }
}
}  // namespace

int run_demo(const DemoOptions& options) {
  // Numbered by a counter: hand-written labels showed [4/7] twice.
  constexpr int kSteps = 8;
  int step_no = 0;
  auto step = [&step_no](const char* what) { std::printf("[%d/%d] %s...\n", ++step_no, kSteps, what); };
  const auto t_start = std::chrono::steady_clock::now();
  std::filesystem::create_directories(options.out_dir);
  std::ostringstream html;
  write_head(html);

  step("identification from observer output and threshold calibration (1 kHz)");
  eval::ExperimentConfig c;
  c.model = robot::load_robot(JG_DEFAULT_MODEL);
  c.rate_hz = 1000.0;
  const auto prep = eval::prepare(c, kMarginNm);
  write_identification(html, c, prep);

  step("the paper's three collisions at 1 kHz and 125 Hz, float and Q16.16");
  const std::vector<PaperRow> rows = write_paper_collisions(html, c);

  step("traces with and without compensation");
  write_traces(html, c, prep);

  step("random campaign (50 collisions on links 2-3) and a 10-minute collision-free run");
  const CampaignFigures camp = write_campaign(html, c);

  // 4a. ISO/TS 15066: body-region contacts by reaction (report/safety_report.*).
  step("ISO/TS 15066 body-region contacts, every region and reaction");
  html << report::safety_section(c, report::SafetySectionOptions{});

  step("diagnosis: concealed effects named and written back into the simulation");
  write_diagnosis(html);

  step("LuGre in float and Q16.16 against double");
  write_arithmetic(html);

  step("firmware cost per estimator and drive cycle on the emulated Cortex-M4F");
  write_mcu_cost(html);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  html << "<p class=\"note\">Generated in " << fmt("%.0f", wall) << " s.</p>" << report::plot_script() << "</body></html>\n";
  const auto report_path = std::filesystem::path(options.out_dir) / "report.html";
  io::write_text_atomic(report_path.string(), html.str());
  std::printf("\npaper collisions at 1 kHz (float): ");
  for (const auto& r : rows[0].runs) std::printf("%s ", r.t_detected ? fmt("%.0f ms", 1e3 * (*r.t_detected - r.t_collision)).c_str() : "missed");
  std::printf("\npaper collisions at 125 Hz (Q16.16): ");
  for (const auto& r : rows[3].runs) std::printf("%s ", r.t_detected ? fmt("%.0f ms", 1e3 * (*r.t_detected - r.t_collision)).c_str() : "missed");
  std::printf("\ncampaign: %d/%zu detected, false alarms %d in %.0f s (%.1f per hour)\n", camp.sum.detected, camp.collisions, camp.alarms, camp.free_s, camp.per_hour);
  std::printf("report: %s (%.0f s)\n", std::filesystem::absolute(report_path).string().c_str(), wall);
  return 0;
}

Command add_demo(CLI::App& app) {
  auto opt = std::make_shared<DemoOptions>();
  auto* cmd = app.add_subcommand("demo", "Run the main job and print what it measured.\nExample: jointguard demo --out out");
  cmd->add_option("--out", opt->out_dir, "Output directory")->capture_default_str();
  return {cmd, [opt]() { return run_demo(*opt); }};
}

}  // namespace jg::cli
