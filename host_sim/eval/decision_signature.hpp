// The joints that take part in the isolation's decision by the size of their estimate, over
// the detection cycle and the aligned cycles after it (run_detection's `isolate`).
//
// A joint takes part when its estimate there exceeds its bar (a share of its threshold): by
// the largest value while the estimate keeps its sign (a contact's own torque builds), by the
// mean once the sign changes. The coupling of a sudden torque on a joint below into a joint
// above it rings, one cycle up and the next down (UR10e: the elbow +4.0 then -4.0 N·m after a
// 25 N·m push on the upper arm, the bar 2.4 N·m), and the mean cancels it; a contact on the
// joint itself keeps its sign and is taken at its largest.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "jointguard/detection/detector.hpp"

namespace jg::eval {

class DecisionSignature {
 public:
  explicit DecisionSignature(std::size_t joints) : sum_(joints, 0.0), low_(joints, 0.0), high_(joints, 0.0), cycles_(joints, 0) {}

  /// Joint `j`'s estimate on one cycle of the decision [N·m].
  void add(std::size_t j, double value) {
    const bool first = cycles_[j] == 0;
    low_[j] = first ? value : std::min(low_[j], value);
    high_[j] = first ? value : std::max(high_[j], value);
    sum_[j] += value;
    ++cycles_[j];
  }

  /// The size joint `j` takes part with [N·m]: its largest |value| while one sign, else |mean|;
  /// 0 before any cycle.
  [[nodiscard]] double size(std::size_t j) const {
    if (cycles_[j] == 0) return 0.0;
    const bool one_sign = low_[j] >= 0.0 || high_[j] <= 0.0;
    return one_sign ? std::max(std::fabs(low_[j]), std::fabs(high_[j])) : std::fabs(sum_[j] / cycles_[j]);
  }

  /// The joints whose size exceeds their bar [N·m], `bar[j]`.
  [[nodiscard]] JointMask mask(const std::vector<double>& bar) const {
    JointMask m = 0;
    for (std::size_t j = 0; j < sum_.size() && j < bar.size(); ++j) {
      if (size(j) > bar[j]) m |= static_cast<JointMask>(1U << j);
    }
    return m;
  }

 private:
  std::vector<double> sum_, low_, high_;
  std::vector<int> cycles_;
};

}  // namespace jg::eval
