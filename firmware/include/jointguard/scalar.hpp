// The project-wide firmware scalar, chosen once (CMake option JG_SCALAR -> JG_SCALAR_Q).
// Core algorithms are templates on their scalar; only the firmware application and the
// node code pick this alias. Host identification works in double and converts its
// parameters to this scalar with a range check (jg::convert).
#pragma once

#include "jointguard/numeric/q.hpp"
#include "jointguard/numeric/qmath.hpp"

#ifndef JG_SCALAR_Q
#define JG_SCALAR_Q 0
#endif

namespace jg {
#if JG_SCALAR_Q
using Scalar = q16;
inline constexpr const char* kScalarName = "q16.16";
#else
using Scalar = float;
inline constexpr const char* kScalarName = "float";
#endif
}  // namespace jg
