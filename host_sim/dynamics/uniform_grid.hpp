// Stop-gap until the recordings' own resampler (host_sim/io) is merged: puts a recording
// with jittered time stamps onto a uniform grid by time stamp, so that identification can
// take real logs. Rows that repeat the previous row's state (q and dq equal: the logger
// read the same state twice) are dropped first; then every numeric column is linearly
// interpolated at t0 + k dt; `collision` takes the previous row's value.
#pragma once

#include <string>

#include "io/recording.hpp"

namespace jg::dyn {

/// True when every step is within 1 % of the median step.
[[nodiscard]] bool is_uniform(const io::Recording& rec);

/// dt <= 0: the median step of the kept rows. `note` (optional) receives what was done.
/// Throws std::invalid_argument for fewer than two distinct rows or a gap over max(20 median
/// steps, 50 ms) between distinct rows (repeated states at rest leave shorter gaps).
[[nodiscard]] io::Recording to_uniform_grid(const io::Recording& rec, double dt, std::string* note = nullptr);

}  // namespace jg::dyn
