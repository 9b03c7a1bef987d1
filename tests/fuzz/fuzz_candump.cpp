// libFuzzer target: candump -L captures (can::read_candump_log).
#include <stdexcept>

#include "can/dbc.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = jg::fuzz::write_input(data, size, "capture.log");
  jg::fuzz::expect_clean<std::runtime_error>(path, [&] { (void)jg::can::read_candump_log(path); });
  return 0;
}
