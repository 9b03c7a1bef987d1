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
#include <algorithm>
#include <functional>
#include <regex>
#include <cstdlib>
#include <sstream>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "cli/mcu_cost.hpp"
#include "eval/experiments.hpp"
#include "identification/identify.hpp"
#include "identification/lugre_batch.hpp"
#include "io/atomic_write.hpp"
#include "models/paper_friction.hpp"
#include "motion/excitation.hpp"

namespace jg::cli {
namespace {
std::string run_capture(const std::string& command, int* status = nullptr) {
  std::string out;
  FILE* p = ::popen(command.c_str(), "r");
  if (p == nullptr) {
    if (status != nullptr) *status = -1;
    return out;
  }
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), buf.size(), p) != nullptr) out += buf.data();
  const int rc = ::pclose(p);
  if (status != nullptr) *status = rc;
  return out;
}

// Worst-case stack of `root` from the ELF's disassembly: each function's frame is the sum
// of its stack-pointer decrements (push/stmdb sp!: 4 B a register, vpush: 8 B a double
// register, sub sp: the immediate; summed over every path, an upper bound), plus the
// deepest of the functions it calls (bl, and b to another function: a tail call), along
// the call graph. It covers newlib's prebuilt code, which -fstack-usage cannot. Indirect
// calls and recursion on the path make the result unknown (-1, note says where).
long static_stack(const std::string& elf, const std::string& root, std::string& note) {
  struct Function {
    long frame = 0;
    std::vector<std::string> callees;
    bool indirect = false;
  };
  std::map<std::string, Function> functions;
  std::istringstream dis(run_capture("arm-none-eabi-objdump -d --no-show-raw-insn -C " + elf));
  const std::regex head_re(R"(^[0-9a-f]+ <(.+)>:$)");
  const std::regex regs_re(R"(\s(?:push|stmdb\s+sp!,)\s*\{([^}]*)\})");
  const std::regex vpush_re(R"(\svpush\s*\{([^}]*)\})");
  const std::regex sub_re(R"(\ssub(?:w|\.w)?\s+sp,\s*(?:sp,\s*)?#(\d+))");
  // The target's name may itself contain '<' and '>' (templates): all up to the last '>'.
  const std::regex call_re(R"(\s(bl|b(?:\.w|\.n)?)\s+[0-9a-f]+\s+<(.+?)(\+0x[0-9a-f]+)?>\s*$)");
  const std::regex indirect_re(R"(\sblx\s+r)");
  const auto count_regs = [](const std::string& list, long per) {
    long n = 0;
    std::istringstream items(list);
    for (std::string item; std::getline(items, item, ',');) {
      const auto dash = item.find('-');
      if (dash == std::string::npos) {
        ++n;
      } else {  // d8-d15
        const auto digits = [](const std::string& t) { return std::stol(t.substr(t.find_first_of("0123456789"))); };
        n += digits(item.substr(dash + 1)) - digits(item.substr(0, dash)) + 1;
      }
    }
    return n * per;
  };
  Function* current = nullptr;
  std::string current_name;
  for (std::string line; std::getline(dis, line);) {
    std::smatch m;
    if (std::regex_match(line, m, head_re)) {
      current_name = m[1].str();
      current = &functions[current_name];
      continue;
    }
    if (current == nullptr || line.find(':') == std::string::npos) continue;
    if (std::regex_search(line, m, regs_re)) current->frame += count_regs(m[1].str(), 4);
    if (std::regex_search(line, m, vpush_re)) current->frame += count_regs(m[1].str(), 8);
    if (std::regex_search(line, m, sub_re)) current->frame += std::stol(m[1].str());
    if (std::regex_search(line, m, indirect_re)) current->indirect = true;
    if (std::regex_search(line, m, call_re) && m[2].str() != current_name) current->callees.push_back(m[2].str());
  }
  std::map<std::string, long> memo;
  std::vector<std::string> path;
  std::function<long(const std::string&)> depth = [&](const std::string& name) -> long {
    if (const auto it = memo.find(name); it != memo.end()) return it->second;
    if (std::find(path.begin(), path.end(), name) != path.end()) {
      note = "recursion through " + name;
      return -1;
    }
    const auto f = functions.find(name);
    if (f == functions.end()) {
      note = "no code for " + name;
      return -1;
    }
    if (f->second.indirect) {
      note = "indirect call in " + name;
      return -1;
    }
    path.push_back(name);
    long deepest = 0;
    for (const std::string& c : f->second.callees) {
      const long d = depth(c);
      if (d < 0) return -1;
      deepest = std::max(deepest, d);
    }
    path.pop_back();
    return memo[name] = f->second.frame + deepest;
  };
  return depth(root);
}

}  // namespace

namespace {
/// The bench's marker functions' addresses in the ELF (jg_bench_begin, _end, _section).
std::map<std::string, unsigned long> bench_markers(const std::string& elf) {
  std::map<std::string, unsigned long> addr;
  std::istringstream nm(run_capture("arm-none-eabi-nm " + elf));
  for (std::string line; std::getline(nm, line);) {
    std::istringstream ls(line);
    std::string a, t, name;
    ls >> a >> t >> name;
    if (name == "jg_bench_begin" || name == "jg_bench_end" || name == "jg_bench_section") addr[name] = std::stoul(a, nullptr, 16);
  }
  return addr;
}

/// One trace line per instruction (-singlestep): "Trace N: 0x... [xxxxxxxx/PC/...]".
/// Sections open at jg_bench_section; within a section every begin/end pair is one cycle.
/// Returns [section][cycle] instructions.
std::vector<std::vector<long>> cycles_per_section(const std::string& log, std::map<std::string, unsigned long>& addr) {
  std::ifstream in(log);
  std::vector<std::vector<long>> cycles;  // [section][cycle] instructions
  long index = 0, begin = -1;
  for (std::string line; std::getline(in, line); ++index) {
    const auto open = line.find('[');
    if (line.rfind("Trace", 0) != 0 || open == std::string::npos) continue;
    const auto slash = line.find('/', open);
    if (slash == std::string::npos) continue;
    const unsigned long pc = std::strtoul(line.c_str() + slash + 1, nullptr, 16);
    if (pc == addr["jg_bench_section"]) {
      cycles.emplace_back();
    } else if (pc == addr["jg_bench_begin"]) {
      begin = index;
    } else if (pc == addr["jg_bench_end"] && begin >= 0 && !cycles.empty()) {
      // Lines strictly between the two markers, less the call into jg_bench_end.
      cycles.back().push_back(index - begin - 2);
      begin = -1;
    }
  }
  return cycles;
}

/// The painted stack ("stack drive_float N" / "stack drive_q N" on the bench's console) and
/// the core library's size (arm-none-eabi-size) into f.
void read_stack_and_size(const std::string& console, const std::string& core_lib, McuFigures& f) {
  std::istringstream con(console);
  for (std::string line; std::getline(con, line);) {
    std::istringstream ls(line);
    std::string word, name;
    long bytes = -1;
    if (ls >> word >> name >> bytes && word == "stack") {
      if (name == "drive_float") f.float_stack = bytes;
      if (name == "drive_q") f.q_stack = bytes;
    }
  }
  std::istringstream sz(core_lib.empty() ? std::string() : run_capture("arm-none-eabi-size -t " + core_lib));
  for (std::string line; std::getline(sz, line);) {
    if (line.find("(TOTALS)") != std::string::npos) {
      std::istringstream ls(line);
      ls >> f.text >> f.data >> f.bss;
    }
  }
}

}  // namespace

McuFigures measure_mcu(const std::string& elf, const std::string& core_lib, const std::string& machine) {
  McuFigures f;
  if (!std::filesystem::exists(elf)) {
    f.note = "cycle benchmark ELF not built (" + elf + "): build the host preset with the arm toolchain installed";
    return f;
  }
  std::map<std::string, unsigned long> addr = bench_markers(elf);
  const auto log = std::filesystem::temp_directory_path() / ("jg_trace_" + std::to_string(::getpid()) + ".log");
  const std::string cmd = "qemu-system-arm -M " + machine + " -nographic -monitor none -serial none "
                          "-semihosting-config enable=on,target=native -singlestep -d nochain,exec -D " +
                          log.string() + " -kernel " + elf + " 2>&1";
  int status = 0;
  const std::string console = run_capture(cmd, &status);
  if (status != 0 || addr.size() != 3) {
    std::filesystem::remove(log);
    f.note = "qemu run failed: " + console;
    return f;
  }
  std::vector<std::vector<long>> cycles = cycles_per_section(log.string(), addr);  // [section][cycle] instructions
  std::filesystem::remove(log);
  if (cycles.size() < 4 || cycles[0].empty() || cycles[1].empty() || cycles[2].empty() || cycles[3].empty()) {
    f.note = "markers not found in the trace";
    return f;
  }
  const auto mean = [](const std::vector<long>& v) {
    double sum = 0.0;
    for (const long x : v) sum += static_cast<double>(x);
    return sum / static_cast<double>(v.size());
  };
  const auto worst = [](const std::vector<long>& v) { return static_cast<double>(*std::max_element(v.begin(), v.end())); };
  constexpr double kEstimatorCycles = 20.0;  // tests/mcu/cycle_bench.cpp: one pair around 20 cycles
  f.float_insns = mean(cycles[0]) / kEstimatorCycles;
  f.q_insns = mean(cycles[1]) / kEstimatorCycles;
  f.float_drive_insns = mean(cycles[2]);
  f.q_drive_insns = mean(cycles[3]);
  f.float_drive_max = worst(cycles[2]);
  f.q_drive_max = worst(cycles[3]);
  read_stack_and_size(console, core_lib, f);
  std::string note;
  f.float_stack_static = static_stack(elf, "jg::JointDrive<float, jg::hal::LoopbackCan<8u> >::poll()", note);
  f.q_stack_static = static_stack(elf, "jg::JointDrive<jg::Q<16>, jg::hal::LoopbackCan<8u> >::poll()", note);
  f.ok = f.float_stack > 0 && f.q_stack > 0;
  if (!f.ok) f.note = "stack figures missing from the bench's console output";
  if (f.float_stack_static < 0 || f.q_stack_static < 0) f.note += (f.note.empty() ? "" : "; ") + ("static stack unknown: " + note);
  return f;
}

namespace {
/// Another cross build's figures.
struct OtherTarget {
  const char* cpu;
  const char* machine;
  McuFigures figures;
};

/// The FPU-less Cortex-M3 and the Armv8-M Cortex-M33, when their cross builds exist.
std::vector<OtherTarget> measure_other_targets() {
  std::vector<OtherTarget> others;
  for (const auto& [cpu, machine] : {std::pair{"cortex-m3", "mps2-an385"}, std::pair{"cortex-m33", "mps2-an505"}}) {
    const std::string elf = mcu_build_dir(cpu) + "/toolchain/mcu/jg_cycle_bench.elf";
    if (std::filesystem::exists(elf)) others.push_back({cpu, machine, measure_mcu(elf, "", machine)});
  }
  return others;
}

/// One scalar's figures in the JSON.
nlohmann::json scalar_json(double joint, double drive, double drive_max, long stack, long stack_static) {
  return nlohmann::json{{"instructions_per_joint_cycle", joint},
                        {"instructions_per_drive_cycle", drive},
                        {"instructions_per_drive_cycle_max", drive_max},
                        {"stack_bytes", stack},
                        {"stack_bytes_static", stack_static}};
}

/// The JSON's "firmware": the Cortex-M4F's figures, the other targets' and the definitions.
nlohmann::json firmware_json(const McuFigures& m, const std::vector<OtherTarget>& others) {
  nlohmann::json targets = nlohmann::json::object();
  for (const OtherTarget& o : others) {
    const McuFigures& f = o.figures;
    targets[o.cpu] = {{"machine", o.machine}, {"measured", f.ok}, {"note", f.note},
                      {"scalar", {{"float", scalar_json(f.float_insns, f.float_drive_insns, f.float_drive_max, f.float_stack, f.float_stack_static)},
                                  {"q", scalar_json(f.q_insns, f.q_drive_insns, f.q_drive_max, f.q_stack, f.q_stack_static)}}}};
  }
  return nlohmann::json{{"targets", targets},
      {"target", "cortex-m4"},
      {"scalar",
       {{"float", scalar_json(m.float_insns, m.float_drive_insns, m.float_drive_max, m.float_stack, m.float_stack_static)},
        {"q", scalar_json(m.q_insns, m.q_drive_insns, m.q_drive_max, m.q_stack, m.q_stack_static)}}},
      {"text", m.text}, {"data", m.data}, {"bss", m.bss}, {"measured", m.ok}, {"note", m.note},
      {"definitions",
       {{"joint_cycle", "estimator: outward + inward step, LuGre, observer, detector (mean of 20)"},
        {"drive_cycle", "JointDrive::poll of joint 2 of 3 over the loopback port: sync, both neighbour frames "
                        "checked and decoded, estimator, both frames encoded, status frame, one collision "
                        "event (mean and worst of 20)"},
        {"stack_bytes", "deepest stack of a drive cycle, measured by stack painting under qemu"},
        {"stack_bytes_static", "worst-case stack of JointDrive::poll over its call graph from the ELF's disassembly "
                               "(every frame's stack-pointer decrements, newlib included)"}}}};
}

void print_firmware(const McuFigures& m, const std::vector<OtherTarget>& others) {
  for (const OtherTarget& o : others) {
    const McuFigures& f = o.figures;
    if (f.ok) {
      std::printf("%s (qemu -M %s): estimator float %.0f, Q16.16 %.0f; drive cycle float %.0f (worst %.0f), "
                  "Q16.16 %.0f (worst %.0f); stack float %ld B, Q16.16 %ld B (static %ld B, %ld B)\n",
                  o.cpu, o.machine, f.float_insns, f.q_insns, f.float_drive_insns, f.float_drive_max, f.q_drive_insns,
                  f.q_drive_max, f.float_stack, f.q_stack, f.float_stack_static, f.q_stack_static);
    } else {
      std::printf("%s figures unavailable: %s\n", o.cpu, f.note.c_str());
    }
  }
  if (m.ok) {
    std::printf("Cortex-M4F (instructions counted under qemu):\n"
                "  estimator cycle (outward + inward + LuGre + observer + detector): float %.0f, Q16.16 %.0f\n"
                "  drive cycle (JointDrive::poll: sync, 2 neighbour frames, estimator, 2 frames, status, event):\n"
                "    float %.0f (worst %.0f), Q16.16 %.0f (worst %.0f)\n"
                "  drive cycle stack: painted float %ld B, Q16.16 %ld B; static worst case float %ld B, Q16.16 %ld B\n"
                "  core text %ld, data %ld, bss %ld bytes\n",
                m.float_insns, m.q_insns, m.float_drive_insns, m.float_drive_max, m.q_drive_insns, m.q_drive_max,
                m.float_stack, m.q_stack, m.float_stack_static, m.q_stack_static, m.text, m.data, m.bss);
  } else {
    std::printf("Cortex-M4F figures unavailable: %s\n", m.note.c_str());
  }
}

/// The host's speed: 60 s of the reference arm at 1 kHz (plant, sensors, controller),
/// recording off, against the wall clock; one paper-sized GA run.
struct HostFigures {
  double simulated_s = 0.0, sim_wall = 0.0, ga_s = 0.0;
};

HostFigures measure_host() {
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
  return {r.simulated_s, sim_wall, ga_s};
}
}  // namespace

Command add_bench(CLI::App& app) {
  auto json = std::make_shared<std::string>();
  auto firmware_only = std::make_shared<bool>(false);
  auto* cmd = app.add_subcommand("bench",
                                 "Measure the firmware's instructions per joint cycle on the Cortex-M4F (qemu), its size,\n"
                                 "the simulation's speed and the identification time.\n"
                                 "Example: jointguard bench --json out/bench.json");
  cmd->add_option("--json", *json, "Write the figures here (contract format)")->check(output_file());
  cmd->add_flag("--firmware-only", *firmware_only,
                "Only the Cortex-M4F figures (no host simulation or identification timing); exit 1 when they cannot be measured");
  return {cmd, [json, firmware_only]() {
            const std::string mcu = mcu_build_dir();
            const McuFigures m = measure_mcu(mcu + "/toolchain/mcu/jg_cycle_bench.elf", mcu + "/firmware/libjg_core.a");
            const std::vector<OtherTarget> others = measure_other_targets();
            if (*firmware_only) {
              print_firmware(m, others);
              if (!json->empty()) {
                write_json_file(*json, nlohmann::json{{"firmware", firmware_json(m, others)}});  // with the identity
                std::printf("wrote %s\n", json->c_str());
              }
              bool all = m.ok;
              for (const OtherTarget& o : others) all = all && o.figures.ok;
              return all ? 0 : 1;
            }
            const HostFigures h = measure_host();
            print_firmware(m, others);
            std::printf("host: simulation %.0fx real time (3-joint arm, 1 kHz control, 2 kHz plant); one paper-sized GA run %.3f s\n",
                        h.simulated_s / h.sim_wall, h.ga_s);
            if (!json->empty()) {
              nlohmann::json j;
              j["firmware"] = firmware_json(m, others);
              j["host"] = {{"sim_realtime_factor", h.simulated_s / h.sim_wall}, {"identify_seconds", h.ga_s},
                           {"identify_definition", "one GA run, population 200 x 300 generations, 1251 samples"}};
              write_json_file(*json, j);  // with the identity
              std::printf("wrote %s\n", json->c_str());
            }
            return 0;
          }};
}

}  // namespace jg::cli
