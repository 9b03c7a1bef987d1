// A recording as a command holds it once read and regularized: its file name (for messages),
// its uniform segments and the torque kind its columns carry. Shared by the workflow's steps
// and the diagnosis, which both work on recordings a command read.
#pragma once

#include <stdexcept>
#include <string>

#include "io/recording.hpp"
#include "io/regularize.hpp"

namespace jg::io {

/// A recording read and regularized by time stamp (io/regularize.hpp).
struct LoadedRecording {
  std::string path;
  Regularized data;  ///< uniform segments and what was done
  TorqueKind torque = TorqueKind::tau_m;
  [[nodiscard]] const Recording& longest() const { return data.segments[data.report.longest()]; }
};

/// Runs `work`; an std::invalid_argument it throws (the data cannot give what is asked:
/// too short, never moving, ...) is re-thrown with the recording's file name in front.
template <class Work>
auto about_recording(const std::string& path, Work&& work) -> decltype(work()) {
  try {
    return work();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(path + ": " + e.what());
  }
}

}  // namespace jg::io
