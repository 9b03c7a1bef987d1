// The golden comparison cannot miss: a NaN or inf on either side, a differing detector
// mask, a differing trailing status word or Q16.16 word, or a broken layout each fail it;
// identical outputs and differences within the tolerance pass.
#include <gtest/gtest.h>

#include <limits>

#include "compare.hpp"

namespace {
using jg::golden::compare;

std::vector<unsigned char> words(const std::vector<std::uint32_t>& w) {
  std::vector<unsigned char> v(4 * w.size());
  std::memcpy(v.data(), w.data(), v.size());
  return v;
}
std::uint32_t bits(float f) {
  std::uint32_t u = 0;
  std::memcpy(&u, &f, 4);
  return u;
}
// Two Q words, the marker, two samples (12 floats + mask each), two status words.
std::vector<std::uint32_t> golden() {
  std::vector<std::uint32_t> w = {7U, 0x12345678U, jg::golden::kFloatMarker};
  for (int s = 0; s < 2; ++s) {
    for (int k = 0; k < 12; ++k) w.push_back(bits(0.5F * static_cast<float>(k + s)));
    w.push_back(s == 1 ? 2U : 0U);
  }
  w.push_back(3U);
  w.push_back(0U);
  return w;
}

TEST(GoldenCompare, IdenticalAndWithinTolerancePass) {
  const auto a = golden();
  EXPECT_TRUE(compare(words(a), words(a), 2e-3).ok);
  auto b = a;
  b[3 + 5] = bits(2.5F + 1e-3F);
  EXPECT_TRUE(compare(words(a), words(b), 2e-3).ok);
  EXPECT_FALSE(compare(words(a), words(b), 1e-4).ok) << "over the tolerance";
}

TEST(GoldenCompare, NanOrInfOnEitherSideFails) {
  const auto a = golden();
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                          -std::numeric_limits<float>::infinity()}) {
    auto b = a;
    b[3 + 4] = bits(bad);
    EXPECT_FALSE(compare(words(a), words(b), 2e-3).ok) << "mcu side " << bad;
    EXPECT_FALSE(compare(words(b), words(a), 2e-3).ok) << "host side " << bad;
    EXPECT_FALSE(compare(words(b), words(b), 2e-3).ok) << "both sides " << bad;
  }
}

TEST(GoldenCompare, EveryOtherWordIsCompared) {
  const auto a = golden();
  const std::size_t last = a.size() - 1;
  for (const std::size_t i : {std::size_t{0}, std::size_t{1}, std::size_t{3 + 12}, std::size_t{3 + 25}, last - 1, last}) {
    auto b = a;
    b[i] ^= 1U;
    EXPECT_FALSE(compare(words(a), words(b), 2e-3).ok) << "word " << i;
  }
}

TEST(GoldenCompare, BrokenLayoutFails) {
  auto a = golden();
  EXPECT_FALSE(compare(words(a), words(std::vector<std::uint32_t>(a.begin(), a.end() - 1)), 2e-3).ok) << "sizes differ";
  a.pop_back();
  EXPECT_FALSE(compare(words(a), words(a), 2e-3).ok) << "not whole samples + two status words";
  auto no_marker = golden();
  no_marker[2] = 0U;
  EXPECT_FALSE(compare(words(no_marker), words(no_marker), 2e-3).ok);
  EXPECT_FALSE(compare({}, {}, 2e-3).ok);
}
}  // namespace
