// Instruction-count and stack benchmark of the firmware on the emulated Cortex-M, in float
// and Q16.16. qemu has no cycle model: `jointguard bench` runs this under qemu -singlestep
// with execution tracing and counts the instructions executed between each
// jg_bench_begin/jg_bench_end pair; a jg_bench_section call opens the next section, in this
// fixed order (host_sim/cli/bench.cpp relies on it):
//   0 estimator, float    1 estimator, Q16.16    2 drive cycle, float    3 drive cycle, Q16.16
// Estimator sections: one pair around kCycles = 20 cycles; drive sections: one pair per cycle.
// Estimator cycle: one joint's outward step, inward step, LuGre, observer, detector.
// Drive cycle: JointDrive::poll of the middle joint of three over the loopback port, with
// the sample set as the MCU does (set_sample), the parent's outward and the child's inward
// frames (decoded, CRC and sequence checked), the master's sync, the estimator, both own
// frames encoded and sent, the status frame, and once the collision event.
// The worst stack depth of each drive cycle is measured by painting: the stack below the
// caller is filled with a pattern before the call and scanned after it. The figures are
// written to the console (semihosting) as "stack <section> <bytes>".
#include <cstdint>
#include <cstddef>

#include "../common/shoulder_link.hpp"
#include "jointguard/hal/loopback_can.hpp"
#include "jointguard/node/joint_drive.hpp"
#include "jointguard/node/joint_estimator.hpp"
#include "semihosting.hpp"

extern "C" {
__attribute__((noinline)) void jg_bench_section(int section) { __asm volatile("" ::"r"(section) : "memory"); }
__attribute__((noinline)) void jg_bench_begin() { __asm volatile("" ::: "memory"); }
__attribute__((noinline)) void jg_bench_end() { __asm volatile("" ::: "memory"); }
}

namespace {
constexpr int kCycles = 20;
constexpr int kWarmupCycles = 6;    ///< drive: the chain fills (joints + 1 cycles) before measuring
constexpr int kCollisionCycle = 8;  ///< drive: the motor torque jumps here (the event follows)
constexpr std::uint32_t kPaint = 0xC5A5C5A5U;
constexpr std::uint32_t kPaintBytes = 4096U;

template <class S>
jg::JointEstimatorParams<S> shoulder_params() {
  // The reference arm's shoulder (joint 2) with the paper's joint-2 friction at 1 kHz.
  jg::JointEstimatorParams<S> p{};
  (void)jg::convert_link(jg::test::shoulder_link(), p.link);
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
  return p;
}

template <class S>
void run_estimator() {
  static const jg::JointEstimatorParams<S> p = shoulder_params<S>();
  static jg::JointEstimatorState<S> s{};
  jg::OutwardMessage<S> parent{};
  parent.angular_velocity.z = jg::from_double<S>(0.3);
  parent.gravity.z = jg::from_double<S>(-9.81);
  jg::InwardMessage<S> child{};
  child.mass = jg::from_double<S>(2.0);
  child.first_moment = {jg::from_double<S>(0.36), S{}, S{}};
  jg::OutwardMessage<S> to_child{};
  jg::InwardMessage<S> to_parent{};
  S q = jg::from_double<S>(0.6), dq = jg::from_double<S>(0.4);
  const S tau = jg::from_double<S>(20.0);
  const S step = jg::from_double<S>(0.001);
  // One marker pair around all kCycles cycles (the host divides by kCycles): markers per
  // cycle would add their own register reloads to so short a cycle.
  jg_bench_begin();
  for (int k = 0; k < kCycles; ++k) {
    (void)jg::joint_outward(p, s, q, dq, parent, to_child);
    (void)jg::joint_inward_and_estimate(p, s, dq, tau, child, to_parent);
    q = q + step;
    dq = dq - step;
  }
  jg_bench_end();
}

using Port = jg::hal::LoopbackCan<8>;

std::uint32_t stack_pointer() {
  std::uint32_t sp = 0;
  __asm volatile("mov %0, sp" : "=r"(sp));
  return sp;
}

// Leaf without a frame of its own: fills [sp - bytes, sp - 64) with the pattern (the 64
// bytes right below sp stay untouched: this function's caller may still use them).
__attribute__((noinline)) void paint_below(std::uint32_t sp, std::uint32_t bytes) {
  for (std::uint32_t a = sp - bytes; a < sp - 64U; a += 4U) {
    *reinterpret_cast<volatile std::uint32_t*>(a) = kPaint;  // NOLINT(performance-no-int-to-ptr)
  }
}
__attribute__((noinline)) std::uint32_t untouched_below(std::uint32_t sp, std::uint32_t bytes) {
  std::uint32_t a = sp - bytes;
  while (a < sp && *reinterpret_cast<volatile const std::uint32_t*>(a) == kPaint) {  // NOLINT(performance-no-int-to-ptr)
    a += 4U;
  }
  return sp - a;
}

template <class S>
__attribute__((noinline)) bool drive_cycle(jg::JointDrive<S, Port>& drive, S q, S dq, S tau) {
  jg_bench_begin();
  drive.set_sample(q, dq, tau);
  const bool ran = drive.poll();
  jg_bench_end();
  return ran;
}

// What the bus delivers before cycle c: the neighbours' frames of cycle c - 1, then the sync.
template <class S>
void bus_delivers(Port& port, std::uint32_t c) {
  jg::hal::CanFrame f{};
  f.fd = true;
  jg::OutwardMessage<S> parent{};
  parent.angular_velocity.z = jg::from_double<S>(0.3);
  parent.gravity.z = jg::from_double<S>(-9.81);
  f.id = jg::protocol::frame_id(jg::protocol::MessageKind::outward, 1U);
  f.length = jg::protocol::encode_outward(parent, static_cast<std::uint8_t>(c - 1U), static_cast<std::uint8_t*>(f.data));
  (void)port.send(f);
  jg::InwardMessage<S> child{};
  child.mass = jg::from_double<S>(2.0);
  child.first_moment = {jg::from_double<S>(0.36), S{}, S{}};
  f.id = jg::protocol::frame_id(jg::protocol::MessageKind::inward, 3U);
  f.length = jg::protocol::encode_inward(child, static_cast<std::uint8_t>(c - 1U), static_cast<std::uint8_t*>(f.data));
  (void)port.send(f);
  f.id = jg::protocol::kSyncId;
  f.length = jg::protocol::encode_sync(c, static_cast<std::uint8_t*>(f.data));
  (void)port.send(f);
}

/// Returns false when a cycle did not run, a frame was rejected or no event was raised.
template <class S>
bool run_drive(const char* name) {
  static Port port{};
  static jg::JointDrive<S, Port> drive(jg::DriveConfig{jg::NodeConfig{2, 3, 5, 2}, false}, shoulder_params<S>(), port,
                                       jg::Vec3<S>{S{}, S{}, jg::from_double<S>(-9.81)});
  S q = jg::from_double<S>(0.6), dq = jg::from_double<S>(0.4);
  const S step = jg::from_double<S>(0.001);
  bool ok = true;
  std::uint32_t worst_stack = 0;
  jg::hal::CanFrame sink{};
  for (int k = 0; k < kWarmupCycles + kCycles; ++k) {
    bus_delivers<S>(port, static_cast<std::uint32_t>(k + 1));
    // Calm, then a contact: the observer sees the extra motor torque as external torque.
    const S tau = jg::from_double<S>(k >= kWarmupCycles + kCollisionCycle ? 60.0 : 20.0);
    if (k < kWarmupCycles) {
      drive.set_sample(q, dq, tau);
      ok = drive.poll() && ok;
    } else {
      const std::uint32_t sp = stack_pointer();
      paint_below(sp, kPaintBytes);
      ok = drive_cycle(drive, q, dq, tau) && ok;
      const std::uint32_t used = untouched_below(sp, kPaintBytes);
      worst_stack = used > worst_stack ? used : worst_stack;
    }
    while (port.receive(sink)) {
      ok = false;  // every frame for this drive must have been consumed by its cycle
    }
    q = q + step;
    dq = dq - step;
  }
  const jg::NodeCounters& nc = drive.node().counters();
  const jg::DriveCounters& dc = drive.counters();
  ok = ok && nc.wrong_length + nc.bad_crc + nc.stale + nc.late + nc.foreign + dc.sync_rejected + dc.foreign == 0U;
  ok = ok && (drive.last_status().flags & jg::protocol::kStatusCollision) != 0U && drive.node().ready();
  jg::mcu::write_text("stack ");
  jg::mcu::write_text(name);
  char digits[12] = {};
  std::size_t n = sizeof digits - 1U;
  do {
    digits[--n] = static_cast<char>('0' + worst_stack % 10U);
    worst_stack /= 10U;
  } while (worst_stack != 0U && n > 0U);
  jg::mcu::write_text(" ");
  jg::mcu::write_text(&digits[n]);
  jg::mcu::write_text("\n");
  return ok;
}
}  // namespace

extern "C" int jg_app_main() {
  jg_bench_section(0);
  run_estimator<float>();
  jg_bench_section(1);
  run_estimator<jg::q16>();
  jg_bench_section(2);
  const bool float_ok = run_drive<float>("drive_float");
  jg_bench_section(3);
  const bool q_ok = run_drive<jg::q16>("drive_q");
  jg_bench_section(4);
  if (!float_ok || !q_ok) {
    jg::mcu::write_text("cycle bench: FAIL (a drive cycle did not run, a frame was rejected or no event)\n");
    return 1;
  }
  jg::mcu::write_text("cycle bench: done\n");
  return 0;
}
