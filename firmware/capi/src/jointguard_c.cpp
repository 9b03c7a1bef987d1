// The C API (capi/include/jointguard.h) over the core's templates, instantiated for the
// package's scalar (jg::Scalar). Everything the C caller holds is placement-constructed in
// its own storage; sizes are checked here at compile time against the header's bounds.
// No allocation: placement new only constructs an object in the caller's storage (the
// standard way to start an object's lifetime there; the non-throwing, non-allocating form
// from <new>, inlined: `ctest -R mcu.capi_no_heap` checks the archive references no
// operator new, __cxa_* or unwinding). No exceptions, no RTTI: the same flags as the core.
#include "jointguard.h"

#include <cmath>
#include <cstring>
#include <new>
#include <type_traits>

#include "jointguard/hal/can.hpp"
#include "jointguard/node/joint_drive.hpp"
#include "jointguard/node/joint_estimator.hpp"
#include "jointguard/scalar.hpp"

namespace {
using jg::Scalar;
using Params = jg::JointEstimatorParams<Scalar>;
using State = jg::JointEstimatorState<Scalar>;

static_assert(std::is_same_v<jg_scalar, std::conditional_t<jg::is_q_v<Scalar>, std::int32_t, float>>,
              "jointguard.h's jg_scalar must match the library's scalar (JG_SCALAR_Q)");
static_assert(static_cast<int>(JG_NOT_FINITE) == static_cast<int>(jg::Error::not_finite) &&
                  static_cast<int>(JG_OUT_OF_RANGE) == static_cast<int>(jg::Error::out_of_range) &&
                  static_cast<int>(JG_INVALID_PARAMETER) == static_cast<int>(jg::Error::invalid_parameter),
              "C error numbers are the core's");
static_assert(JG_STATUS_COLLISION == jg::protocol::kStatusCollision && JG_STATUS_COMM_FAULT == jg::protocol::kStatusCommFault &&
                  JG_STATUS_READY == jg::protocol::kStatusReady && JG_STATUS_INPUT_FAULT == jg::protocol::kStatusInputFault &&
                  JG_STATUS_BOOTING == jg::protocol::kStatusBooting,
              "C status bits are the frame's");

// ---- scalar <-> jg_scalar (bit for bit: Q16.16 travels as its raw int32) ----
// Templates only so that `if constexpr` discards the other scalar's branch.
template <class S = Scalar>
S from_c(jg_scalar v) noexcept {
  if constexpr (jg::is_q_v<S>) {
    return S::from_raw(v);
  } else {
    return v;
  }
}
template <class S>
jg_scalar to_c(S v) noexcept {
  if constexpr (jg::is_q_v<S>) {
    return v.raw();
  } else {
    return v;
  }
}
jg::Vec3<Scalar> vec_from_c(const jg_scalar (&v)[3]) noexcept { return {from_c(v[0]), from_c(v[1]), from_c(v[2])}; }
void vec_to_c(const jg::Vec3<Scalar>& v, jg_scalar (&out)[3]) noexcept {
  out[0] = to_c(v.x);
  out[1] = to_c(v.y);
  out[2] = to_c(v.z);
}
jg::OutwardMessage<Scalar> from_c(const jg_outward_message& m) noexcept {
  return {vec_from_c(m.angular_velocity), vec_from_c(m.origin_velocity), vec_from_c(m.gravity)};
}
void to_c(const jg::OutwardMessage<Scalar>& m, jg_outward_message& out) noexcept {
  vec_to_c(m.angular_velocity, out.angular_velocity);
  vec_to_c(m.origin_velocity, out.origin_velocity);
  vec_to_c(m.gravity, out.gravity);
}
jg::InwardMessage<Scalar> from_c(const jg_inward_message& m) noexcept {
  return {vec_from_c(m.angular_momentum), vec_from_c(m.linear_momentum), vec_from_c(m.first_moment), from_c(m.mass)};
}
void to_c(const jg::InwardMessage<Scalar>& m, jg_inward_message& out) noexcept {
  vec_to_c(m.angular_momentum, out.angular_momentum);
  vec_to_c(m.linear_momentum, out.linear_momentum);
  vec_to_c(m.first_moment, out.first_moment);
  out.mass = to_c(m.mass);
}

jg_error c_error(jg::Error e) noexcept { return static_cast<jg_error>(static_cast<int>(e)); }

// ---- storage: the C unions hold the C++ objects ----
template <class T, class Storage>
T* object_in(Storage* s) noexcept {
  static_assert(sizeof(T) <= sizeof(Storage), "the object does not fit the C API's storage: raise JG_*_BYTES");
  static_assert(alignof(T) <= alignof(Storage), "the C API's storage is not aligned enough for the object");
  return std::launder(static_cast<T*>(static_cast<void*>(s)));
}
template <class T, class Storage>
const T* object_in(const Storage* s) noexcept {
  static_assert(sizeof(T) <= sizeof(Storage), "the object does not fit the C API's storage: raise JG_*_BYTES");
  return std::launder(static_cast<const T*>(static_cast<const void*>(s)));
}

/// The C port as a HAL backend: the drive is a template on it, like on every other port.
class CallbackPort {
 public:
  explicit CallbackPort(const jg_can_port& ops) noexcept : ops_(ops) {}
  // const: the port only forwards to the board's callbacks (its own state is the ops table).
  [[nodiscard]] jg::hal::CanStatus send(const jg::hal::CanFrame& f) const noexcept {
    jg_can_frame c{};
    c.id = f.id;
    c.length = f.length;
    c.fd = f.fd;
    c.extended = f.extended;
    c.timestamp_us = f.timestamp_us;
    std::memcpy(static_cast<void*>(c.data), static_cast<const void*>(f.data), f.length <= 64U ? f.length : 64U);
    return static_cast<jg::hal::CanStatus>(ops_.send(ops_.context, &c));
  }
  bool receive(jg::hal::CanFrame& f) const noexcept {
    jg_can_frame c{};
    if (!ops_.receive(ops_.context, &c)) {
      return false;
    }
    f.id = c.id;
    f.length = c.length <= 64U ? c.length : std::uint8_t{64};
    f.fd = c.fd;
    f.extended = c.extended;
    f.timestamp_us = c.timestamp_us;
    std::memcpy(static_cast<void*>(f.data), static_cast<const void*>(c.data), f.length);
    return true;
  }
  [[nodiscard]] jg::hal::CanErrorState error_state() const noexcept {
    return ops_.error_state == nullptr ? jg::hal::CanErrorState::error_active
                                       : static_cast<jg::hal::CanErrorState>(ops_.error_state(ops_.context));
  }
  void set_filters(const jg::hal::CanFilter* filters, std::size_t n) const noexcept {
    if (ops_.set_filters == nullptr) {
      return;
    }
    constexpr std::size_t kMax = 8;
    jg_can_filter c[kMax]{};
    std::size_t count = 0;
    for (; count < n && count < kMax; ++count) {
      c[count] = {filters[count].match, filters[count].mask};
    }
    ops_.set_filters(ops_.context, static_cast<const jg_can_filter*>(c), count);
  }

 private:
  jg_can_port ops_;
};
static_assert(jg::hal::is_can_port_v<CallbackPort>, "the callback port satisfies the HAL contract");

struct DriveObject {
  explicit DriveObject(const jg_can_port& ops, const jg::DriveConfig& config, const Params& params,
                       const jg::Vec3<Scalar>& gravity) noexcept
      : port(ops), drive(config, params, port, gravity) {}
  CallbackPort port;
  jg::JointDrive<Scalar, CallbackPort> drive;
};

/// Samples in `seconds` (rounded up), at least `min`; false beyond the counters' 65535.
bool samples_of(double seconds, double sample_time_s, std::uint16_t min, std::uint16_t& out) noexcept {
  const double n = std::ceil(seconds / sample_time_s - 1e-9);
  if (!(n <= 65535.0)) {
    return false;
  }
  out = n < static_cast<double>(min) ? min : static_cast<std::uint16_t>(n);
  return true;
}

/// The holding detector and deadband of jg_joint_options (header), converted as the host's
/// joint parameters are (host_sim/eval/evaluate.cpp hold_params, eval/joint_params.hpp).
jg_error hold_params(const jg_joint_options& o, double sample_time_s, Params& p) noexcept {
  if (!jg::detail::is_finite(o.hold_change_threshold) || !jg::detail::is_finite(o.hold_settle_s) ||
      !jg::detail::is_finite(o.hold_reference_s) || !jg::detail::is_finite(o.holding_velocity_deadband)) {
    return JG_NOT_FINITE;
  }
  if (o.hold_settle_s < 0.0 || o.hold_reference_s < 0.0 || o.holding_velocity_deadband < 0.0) {
    return JG_INVALID_PARAMETER;
  }
  jg::HoldChangeParams<Scalar> h{};
  if (!samples_of(o.hold_settle_s > 0.0 ? o.hold_settle_s : 0.15, sample_time_s, 0U, h.settle_cycles) ||
      !samples_of(o.hold_reference_s > 0.0 ? o.hold_reference_s : 0.016, sample_time_s, 1U, h.reference_cycles)) {
    return JG_OUT_OF_RANGE;
  }
  jg::NumericStatus st{};
  // <= 0 disables the detector (hold_change_step); kept as 0 so no negative value is stored.
  h.change_threshold = jg::convert<Scalar>(o.hold_change_threshold > 0.0 ? o.hold_change_threshold : 0.0, st);
  h.inv_reference_cycles = jg::convert<Scalar>(1.0 / h.reference_cycles, st);
  const auto deadband = jg::convert<Scalar>(o.holding_velocity_deadband, st);
  if (!st.ok()) {
    return JG_OUT_OF_RANGE;
  }
  p.hold = h;
  p.holding_velocity_deadband = deadband;
  return JG_OK;
}

jg_error make_params(const jg_joint_config& c, const jg_joint_options* options, Params& p) noexcept {
  jg::LinkDescription l{};
  l.a_prev = c.link.a_prev;
  l.alpha_prev = c.link.alpha_prev;
  l.d = c.link.d;
  l.theta_offset = c.link.theta_offset;
  l.mass = c.link.mass;
  for (int k = 0; k < 3; ++k) {
    l.com[k] = c.link.com[k];
  }
  for (int k = 0; k < 6; ++k) {
    l.inertia_com[k] = c.link.inertia_com[k];
  }
  l.rotor_inertia = c.link.rotor_inertia;
  l.torque_constant = c.link.torque_constant;
  l.current_limit = c.link.current_limit;
  if (const jg::Error e = jg::convert_link(l, p.link); e != jg::Error::ok) {
    return c_error(e);
  }
  if (!(c.sample_time_s > 0.0) || !(c.sample_time_s < 1.0)) {
    return JG_INVALID_PARAMETER;
  }
  p.compensate_friction = c.compensate_friction;
  if (c.compensate_friction) {
    const jg::LuGreParams<double> f{c.friction.sigma0, c.friction.sigma1, c.friction.sigma2,
                                    c.friction.tau_c,  c.friction.tau_s,  c.friction.w_s};
    if (const jg::Error e = jg::discretize(f, c.sample_time_s, p.friction); e != jg::Error::ok) {
      return c_error(e);
    }
  }
  if (static_cast<unsigned>(c.observer) > 3U) {
    return JG_BAD_CONFIG;
  }
  const jg::ObserverGains g{static_cast<jg::ObserverKind>(c.observer), c.gain_k1, c.gain_k2, c.gain_k3,
                            options != nullptr && options->align_motor_torque};
  if (const jg::Error e = jg::discretize(g, c.sample_time_s, p.observer); e != jg::Error::ok) {
    return c_error(e);
  }
  const jg_threshold& t = c.threshold;
  if (!jg::detail::is_finite(t.base) || !jg::detail::is_finite(t.per_speed) || !jg::detail::is_finite(t.low_speed_extra) ||
      !jg::detail::is_finite(t.low_speed_width)) {
    return JG_NOT_FINITE;
  }
  if (t.base < 0.0 || t.per_speed < 0.0 || t.low_speed_extra < 0.0 || !(t.low_speed_width > 0.0)) {
    return JG_INVALID_PARAMETER;
  }
  jg::NumericStatus st{};
  p.threshold = {jg::convert<Scalar>(t.base, st), jg::convert<Scalar>(t.per_speed, st),
                 jg::convert<Scalar>(t.low_speed_extra, st), jg::convert<Scalar>(1.0 / t.low_speed_width, st)};
  if (!st.ok()) {
    return JG_OUT_OF_RANGE;
  }
  p.debounce.cycles = c.debounce_cycles == 0U ? std::uint8_t{1} : c.debounce_cycles;
  return options == nullptr ? JG_OK : hold_params(*options, c.sample_time_s, p);
}

jg_error gravity_of(const double gravity[3], jg::Vec3<Scalar>& out) noexcept {
  jg::NumericStatus st{};
  out = {jg::convert<Scalar>(gravity[0], st), jg::convert<Scalar>(gravity[1], st), jg::convert<Scalar>(gravity[2], st)};
  if (st.not_finite != 0U) {
    return JG_NOT_FINITE;
  }
  return st.ok() ? JG_OK : JG_OUT_OF_RANGE;
}
}  // namespace

extern "C" {

jg_scalar jg_scalar_from_double(double value, jg_error* error) {
  jg::NumericStatus st{};
  const auto s = jg::convert<Scalar>(value, st);
  if (error != nullptr) {
    *error = st.not_finite != 0U ? JG_NOT_FINITE : (st.saturated != 0U ? JG_OUT_OF_RANGE : JG_OK);
  }
  return to_c(s);
}

double jg_scalar_to_double(jg_scalar value) { return jg::to_double(from_c(value)); }

const char* jg_scalar_name(void) { return jg::kScalarName; }

const char* jg_error_name(jg_error e) {
  switch (e) {
    case JG_NULL_ARGUMENT: return "null_argument";
    case JG_BAD_CONFIG: return "bad_config";
    default: return jg::to_string(static_cast<jg::Error>(static_cast<int>(e)));
  }
}

jg_error jg_joint_init(const jg_joint_config* config, jg_joint_params* params, jg_joint_state* state) {
  return jg_joint_init_options(config, nullptr, params, state);
}

jg_error jg_joint_init_options(const jg_joint_config* config, const jg_joint_options* options, jg_joint_params* params,
                               jg_joint_state* state) {
  if (config == nullptr || params == nullptr || state == nullptr) {
    return JG_NULL_ARGUMENT;
  }
  Params p{};
  if (const jg_error e = make_params(*config, options, p); e != JG_OK) {
    return e;
  }
  ::new (static_cast<void*>(params)) Params(p);
  ::new (static_cast<void*>(state)) State{};
  return JG_OK;
}

jg_error jg_base_message(const double gravity[3], jg_outward_message* out) {
  if (gravity == nullptr || out == nullptr) {
    return JG_NULL_ARGUMENT;
  }
  jg::Vec3<Scalar> g{};
  const jg_error e = gravity_of(gravity, g);
  to_c(jg::base_message(g), *out);
  return e;
}

void jg_tip_message(jg_inward_message* out) {
  if (out != nullptr) {
    to_c(jg::tip_message<Scalar>(), *out);
  }
}

jg_error jg_joint_outward(const jg_joint_params* params, jg_joint_state* state, jg_scalar q, jg_scalar dq,
                          const jg_outward_message* from_parent, jg_outward_message* to_child) {
  return jg_joint_outward_holding(params, state, q, dq, false, from_parent, to_child);
}

jg_error jg_joint_outward_holding(const jg_joint_params* params, jg_joint_state* state, jg_scalar q, jg_scalar dq,
                                  bool holding, const jg_outward_message* from_parent, jg_outward_message* to_child) {
  if (params == nullptr || state == nullptr || from_parent == nullptr || to_child == nullptr) {
    return JG_NULL_ARGUMENT;
  }
  jg::OutwardMessage<Scalar> out{};
  // Not holding, the velocity passes unchanged (estimate_velocity): the former call.
  const jg::Error e = jg::joint_outward(*object_in<Params>(params), *object_in<State>(state), from_c(q), from_c(dq), holding,
                                        from_c(*from_parent), out);
  to_c(out, *to_child);
  return c_error(e);
}

bool jg_joint_inward_and_estimate(const jg_joint_params* params, jg_joint_state* state, jg_scalar dq,
                                  jg_scalar motor_torque, const jg_inward_message* from_child,
                                  jg_inward_message* to_parent) {
  return jg_joint_inward_and_estimate_holding(params, state, dq, motor_torque, false, from_child, to_parent);
}

bool jg_joint_inward_and_estimate_holding(const jg_joint_params* params, jg_joint_state* state, jg_scalar dq,
                                          jg_scalar motor_torque, bool holding, const jg_inward_message* from_child,
                                          jg_inward_message* to_parent) {
  if (params == nullptr || state == nullptr || from_child == nullptr || to_parent == nullptr) {
    return false;
  }
  jg::InwardMessage<Scalar> out{};
  const bool flag = jg::joint_inward_and_estimate(*object_in<Params>(params), *object_in<State>(state), from_c(dq),
                                                  from_c(motor_torque), holding, from_c(*from_child), out);
  to_c(out, *to_parent);
  return flag;
}

jg_scalar jg_joint_external_torque(const jg_joint_state* state) {
  return state == nullptr ? jg_scalar{} : to_c(object_in<State>(state)->external_torque);
}

jg_scalar jg_joint_friction_torque(const jg_joint_state* state) {
  return state == nullptr ? jg_scalar{} : to_c(object_in<State>(state)->friction_torque);
}

void jg_joint_reset_detector(jg_joint_state* state) {
  if (state != nullptr) {
    auto* s = object_in<State>(state);
    jg::reset_detector(s->detector);
    s->flagged = false;
  }
}

jg_error jg_drive_init(jg_drive* drive, const jg_drive_config* config, const jg_joint_config* joint,
                       const double gravity[3], const jg_can_port* port) {
  return jg_drive_init_options(drive, config, joint, nullptr, gravity, port);
}

jg_error jg_drive_init_options(jg_drive* drive, const jg_drive_config* config, const jg_joint_config* joint,
                               const jg_joint_options* options, const double gravity[3], const jg_can_port* port) {
  if (drive == nullptr || config == nullptr || joint == nullptr || gravity == nullptr || port == nullptr ||
      port->send == nullptr || port->receive == nullptr) {
    return JG_NULL_ARGUMENT;
  }
  if (config->joints < 1U || config->joints > jg::kMaxDetectorJoints || config->joint < 1U || config->joint > config->joints) {
    return JG_BAD_CONFIG;
  }
  Params p{};
  if (const jg_error e = make_params(*joint, options, p); e != JG_OK) {
    return e;
  }
  jg::Vec3<Scalar> g{};
  if (const jg_error e = gravity_of(gravity, g); e != JG_OK) {
    return e;
  }
  jg::DriveConfig d{};
  d.node.joint = config->joint;
  d.node.joints = config->joints;
  d.node.fault_cycles = config->fault_cycles == 0U ? std::uint8_t{5} : config->fault_cycles;
  d.node.max_age_cycles = config->max_age_cycles == 0U ? std::uint8_t{2} : config->max_age_cycles;
  d.sensors_over_can = config->sensors_over_can;
  ::new (static_cast<void*>(drive)) DriveObject(*port, d, p, g);
  return JG_OK;
}

void jg_drive_set_sample(jg_drive* drive, jg_scalar position, jg_scalar velocity, jg_scalar motor_torque) {
  jg_drive_set_sample_holding(drive, position, velocity, motor_torque, false);
}

void jg_drive_set_sample_holding(jg_drive* drive, jg_scalar position, jg_scalar velocity, jg_scalar motor_torque,
                                 bool holding) {
  if (drive != nullptr) {
    object_in<DriveObject>(drive)->drive.set_sample(from_c(position), from_c(velocity), from_c(motor_torque), holding);
  }
}

void jg_drive_announce(jg_drive* drive) {
  if (drive != nullptr) {
    object_in<DriveObject>(drive)->drive.announce();
  }
}

bool jg_drive_poll(jg_drive* drive) { return drive != nullptr && object_in<DriveObject>(drive)->drive.poll(); }

void jg_drive_status_get(const jg_drive* drive, jg_drive_status* out) {
  if (drive == nullptr || out == nullptr) {
    return;
  }
  const auto& d = object_in<DriveObject>(drive)->drive;
  out->external_torque = to_c(d.last_status().external_torque);
  out->flags = d.last_status().flags;
  out->rejected = d.last_status().rejected;
  out->cycles = d.counters().cycles;
  out->last_cycle = d.last_cycle();
}

}  // extern "C"
