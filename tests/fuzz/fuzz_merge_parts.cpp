// libFuzzer target: the parts that `evaluate --shard K/N` writes, as `jointguard merge` reads
// them (cli::merge_partials, host_sim/cli/merge_parts.cpp): the input alone, and the input
// given twice (the second copy is compared with the first: identity, totals, configuration,
// then refused as the same shard twice, or taken as another shard of a one-run campaign).
#include <stdexcept>

#include "cli/evaluate_output.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string a = jg::fuzz::write_input(data, size, "part1.json");
  jg::fuzz::expect_clean<std::invalid_argument>(a, [&] { (void)jg::cli::merge_partials({a}); });
  const std::string b = jg::fuzz::write_input(data, size, "part2.json");
  // An error about the second copy names it (an existing file), else the first.
  jg::fuzz::expect_clean<std::invalid_argument>(a, [&] { (void)jg::cli::merge_partials({a, b}); }, true);
  return 0;
}
