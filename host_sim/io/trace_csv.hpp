// The detector's estimate over time as CSV: one writer for every command that traces
// (`replay --trace`, the host-in-the-loop runs' `--trace`), so the files read the same.
#pragma once

#include <string>
#include <vector>

namespace jg::io {

/// Header `t,mu<id>...`, then one row per sample: t [s] to 1 us (%.6f), each joint's
/// estimate [N·m] to 9 significant digits (%.9g: a float's or a Q16.16 value's every digit).
/// `mu` is [joint][sample]; `joint_ids` names the columns (mu1, mu2, ...); rows run to the
/// shortest of t and the mu columns.
[[nodiscard]] std::string trace_csv(const std::vector<double>& t, const std::vector<std::vector<double>>& mu,
                                    const std::vector<int>& joint_ids);

/// Joint ids 1..n, for a trace whose joints are the arm's in order.
[[nodiscard]] std::vector<int> joint_ids_1_to(std::size_t n);

}  // namespace jg::io
