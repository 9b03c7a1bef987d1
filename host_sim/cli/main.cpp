// jointguard: the host command line. Exit codes: 0 success, 1 the work failed (the
// message names the file, line and field or what is missing), 2 bad command line.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <vector>

#include "cli/commands.hpp"
#include "cli/common.hpp"

int main(int argc, char** argv) {
  CLI::App app{"jointguard: sensorless collision detection for robot arms (host tools)"};
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Help for every subcommand");
  const std::vector<jg::cli::Command> commands = {
      jg::cli::add_simulate(app),  jg::cli::add_identify(app), jg::cli::add_calibrate(app),
      jg::cli::add_evaluate(app),  jg::cli::add_replay(app),   jg::cli::add_diagnose(app),
      jg::cli::add_bench(app),     jg::cli::add_demo(app),     jg::cli::add_node(app),
      jg::cli::add_plant(app),    jg::cli::add_decode(app),   jg::cli::add_merge(app),
      jg::cli::add_inject(app),   jg::cli::add_pipeline(app), jg::cli::add_effects(app),
  };
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  for (const auto& c : commands) {
    if (c.app->parsed()) {
      jg::cli::set_running_command(*c.app);  // the identity of what it writes (cli/common.hpp)
      try {
        return c.run();
      } catch (const std::exception& e) {
        std::fprintf(stderr, "jointguard %s: error: %s\n", c.app->get_name().c_str(), e.what());
        return 1;
      }
    }
  }
  return 2;
}
