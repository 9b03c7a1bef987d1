#pragma once
#include <string>

namespace jg::cli {
struct DemoOptions {
  std::string out_dir = "out";
};
int run_demo(const DemoOptions& options);
}  // namespace jg::cli
