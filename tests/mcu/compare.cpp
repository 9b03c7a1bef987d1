// Compares the host's and the MCU's golden outputs: the Q16.16 section must be bit for
// bit identical; the float section within a tolerance (the MCU fuses multiply-adds and
// uses newlib's expf/sinf/cosf, the host neither), stated in docs/fixed-point.md.
// Usage: jg_golden_compare <host> <mcu> <float_tolerance_nm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s <host> <mcu> <float_tolerance>\n", argv[0]);
    return 2;
  }
  auto load = [](const char* p) {
    std::ifstream in(p, std::ios::binary);
    std::vector<unsigned char> v((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return v;
  };
  const auto a = load(argv[1]), b = load(argv[2]);
  const double tol = std::atof(argv[3]);
  if (a.empty() || a.size() != b.size() || a.size() % 4 != 0) {
    std::printf("FAIL: output sizes differ or empty (host %zu bytes, mcu %zu bytes)\n", a.size(), b.size());
    return 1;
  }
  const std::size_t words = a.size() / 4;
  auto word = [](const std::vector<unsigned char>& v, std::size_t i) {
    std::uint32_t w = 0;
    std::memcpy(&w, v.data() + 4 * i, 4);
    return w;
  };
  std::size_t marker = words;
  for (std::size_t i = 0; i < words; ++i) {
    if (word(a, i) == 0xF10A7000U) {
      marker = i;
      break;
    }
  }
  if (marker == words) {
    std::printf("FAIL: float section marker missing\n");
    return 1;
  }
  std::size_t q_diff = 0;
  for (std::size_t i = 0; i < marker; ++i) q_diff += word(a, i) != word(b, i) ? 1U : 0U;
  double worst = 0.0;
  std::size_t mask_diff = 0;
  const std::size_t float_end = words - 2;  // last two words: numeric status counters
  for (std::size_t i = marker + 1; i < float_end; ++i) {
    // Every 13th word of a sample is the detector mask (integer), the rest floats.
    if ((i - marker - 1) % 13 == 12) {
      mask_diff += word(a, i) != word(b, i) ? 1U : 0U;
      continue;
    }
    float fa = 0, fb = 0;
    const std::uint32_t wa = word(a, i), wb = word(b, i);
    std::memcpy(&fa, &wa, 4);
    std::memcpy(&fb, &wb, 4);
    worst = std::max(worst, static_cast<double>(std::fabs(fa - fb)));
  }
  std::printf("Q16.16 words compared: %zu, differing: %zu\n", marker, q_diff);
  std::printf("float values compared: %zu, worst |host - mcu|: %.3e (tolerance %.1e), detector masks differing: %zu\n",
              float_end - marker - 1, worst, tol, mask_diff);
  const bool ok = q_diff == 0 && worst <= tol && mask_diff == 0;
  std::printf("%s\n", ok ? "PASS" : "FAIL");
  return ok ? 0 : 1;
}
