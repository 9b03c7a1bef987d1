// Instruction-count benchmark of one joint's full estimation cycle on the Cortex-M4F
// (outward step, inward step, LuGre, observer, detector) in float and Q16.16. qemu has no
// cycle model: `jointguard bench` runs this under qemu -singlestep with execution tracing
// and counts the instructions executed between the markers.
#include "../common/shoulder_link.hpp"
#include "jointguard/node/joint_estimator.hpp"
#include "semihosting.hpp"

extern "C" {
__attribute__((noinline)) void jg_bench_begin(int scalar) { __asm volatile("" ::"r"(scalar) : "memory"); }
__attribute__((noinline)) void jg_bench_end(int scalar) { __asm volatile("" ::"r"(scalar) : "memory"); }
}

namespace {
constexpr int kCycles = 20;

template <class S>
void run(int id) {
  // The reference arm's shoulder (joint 2) with the paper's joint-2 friction at 1 kHz.
  const jg::LinkDescription d = jg::test::shoulder_link();
  static jg::JointEstimatorParams<S> p{};
  static jg::JointEstimatorState<S> s{};
  (void)jg::convert_link(d, p.link);
  // Discretised on the host for the paper's joint 2 at dT = 1 ms (values of discretize()).
  p.friction.bristle_gain = jg::from_double<S>(95.4878562);
  p.friction.bristle_damping = jg::from_double<S>(5.2303);
  p.friction.viscous = jg::from_double<S>(6.1838);
  p.friction.curve = {jg::from_double<S>(8.1855), jg::from_double<S>(4.5407 - 8.1855), jg::from_double<S>(1.0 / 0.0996)};
  p.observer.sections = 1;
  p.observer.decay[0] = jg::from_double<jg::precise_coefficient_t<S>>(0.860707976);
  p.observer.input_gain[0] = jg::from_double<jg::precise_coefficient_t<S>>(0.139292024);
  p.observer.inv_dt = jg::from_double<S>(1000.0);
  p.threshold = {jg::from_double<S>(2.0), S{}, jg::from_double<S>(3.0), jg::from_double<S>(33.3)};
  p.debounce = {2};
  jg::OutwardMessage<S> parent{};
  parent.angular_velocity.z = jg::from_double<S>(0.3);
  parent.gravity.z = jg::from_double<S>(-9.81);
  jg::InwardMessage<S> child{};
  child.mass = jg::from_double<S>(2.0);
  child.first_moment = {jg::from_double<S>(0.36), S{}, S{}};
  jg::OutwardMessage<S> to_child{};
  jg::InwardMessage<S> to_parent{};
  S q = jg::from_double<S>(0.6), dq = jg::from_double<S>(0.4), tau = jg::from_double<S>(20.0);
  const S step = jg::from_double<S>(0.001);
  jg_bench_begin(id);
  for (int k = 0; k < kCycles; ++k) {
    (void)jg::joint_outward(p, s, q, dq, parent, to_child);
    (void)jg::joint_inward_and_estimate(p, s, dq, tau, child, to_parent);
    q = q + step;
    dq = dq - step;
  }
  jg_bench_end(id);
}
}  // namespace

extern "C" int jg_app_main() {
  run<float>(0);
  run<jg::q16>(1);
  jg::mcu::write_text("cycle bench: done\n");
  return 0;
}
