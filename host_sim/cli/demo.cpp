// `jointguard demo`: what exists so far, end to end. LuGre friction with the paper's
// Table 1 parameters on the paper's excitation trajectory, in double (reference), float
// and Q16.16 side by side, at the paper's 125 Hz and at 1 kHz.
#include "cli/demo.hpp"

#include <memory>

#include "cli/commands.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

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

int run_demo(const DemoOptions& options) {
  std::filesystem::create_directories(options.out_dir);
  const std::filesystem::path csv_path = std::filesystem::path(options.out_dir) / "lugre_joint1_1khz.csv";
  std::printf("LuGre friction, paper Table 1 parameters, paper excitation 0.6 sin(2 pi 0.2 t)\n");
  std::printf("with quintic blends from and to rest (%.1f s). Reference: double.\n\n",
              sim::PaperExcitation{}.duration());
  std::printf("Q16.16 error = total against double on the exact velocity; (arith) = against double\n"
              "fed the same Q16.16-quantised velocity, i.e. the arithmetic alone.\n\n");
  std::printf("joint  dT [s]  friction RMS [N·m]  max|float-double|  max|Q16.16-double|  (arith)\n");
  for (const double dt : {0.008, 0.001}) {
    for (std::size_t j = 0; j < sim::kPaperTable1.size(); ++j) {
      std::ofstream csv;
      std::ofstream* csv_ptr = nullptr;
      if (j == 0 && dt < 0.005) {
        csv.open(csv_path);
        csv << "t,w,tau_f_double,tau_f_float,tau_f_q16\n";
        csv_ptr = &csv;
      }
      const Comparison c = compare_joint(sim::kPaperTable1[j], dt, csv_ptr);
      std::printf("%5zu  %6.3f  %18.4f  %17.3e  %18.3e  %9.3e\n", j + 1, dt, c.rms_friction,
                  c.max_err_float, c.max_err_q, c.max_err_q_arith);
    }
  }
  std::printf("\nTrace of joint 1 at 1 kHz: %s\n", csv_path.string().c_str());
  return 0;
}

Command add_demo(CLI::App& app) {
  auto opt = std::make_shared<DemoOptions>();
  auto* cmd = app.add_subcommand("demo", "Run the main job and print what it measured.\nExample: jointguard demo --out out");
  cmd->add_option("--out", opt->out_dir, "Output directory")->capture_default_str();
  return {cmd, [opt]() { return run_demo(*opt); }};
}

}  // namespace jg::cli
