// Error codes of the firmware core. The numbers are stable: they travel in CAN status
// frames and logs. Append new codes; never renumber.
#pragma once

#include <cstdint>

namespace jg {

enum class Error : std::uint8_t {
  ok = 0,
  not_finite = 1,         ///< NaN or infinity in an input or parameter
  out_of_range = 2,       ///< value does not fit the firmware scalar's range
  invalid_parameter = 3,  ///< physically meaningless parameter (e.g. negative stiffness)
};

[[nodiscard]] constexpr const char* to_string(Error e) noexcept {
  switch (e) {
    case Error::ok: return "ok";
    case Error::not_finite: return "not_finite";
    case Error::out_of_range: return "out_of_range";
    case Error::invalid_parameter: return "invalid_parameter";
  }
  return "unknown";
}

}  // namespace jg
