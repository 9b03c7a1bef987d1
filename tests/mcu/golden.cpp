#include "golden.hpp"

#include <limits>

#include "golden_io.hpp"
#include "jointguard/detection/detector.hpp"
#include "jointguard/detection/hold_detector.hpp"
#include "jointguard/dynamics/momentum_recursion.hpp"

namespace jg::golden {
namespace {
constexpr int kJoints = 3;

template <class S>
struct Setup {
  LuGreDiscrete<S> friction[kJoints]{};
  ObserverCoeffs<S> observer[kJoints]{};
  LinkConstants<S> links[kJoints]{};
};

template <class S>
void read_setup(Cursor& c, Setup<S>& s) {
  auto rd = [&c](auto& v) { get(c, v); };
  for (auto& f : s.friction) visit(f, rd);
  for (auto& o : s.observer) {
    o.sections = static_cast<std::uint8_t>(c.get32());
    visit(o, rd);
  }
  for (auto& l : s.links) visit(l, rd);
}

/// Every sample: momentum recursion, LuGre, observer with the prediction inside, detector
/// (band, and the holding detector over the pick task's 0.5 s dwell at the workpiece,
/// 3.2-3.7 s of make_input.cpp's run: its change bits are mask bits 3..5).
template <class S>
void run_chain(const Setup<S>& s, const float* samples, std::uint32_t n, Cursor& out, NumericStatus& st) {
  LuGreState<S> friction_state[kJoints]{};
  ObserverState<S> observer_state[kJoints]{};
  JointDetectorState detector[kJoints]{};
  HoldChangeState<S> hold[kJoints]{};
  const HoldChangeParams<S> hold_params{from_double<S>(0.3), 150U, 16U, from_double<S>(1.0 / 16.0)};
  const JointThreshold<S> threshold{from_double<S>(5.0), from_double<S>(2.0)};
  const Vec3<S> gravity{S{}, S{}, from_double<S>(-9.81)};
  for (std::uint32_t k = 0; k < n; ++k) {
    const float* row = samples + 9U * k;
    S q[kJoints], dq[kJoints], tau[kJoints];
    for (int j = 0; j < kJoints; ++j) {
      q[j] = from_float<S>(row[j], st);
      dq[j] = from_float<S>(row[3 + j], st);
      tau[j] = from_float<S>(row[6 + j], st);
    }
    JointMomentum<S> m[kJoints]{};
    chain_momentum(s.links, kJoints, q, dq, gravity, m);
    std::uint32_t mask = 0;
    for (int j = 0; j < kJoints; ++j) {
      const S f = lugre_step(s.friction[j], friction_state[j], dq[j]);
      const S r = observer_step(s.observer[j], observer_state[j], m[j].momentum, tau[j], m[j].beta, f);
      const bool holding = k >= 3200U && k < 3700U;
      const bool changed = hold_change_step(hold_params, hold[j], holding, -r);
      if (changed) mask |= 1U << static_cast<unsigned>(3 + j);
      if (detector_step(threshold, DebounceSettings{2}, detector[j], -r, dq[j], changed)) mask |= 1U << static_cast<unsigned>(j);
      put(out, m[j].momentum);
      put(out, m[j].beta);
      put(out, f);
      put(out, r);
    }
    out.put32(mask);
  }
}

void run_math(Cursor& out) {
  for (double x = -20.0; x < 5.0; x += 0.37) put(out, jg::exp(q16::from_double(x)));
  for (double x = -10.0; x < 10.0; x += 0.173) {
    put(out, jg::sin(q16::from_double(x)));
    put(out, jg::cos(q16::from_double(x)));
  }
  for (double x = 0.0; x < 100.0; x += 0.77) put(out, jg::sqrt(q16::from_double(x)));
  for (double a = -50.0; a < 50.0; a += 7.3) {
    for (double b = -3.0; b < 3.0; b += 0.41) put(out, jg::div(q16::from_double(a), q16::from_double(b)));
  }
  // Intermediate terms (QTerm): QADD/QSUB saturation in the full int32 range on the MCU
  // against the overflow builtins on the host, the rounding that keeps INT32_MIN, the
  // mapping of from_term, products with an INT32_MIN factor.
  const std::int32_t edges[] = {0, 1, -1, 65536, -65536, 2147483647, -2147483647, std::numeric_limits<std::int32_t>::min(),
                                1073741824, -1073741825, 123456789, -987654321};
  for (const std::int32_t a : edges) {
    const auto ta = QTerm<16>::from_raw(a);
    put(out, jg::square(ta));
    put(out, jg::from_term(ta));
    for (const std::int32_t b : edges) {
      const q16 qb = q16::from_raw(b);
      out.put32(static_cast<std::uint32_t>(jg::add_term(ta, qb).raw()));
      out.put32(static_cast<std::uint32_t>(jg::sub_term(ta, qb).raw()));
      out.put32(static_cast<std::uint32_t>(jg::sub_term(qb, ta).raw()));
      out.put32(static_cast<std::uint32_t>(jg::mul_term(ta, qb).raw()));
      out.put32(static_cast<std::uint32_t>(jg::sum_of_products_term(ta, qb, qb, ta).raw()));
      put(out, qb + ta);
      put(out, qb - ta);
      put(out, jg::mac(ta, qb, ta));
      put(out, jg::sum_of_products(ta, qb, qb, ta, ta, qb, qb, ta));
    }
  }
}
}  // namespace

int run(const std::uint8_t* in, std::size_t in_len, std::uint8_t* out, std::size_t out_capacity, std::size_t& out_len) {
  Cursor c{const_cast<std::uint8_t*>(in), in_len};
  if (c.get32() != kMagic) return 2;
  const std::uint32_t n = c.get32();
  if (n > kMaxSamples) return 3;
  static Setup<float> sf;
  static Setup<q16> sq;
  read_setup(c, sf);
  read_setup(c, sq);
  const std::size_t floats = 9U * n;
  if (!c.ok || c.pos + 4U * floats > in_len) return 4;
  static float samples[9 * kMaxSamples];
  for (std::size_t i = 0; i < floats; ++i) get(c, samples[i]);
  Cursor o{out, out_capacity};
  NumericStatus st{};
  // Section 1: Q16.16 (bit-identical expected), section 2: float.
  o.put32(n);
  run_chain(sq, samples, n, o, st);
  run_math(o);
  o.put32(0xF10A7000U);  // float section marker
  run_chain(sf, samples, n, o, st);
  o.put32(st.saturated);
  o.put32(st.not_finite);
  if (!o.ok) return 5;
  out_len = o.pos;
  return 0;
}

}  // namespace jg::golden
