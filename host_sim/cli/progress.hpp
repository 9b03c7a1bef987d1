// A progress bar with ETA on stderr, shown only when stderr is a terminal.
#pragma once

#include <chrono>
#include <string>

namespace jg::cli {

class Progress {
 public:
  explicit Progress(std::string label);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  void update(double fraction);  ///< 0..1; redraws at most 10 times a second
  void finish();

 private:
  std::string label_;
  bool enabled_;
  bool done_ = false;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace jg::cli
