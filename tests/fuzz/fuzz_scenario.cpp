// libFuzzer target: scenario files (sim::load_scenario). The seeds name `model: ref3.yaml`,
// a copy of models/ref3.yaml put beside the input once per process.
#include <filesystem>

#include "fuzz_common.hpp"
#include "io/recording.hpp"
#include "sim/scenario.hpp"

#ifndef JG_FUZZ_MODEL
#error "JG_FUZZ_MODEL: path of models/ref3.yaml"
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool model_copied = [] {
    std::filesystem::copy_file(JG_FUZZ_MODEL, jg::fuzz::work_dir() / "ref3.yaml",
                               std::filesystem::copy_options::overwrite_existing);
    return true;
  }();
  (void)model_copied;
  const std::string path = jg::fuzz::write_input(data, size, "scenario.yaml");
  jg::fuzz::expect_clean<jg::io::FormatError>(path, [&] {
    const jg::sim::Scenario s = jg::sim::load_scenario(path);
    (void)s;
  }, /*other_files=*/true);  // errors inside the robot file it names name that file
  return 0;
}
