// The joint drive in C++: the package's JointDrive bound to its STM32G4 FDCAN backend, CRC
// unit and TIM2 clock (docs/porting.md sections 3 and 7), the firmware scalar chosen when the package
// was built (jg::Scalar). Constants are converted once at start-up with range checks; the
// loop samples, polls the bus (the master's sync paces the cycle) and reacts to a collision.
#include <cstdint>

#include "board.h"
#include "joint_constants.h"
#include "jointguard/hal/mcu/stm32g4_clock.hpp"
#include "jointguard/hal/mcu/stm32g4_crc.hpp"
#include "jointguard/hal/mcu/stm32g4_fdcan.hpp"
#include "jointguard/node/joint_drive.hpp"
#include "jointguard/scalar.hpp"

namespace {
namespace g4 = jg::hal::stm32g4;
// The FDCAN port with the CRC unit as the frames' CRC-8/AUTOSAR (polynomial 0x2F, init and
// final XOR 0xFF): the drive encodes and checks every frame on the unit instead of the
// software table; the frames are the same bytes (tests/can/test_crc_policy.cpp).
using Port = g4::PortWithCrcUnit<g4::FdcanPort<g4::Mmio, g4::Tim2Clock<g4::Mmio>>>;
using S = jg::Scalar;

g4::Mmio mmio;
g4::Tim2Clock<g4::Mmio> clock_us(mmio);
Port port(mmio, clock_us, g4::FdcanConfig{});  // FDCAN1, PLL "Q" 80 MHz, 1/5 Mbit/s, TDC on

bool make_params(jg::JointEstimatorParams<S>& p) {
  jg::LinkDescription l{};
  l.a_prev = LINK_A_PREV;
  l.alpha_prev = LINK_ALPHA_PREV;
  l.d = LINK_D;
  l.mass = LINK_MASS;
  l.com[0] = LINK_COM_X;
  l.inertia_com[2] = LINK_INERTIA_ZZ;
  l.rotor_inertia = LINK_ROTOR_INERTIA;
  l.torque_constant = LINK_TORQUE_CONSTANT;
  l.current_limit = LINK_CURRENT_LIMIT;
  const jg::LuGreParams<double> f{LUGRE_SIGMA0, LUGRE_SIGMA1, LUGRE_SIGMA2, LUGRE_TAU_C, LUGRE_TAU_S, LUGRE_W_S};
  const jg::ObserverGains g{jg::ObserverKind::first_order, OBSERVER_GAIN, 0.0, 0.0};
  jg::NumericStatus st{};
  p.threshold = {jg::convert<S>(THRESHOLD_BASE, st), S{}, jg::convert<S>(THRESHOLD_LOW_SPEED_EXTRA, st),
                 jg::convert<S>(1.0 / THRESHOLD_LOW_SPEED_WIDTH, st)};
  // The holding detector: settle and reference in samples (the constants are far below the
  // counters' 65535), the reference's mean as a product.
  const auto samples = [](double seconds) { return static_cast<std::uint16_t>(seconds / SAMPLE_TIME_S + 0.5); };
  p.hold = {jg::convert<S>(HOLD_CHANGE_THRESHOLD, st), samples(HOLD_SETTLE_S), samples(HOLD_REFERENCE_S),
            jg::convert<S>(1.0 / samples(HOLD_REFERENCE_S), st)};
  p.holding_velocity_deadband = jg::convert<S>(HOLDING_VELOCITY_DEADBAND, st);
  return jg::convert_link(l, p.link) == jg::Error::ok && jg::discretize(f, SAMPLE_TIME_S, p.friction) == jg::Error::ok &&
         jg::discretize(g, SAMPLE_TIME_S, p.observer) == jg::Error::ok && st.ok();
}

S to_scalar(double x) {
  jg::NumericStatus st{};
  return jg::convert<S>(x, st);  // saturates (never wraps) when a sensor reads out of range
}
}  // namespace

int main() {
  board_init();
  g4::enable_crc_unit(mmio);  // clock gate on before the first frame is encoded
  jg::JointEstimatorParams<S> params{};
  if (!make_params(params) || !clock_us.start(160'000'000U)) {
    board_hold_position();  // constants that do not fit the scalar: never run the estimator
    for (;;) {
    }
  }
  jg::DriveConfig config{};
  config.node.joint = JOINT_NUMBER;
  config.node.joints = JOINT_COUNT;
  static jg::JointDrive<S, Port> drive(config, params, port, {S{}, S{}, to_scalar(-9.81)});  // sets the filters
  if (port.start() != g4::FdcanError::none) {
    board_hold_position();
    for (;;) {
    }
  }
  std::uint32_t ticks = 0;
  for (;;) {
    board_wait_for_sample_tick();
    drive.set_sample(to_scalar(board_link_position_rad()), to_scalar(board_link_velocity_rad_s()),
                     to_scalar(board_motor_torque_nm()), board_holding_setpoint());
    if (!drive.poll() && ++ticks % 100U == 0U) {
      drive.announce();  // until the master's first sync: "booting" every 100 ms
    }
    if ((drive.last_status().flags & (jg::protocol::kStatusCollision | jg::protocol::kStatusCommFault)) != 0U) {
      board_hold_position();
    }
  }
}
