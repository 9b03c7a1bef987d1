// Google Benchmark of the firmware core on the host: one joint's full cycle and its parts,
// in float and Q16.16. Run: ./build/host/tests/bench/jg_bench_core (not part of ctest).
#include <benchmark/benchmark.h>

#include "../common/shoulder_link.hpp"
#include "jointguard/node/joint_estimator.hpp"

namespace {
template <class S>
struct Fixture {
  jg::JointEstimatorParams<S> p{};
  jg::JointEstimatorState<S> s{};
  jg::OutwardMessage<S> parent{}, to_child{};
  jg::InwardMessage<S> child{}, to_parent{};
  Fixture() {
    const jg::LinkDescription d = jg::test::shoulder_link();
    (void)jg::convert_link(d, p.link);
    (void)jg::discretize(jg::LuGreParams<double>{95487.8562, 499.4331, 6.1838, 8.1855, 4.5407, 0.0996}, 0.001, p.friction);
    (void)jg::discretize(jg::ObserverGains{jg::ObserverKind::first_order, 150.0, 0.0, 0.0}, 0.001, p.observer);
    p.threshold = {jg::from_double<S>(2.0), S{}, jg::from_double<S>(3.0), jg::from_double<S>(33.3)};
    parent.gravity.z = jg::from_double<S>(-9.81);
    child.mass = jg::from_double<S>(2.0);
  }
};

template <class S>
void JointCycle(benchmark::State& state) {
  Fixture<S> f;
  S q = jg::from_double<S>(0.6), dq = jg::from_double<S>(0.4);
  const S tau = jg::from_double<S>(20.0), step = jg::from_double<S>(1e-4);
  for (auto _ : state) {
    (void)jg::joint_outward(f.p, f.s, q, dq, f.parent, f.to_child);
    benchmark::DoNotOptimize(jg::joint_inward_and_estimate(f.p, f.s, dq, tau, f.child, f.to_parent));
    q = q + step;
    benchmark::ClobberMemory();
  }
}
BENCHMARK(JointCycle<float>);
BENCHMARK(JointCycle<jg::q16>);

template <class S>
void LuGreStep(benchmark::State& state) {
  Fixture<S> f;
  S w = jg::from_double<S>(0.3);
  const S step = jg::from_double<S>(-1e-4);
  for (auto _ : state) {
    benchmark::DoNotOptimize(jg::lugre_step(f.p.friction, f.s.friction, w));
    w = w + step;
  }
}
BENCHMARK(LuGreStep<float>);
BENCHMARK(LuGreStep<jg::q16>);
}  // namespace

BENCHMARK_MAIN();
