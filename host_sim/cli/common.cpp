#include "cli/common.hpp"

#include <stdexcept>

#include "tuning/observer_tuning.hpp"

namespace jg::cli {

void ObserverOptions::add_to(CLI::App* cmd) {
  cmd->add_option("--observer", preset, "Observer preset")
      ->check(CLI::IsMember({"first_order", "lowpass2", "paper_bandpass", "paper_improved"}))
      ->capture_default_str();
  cmd->add_option("--gains", gains,
                  "Observer gains K1[,K2[,K3]] [1/s] (first_order default: 150 at 500 Hz and above, 250 below)")
      ->delimiter(',');
}

ObserverGains ObserverOptions::to_gains(double rate_hz) const {
  if (gains.empty() && preset == "first_order") return tuning::default_gains(rate_hz);
  ObserverGains g;
  if (preset == "first_order") g.kind = ObserverKind::first_order;
  else if (preset == "lowpass2") g.kind = ObserverKind::lowpass2;
  else if (preset == "paper_bandpass") g.kind = ObserverKind::paper_bandpass;
  else g.kind = ObserverKind::paper_improved;
  const std::size_t needed = g.kind == ObserverKind::first_order ? 1 : (g.kind == ObserverKind::paper_improved ? 3 : 2);
  if (gains.size() < needed) {
    throw std::invalid_argument("--gains: the " + preset + " observer needs " + std::to_string(needed) +
                                " gains (K1[,K2[,K3]]), got " + std::to_string(gains.size()));
  }
  for (const double k : gains) {
    if (!(k > 0.0)) throw std::invalid_argument("--gains: every gain must be > 0 [1/s]");
  }
  g.k1 = gains[0];
  g.k2 = needed > 1 ? gains[1] : 0.0;
  g.k3 = needed > 2 ? gains[2] : 0.0;
  return g;
}

void add_model_selection(CLI::App* cmd, robot::LoadOptions& o) {
  cmd->add_option("--base", o.base_link, "URDF: first link of the chain (default: the root link)");
  cmd->add_option("--tip", o.tip_link, "URDF: last link of the chain (default: the deepest tip)");
  cmd->add_option("--drive", o.drive_file, "Drive parameters by joint name (YAML: joints, k_i, ...; docs/robot-model.md)")
      ->check(CLI::ExistingFile);
}

void check_scalar(const std::string& scalar) {
  if (scalar != "float" && scalar != "q") throw std::invalid_argument("--scalar must be float or q");
}

}  // namespace jg::cli
