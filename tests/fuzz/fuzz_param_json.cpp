// libFuzzer target: the friction (--friction) and threshold (--threshold) JSON readers,
// alone and matched to the joints 1, 2, 3 of a recording.
#include "eval/pipeline.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = jg::fuzz::write_input(data, size, "params.json");
  const std::vector<int> joints{1, 2, 3};
  jg::fuzz::expect_clean<jg::io::FormatError>(path, [&] { (void)jg::eval::read_friction_json(path); });
  jg::fuzz::expect_clean<jg::io::FormatError>(path, [&] { (void)jg::eval::read_friction_json(path, joints); });
  jg::fuzz::expect_clean<jg::io::FormatError>(path, [&] { (void)jg::eval::read_threshold_json(path); });
  jg::fuzz::expect_clean<jg::io::FormatError>(path, [&] { (void)jg::eval::read_threshold_json(path, joints); });
  return 0;
}
