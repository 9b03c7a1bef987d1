// libFuzzer target: recording CSV as every command reads it: io::read_recording, then
// io::regularize (uniform segments) and its one-line summary.
#include "fuzz_common.hpp"
#include "io/recording.hpp"
#include "io/regularize.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = jg::fuzz::write_input(data, size, "rec.csv");
  jg::fuzz::expect_clean<jg::io::FormatError>(path, [&] {
    const jg::io::Recording rec = jg::io::read_recording(path);
    const jg::io::Regularized r = jg::io::regularize(rec, {}, path);
    (void)r.report.summary();
  });
  return 0;
}
