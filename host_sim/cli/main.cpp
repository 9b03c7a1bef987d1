// jointguard: the host command line. Exit codes: 0 success, 1 runtime failure,
// 2 usage error (bad arguments).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "cli/demo.hpp"

int main(int argc, char** argv) {
  CLI::App app{"jointguard: sensorless collision detection for robot arms (host tools)"};
  app.require_subcommand(1);

  jg::cli::DemoOptions demo;
  auto* demo_cmd = app.add_subcommand("demo", "Run the main job and print what it measured.\n"
                                              "Example: jointguard demo --out out");
  demo_cmd->add_option("--out", demo.out_dir, "Output directory")->capture_default_str();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    if (demo_cmd->parsed()) {
      return jg::cli::run_demo(demo);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "jointguard: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
