// The golden comparison (host against MCU output), as a function so that its own test can
// feed it broken outputs. Layout (tests/mcu/golden.cpp): the Q16.16 section, the marker
// 0xF10A7000, the float section (13 words per sample: 12 floats, then the detector mask),
// then two status counters.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace jg::golden {

inline constexpr std::uint32_t kFloatMarker = 0xF10A7000U;
inline constexpr std::size_t kFloatWordsPerSample = 13;

struct Comparison {
  bool ok = false;
  std::string failure;  ///< why, when !ok (the first structural problem)
  std::size_t q_words = 0, q_diff = 0;
  std::size_t float_values = 0, not_finite = 0, mask_diff = 0, tail_diff = 0;
  double worst = 0.0;  ///< worst |host - mcu| over the finite float pairs
};

inline std::uint32_t word_at(const std::vector<unsigned char>& v, std::size_t i) {
  std::uint32_t w = 0;
  std::memcpy(&w, v.data() + 4 * i, 4);
  return w;
}

/// Every word is compared: Q16.16 words and detector masks bit for bit, the two trailing
/// status counters exactly, floats within `tolerance`; NaN or inf on either side fails.
inline Comparison compare(const std::vector<unsigned char>& a, const std::vector<unsigned char>& b, double tolerance) {
  Comparison c;
  if (a.empty() || a.size() != b.size() || a.size() % 4 != 0) {
    c.failure = "output sizes differ or empty (host " + std::to_string(a.size()) + " bytes, mcu " + std::to_string(b.size()) + ")";
    return c;
  }
  const std::size_t words = a.size() / 4;
  std::size_t marker = words;
  for (std::size_t i = 0; i < words; ++i) {
    if (word_at(a, i) == kFloatMarker) {
      marker = i;
      break;
    }
  }
  if (marker == words || word_at(b, marker) != kFloatMarker) {
    c.failure = "float section marker missing";
    return c;
  }
  if (words < marker + 3 || (words - marker - 3) % kFloatWordsPerSample != 0) {
    c.failure = "float section is not a whole number of samples followed by two status words";
    return c;
  }
  c.q_words = marker;
  for (std::size_t i = 0; i < marker; ++i) c.q_diff += word_at(a, i) != word_at(b, i) ? 1U : 0U;
  const std::size_t float_end = words - 2;
  for (std::size_t i = marker + 1; i < float_end; ++i) {
    if ((i - marker - 1) % kFloatWordsPerSample == kFloatWordsPerSample - 1) {
      c.mask_diff += word_at(a, i) != word_at(b, i) ? 1U : 0U;
      continue;
    }
    const std::uint32_t wa = word_at(a, i), wb = word_at(b, i);
    float fa = 0, fb = 0;
    std::memcpy(&fa, &wa, 4);
    std::memcpy(&fb, &wb, 4);
    ++c.float_values;
    if (!std::isfinite(fa) || !std::isfinite(fb)) {
      ++c.not_finite;
      continue;
    }
    const double d = std::fabs(static_cast<double>(fa) - static_cast<double>(fb));
    c.worst = d > c.worst ? d : c.worst;
  }
  for (std::size_t i = float_end; i < words; ++i) c.tail_diff += word_at(a, i) != word_at(b, i) ? 1U : 0U;
  c.ok = c.q_diff == 0 && c.not_finite == 0 && c.worst <= tolerance && c.mask_diff == 0 && c.tail_diff == 0;
  if (!c.ok) c.failure = "outputs differ";
  return c;
}

}  // namespace jg::golden
