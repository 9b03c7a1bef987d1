#include "cli/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace jg::cli {

Progress::Progress(std::string label)
    : label_(std::move(label)), enabled_(::isatty(STDERR_FILENO) != 0), start_(std::chrono::steady_clock::now()) {}

Progress::~Progress() { finish(); }

void Progress::update(double fraction) {
  if (!enabled_ || done_) {
    return;
  }
  const auto now = std::chrono::steady_clock::now();
  if (now - last_draw_ < std::chrono::milliseconds(100)) {
    return;
  }
  last_draw_ = now;
  fraction = std::clamp(fraction, 0.0, 1.0);
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double eta = fraction > 1e-3 ? elapsed * (1.0 - fraction) / fraction : 0.0;
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(fraction * kWidth);
  std::fprintf(stderr, "\r%s [%.*s%*s] %3.0f%%  ETA %4.0f s ", label_.c_str(), filled,
               "##############################", kWidth - filled, "", 100.0 * fraction, eta);
  std::fflush(stderr);
}

void Progress::finish() {
  if (enabled_ && !done_ && last_draw_.time_since_epoch().count() != 0) {
    std::fprintf(stderr, "\r%*s\r", static_cast<int>(label_.size()) + 60, "");
    std::fflush(stderr);
  }
  done_ = true;
}

}  // namespace jg::cli
