#include "io/trace_csv.hpp"

#include <algorithm>
#include <cstdio>

namespace jg::io {

std::string trace_csv(const std::vector<double>& t, const std::vector<std::vector<double>>& mu,
                      const std::vector<int>& joint_ids) {
  std::string text = "t";
  for (const int id : joint_ids) text += ",mu" + std::to_string(id);
  text += '\n';
  std::size_t rows = t.size();
  for (const auto& m : mu) rows = std::min(rows, m.size());
  char buf[64];
  for (std::size_t k = 0; k < rows; ++k) {
    std::snprintf(buf, sizeof buf, "%.6f", t[k]);
    text += buf;
    for (const auto& m : mu) {
      std::snprintf(buf, sizeof buf, ",%.9g", m[k]);
      text += buf;
    }
    text += '\n';
  }
  return text;
}

std::vector<int> joint_ids_1_to(std::size_t n) {
  std::vector<int> ids(n);
  for (std::size_t j = 0; j < n; ++j) ids[j] = static_cast<int>(j) + 1;
  return ids;
}

}  // namespace jg::io
