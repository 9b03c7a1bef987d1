// libFuzzer target: the DBC reader (can::read_dbc), then every signal of every message
// decoded from a payload of the message's length (can::decode_signal), as `decode` does.
#include <stdexcept>

#include "can/dbc.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = jg::fuzz::write_input(data, size, "bus.dbc");
  jg::fuzz::expect_clean<std::runtime_error>(path, [&] {
    const jg::can::Dbc dbc = jg::can::read_dbc(path);
    std::uint8_t payload[64];
    for (std::size_t i = 0; i < sizeof payload; ++i) payload[i] = static_cast<std::uint8_t>(0xA5U ^ (i * 37U));
    for (const auto& [id, m] : dbc.messages) {
      for (const auto& s : m.signals) (void)jg::can::decode_signal(s, payload, m.length);
    }
  });
  return 0;
}
