// Helpers shared by the subcommands: options every command spells the same way.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "jointguard/observer/momentum_observer.hpp"

namespace jg::cli {

/// --observer first_order|lowpass2|paper_bandpass|paper_improved and --gains K1[,K2[,K3]].
struct ObserverOptions {
  std::string preset = "first_order";
  std::vector<double> gains{150.0};
  void add_to(CLI::App* cmd);
  [[nodiscard]] ObserverGains to_gains() const;
};

void check_scalar(const std::string& scalar);

}  // namespace jg::cli
