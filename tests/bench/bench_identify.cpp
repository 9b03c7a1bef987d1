// Paper-sized identification benchmark: one GA run (population 200, 300 generations)
// over 1251 samples of noisy paper-trajectory friction (joint 1, Table 1 truth), and
// optionally the full default identification (10 runs on both cores + refinement).
// Writes the data set as CSV for the SciPy comparison (scripts/bench_identify.sh).
// Usage: jg_bench_identify [--data out.csv] [--runs 10]
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <string>

#include "identification/identify.hpp"
#include "identification/lugre_batch.hpp"
#include "models/paper_friction.hpp"
#include "motion/excitation.hpp"

int main(int argc, char** argv) {
  std::string data_path;
  int runs = 10;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--data") == 0) data_path = argv[i + 1];
    else if (std::strcmp(argv[i], "--runs") == 0) runs = std::atoi(argv[i + 1]);
    else {
      std::fprintf(stderr, "usage: %s [--data out.csv] [--runs N]\n", argv[0]);
      return 2;
    }
  }
  using namespace jg::ident;
  const jg::sim::PaperExcitation traj(0.6, 0.2, 4, 2.5);
  FrictionSeries s;
  s.dt = 0.008;
  for (long k = 0; k < 1251; ++k) s.velocity.push_back(traj.at(traj.steady_begin() + 0.008 * static_cast<double>(k)).dq);
  s.friction = lugre_predict(jg::sim::kPaperTable1[0], s.velocity, s.dt);
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.3);
  for (auto& f : s.friction) f += noise(rng);
  if (!data_path.empty()) {
    std::ofstream out(data_path);
    out << "w,friction\n";
    out.precision(17);
    for (std::size_t k = 0; k < s.velocity.size(); ++k) out << s.velocity[k] << ',' << s.friction[k] << '\n';
  }
  GaSettings g;
  double cost = 0.0;
  const auto t0 = std::chrono::steady_clock::now();
  const auto best = run_ga(s, g, SearchRanges{}, 1, cost);
  const double one_run = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  g.runs = runs;
  const auto t1 = std::chrono::steady_clock::now();
  const auto full = identify_lugre(s, g);
  const double full_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  std::printf("{\"samples\": %zu, \"population\": %d, \"generations\": %d, \"evaluations\": %d,\n"
              " \"ga_one_run_seconds\": %.4f, \"ga_one_run_objective\": %.6g, \"ga_one_run_tau_c\": %.5f,\n"
              " \"identify_runs\": %d, \"identify_seconds\": %.4f, \"identify_rms\": %.5f}\n",
              s.velocity.size(), g.population, g.generations, g.population * (g.generations + 1), one_run, cost,
              best.tau_c, runs, full_s, full.rms);
  return 0;
}
