// Compares the host's and the MCU's golden outputs (tests/mcu/compare.hpp): the Q16.16
// section bit for bit, the float section within a tolerance (the MCU fuses multiply-adds
// and uses newlib's expf/sinf/cosf, the host neither; docs/fixed-point.md), NaN or inf on
// either side a failure, detector masks and the two status counters exactly.
// Usage: jg_golden_compare <host> <mcu> <float_tolerance_nm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>

#include "compare.hpp"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s <host> <mcu> <float_tolerance>\n", argv[0]);
    return 2;
  }
  auto load = [](const char* p) {
    std::ifstream in(p, std::ios::binary);
    return std::vector<unsigned char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  char* end = nullptr;
  const double tol = std::strtod(argv[3], &end);
  if (end == argv[3] || *end != '\0' || !(tol >= 0.0) || !std::isfinite(tol)) {
    std::fprintf(stderr, "bad tolerance '%s': a finite number >= 0\n", argv[3]);
    return 2;
  }
  const jg::golden::Comparison c = jg::golden::compare(load(argv[1]), load(argv[2]), tol);
  if (!c.failure.empty() && c.q_words == 0) {
    std::printf("FAIL: %s\n", c.failure.c_str());
    return 1;
  }
  std::printf("Q16.16 words compared: %zu, differing: %zu\n", c.q_words, c.q_diff);
  std::printf("float values compared: %zu, not finite: %zu, worst |host - mcu|: %.3e (tolerance %.1e), "
              "detector masks differing: %zu, status counters differing: %zu\n",
              c.float_values, c.not_finite, c.worst, tol, c.mask_diff, c.tail_diff);
  std::printf("%s\n", c.ok ? "PASS" : "FAIL");
  return c.ok ? 0 : 1;
}
