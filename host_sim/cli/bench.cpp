// `jointguard bench`: firmware cost per joint cycle on the Cortex-M4F (instructions counted
// under qemu -singlestep with execution tracing: qemu has no cycle model), firmware size,
// host simulation speed and identification time. JSON per the contract.
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "cli/commands.hpp"
#include "cli/mcu_cost.hpp"
#include "eval/experiments.hpp"
#include "identification/identify.hpp"
#include "identification/lugre_batch.hpp"
#include "models/paper_friction.hpp"
#include "motion/excitation.hpp"

namespace jg::cli {
namespace {
std::string run_capture(const std::string& command) {
  std::string out;
  FILE* p = ::popen(command.c_str(), "r");
  if (p == nullptr) return out;
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), buf.size(), p) != nullptr) out += buf.data();
  ::pclose(p);
  return out;
}

}  // namespace

McuFigures measure_mcu(const std::string& elf, const std::string& core_lib) {
  McuFigures f;
  if (!std::filesystem::exists(elf)) {
    f.note = "cycle benchmark ELF not built (" + elf + "): build the host preset with the arm toolchain installed";
    return f;
  }
  std::map<std::string, unsigned long> addr;
  std::istringstream nm(run_capture("arm-none-eabi-nm " + elf));
  for (std::string line; std::getline(nm, line);) {
    std::istringstream ls(line);
    std::string a, t, name;
    ls >> a >> t >> name;
    if (name == "jg_bench_begin" || name == "jg_bench_end") addr[name] = std::stoul(a, nullptr, 16);
  }
  const auto log = std::filesystem::temp_directory_path() / ("jg_trace_" + std::to_string(::getpid()) + ".log");
  const std::string cmd = "qemu-system-arm -M mps2-an386 -nographic -monitor none -serial none "
                          "-semihosting-config enable=on,target=native -singlestep -d nochain,exec -D " +
                          log.string() + " -kernel " + elf + " > /dev/null 2>&1";
  if (std::system(cmd.c_str()) != 0 || addr.size() != 2) {
    f.note = "qemu run failed";
    return f;
  }
  std::ifstream in(log);
  const std::regex pc_re(R"(\[[0-9a-f]+/([0-9a-f]+)/)");
  std::vector<long> begins, ends;
  long index = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("Trace", 0) != 0) continue;
    std::smatch m;
    if (std::regex_search(line, m, pc_re)) {
      const unsigned long pc = std::stoul(m[1].str(), nullptr, 16);
      if (pc == addr["jg_bench_begin"]) begins.push_back(index);
      if (pc == addr["jg_bench_end"]) ends.push_back(index);
    }
    ++index;
  }
  std::filesystem::remove(log);
  if (begins.size() < 2 || ends.size() < 2) {
    f.note = "markers not found in the trace";
    return f;
  }
  constexpr double kCycles = 20.0;  // tests/mcu/cycle_bench.cpp
  f.float_insns = static_cast<double>(ends[0] - begins[0] - 2) / kCycles;
  f.q_insns = static_cast<double>(ends[1] - begins[1] - 2) / kCycles;
  std::istringstream sz(run_capture("arm-none-eabi-size -t " + core_lib));
  for (std::string line; std::getline(sz, line);) {
    if (line.find("(TOTALS)") != std::string::npos) {
      std::istringstream ls(line);
      ls >> f.text >> f.data >> f.bss;
    }
  }
  f.ok = true;
  return f;
}

Command add_bench(CLI::App& app) {
  auto json = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("bench",
                                 "Measure the firmware's instructions per joint cycle on the Cortex-M4F (qemu), its size,\n"
                                 "the simulation's speed and the identification time.\n"
                                 "Example: jointguard bench --json out/bench.json");
  cmd->add_option("--json", *json, "Write the figures here (contract format)");
  return {cmd, [json]() {
            const std::string mcu = mcu_build_dir();
            const McuFigures m = measure_mcu(mcu + "/toolchain/mcu/jg_cycle_bench.elf", mcu + "/firmware/libjg_core.a");
            // Host: 60 s of the reference arm at 1 kHz (plant, sensors, controller), recording off.
            eval::ExperimentConfig c;
            c.model = robot::load_robot(JG_DEFAULT_MODEL);
            sim::JointVector home = sim::JointVector::Zero(3), lo(3), hi(3);
            home << 0.0, 0.6, -0.8;
            lo = home.array() - 0.7;
            hi = home.array() + 0.7;
            auto setup = eval::base_setup(c, std::shared_ptr<const sim::Trajectory>(sim::make_random_moves(home, lo, hi, 0.8, 65.0, 1)), 1);
            setup.duration_s = 60.0;
            setup.record = false;
            const auto t0 = std::chrono::steady_clock::now();
            const auto r = sim::run_simulation(setup);
            const double sim_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            // Identification: one paper-sized GA run (200 x 300 over 1251 samples).
            const sim::PaperExcitation traj(0.6, 0.2, 4, 2.5);
            ident::FrictionSeries s;
            s.dt = 0.008;
            for (long k = 0; k < 1251; ++k) s.velocity.push_back(traj.at(traj.steady_begin() + 0.008 * static_cast<double>(k)).dq);
            s.friction = ident::lugre_predict(sim::kPaperTable1[0], s.velocity, s.dt);
            double cost = 0.0;
            const auto t1 = std::chrono::steady_clock::now();
            (void)ident::run_ga(s, ident::GaSettings{}, ident::SearchRanges{}, 1, cost);
            const double ga_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
            if (m.ok) {
              std::printf("Cortex-M4F, one joint's full cycle (outward + inward + LuGre + observer + detector):\n"
                          "  float %.0f instructions, Q16.16 %.0f instructions\n  core text %ld, data %ld, bss %ld bytes\n",
                          m.float_insns, m.q_insns, m.text, m.data, m.bss);
            } else {
              std::printf("Cortex-M4F figures unavailable: %s\n", m.note.c_str());
            }
            std::printf("host: simulation %.0fx real time (3-joint arm, 1 kHz control, 2 kHz plant); one paper-sized GA run %.3f s\n",
                        r.simulated_s / sim_wall, ga_s);
            if (!json->empty()) {
              nlohmann::json j;
              j["firmware"] = {{"target", "cortex-m4"},
                               {"scalar", {{"float", {{"instructions_per_joint_cycle", m.float_insns}}},
                                           {"q", {{"instructions_per_joint_cycle", m.q_insns}}}}},
                               {"text", m.text}, {"data", m.data}, {"bss", m.bss}, {"measured", m.ok}, {"note", m.note}};
              j["host"] = {{"sim_realtime_factor", r.simulated_s / sim_wall}, {"identify_seconds", ga_s},
                           {"identify_definition", "one GA run, population 200 x 300 generations, 1251 samples"}};
              std::ofstream(*json) << j.dump(2) << '\n';
              std::printf("wrote %s\n", json->c_str());
            }
            return 0;
          }};
}

}  // namespace jg::cli
