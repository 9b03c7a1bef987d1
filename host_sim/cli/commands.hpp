// Subcommands of the jointguard CLI. Each registers itself on the app and returns the
// function that runs it once parsed. Exit codes (all subcommands):
//   0 success; 1 the work failed (bad input file, unusable data: the message says which);
//   2 bad command line (CLI11's usage message).
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

namespace jg::cli {

using Runner = std::function<int()>;
struct Command {
  CLI::App* app = nullptr;
  Runner run;
};

Command add_demo(CLI::App& app);
Command add_simulate(CLI::App& app);
Command add_identify(CLI::App& app);
Command add_calibrate(CLI::App& app);
Command add_replay(CLI::App& app);
Command add_evaluate(CLI::App& app);
Command add_merge(CLI::App& app);
Command add_diagnose(CLI::App& app);
Command add_inject(CLI::App& app);
Command add_bench(CLI::App& app);
Command add_node(CLI::App& app);
Command add_plant(CLI::App& app);
Command add_decode(CLI::App& app);
/// The effect catalogue (cli/effects.cpp).
Command add_effects(CLI::App& app);
/// identify, calibrate, replay and report in one command (cli/pipeline.cpp).
Command add_pipeline(CLI::App& app);

}  // namespace jg::cli
