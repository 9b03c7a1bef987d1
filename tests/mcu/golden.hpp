// Golden-output program shared by the host build and the emulated Cortex-M4F: the same
// source runs the firmware core (LuGre, Q math, momentum recursion, observer, detector)
// in float and Q16.16 on the same input file and writes every output. A CTest test
// compares the two output files: Q16.16 bit for bit, float within a stated tolerance.
#pragma once

#include <cstddef>
#include <cstdint>

namespace jg::golden {

inline constexpr std::uint32_t kMagic = 0x31474A4AU;  // "JJG1"
inline constexpr std::size_t kMaxSamples = 12000;

/// Runs the computation. `in`/`out` are caller-owned; returns 0 on success, else an
/// error code (bad magic, sizes) and writes nothing useful.
int run(const std::uint8_t* in, std::size_t in_len, std::uint8_t* out, std::size_t out_capacity, std::size_t& out_len);

}  // namespace jg::golden
