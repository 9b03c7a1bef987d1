// Per-joint signals the diagnosis works on: the residual (real minus simulated or
// predicted motor torque) and the variables that may explain it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "jointguard/friction/lugre.hpp"

namespace jg::diag {

struct JointSignals {
  int joint = 1;                 ///< joint number as in the recording
  double dt = 0.0;               ///< sample time [s] (uniform)
  std::vector<double> t;         ///< [s]
  std::vector<double> q;         ///< link position [rad]
  std::vector<double> dq;        ///< velocity [rad/s]
  std::vector<double> ddq;       ///< acceleration estimated by differentiating dq [rad/s^2]
  double acceleration_sigma_s = 0.0;  ///< width of the zero-phase Gaussian derivative used for ddq (0: +/-10 ms slope)
  std::vector<double> tau_real;  ///< measured motor torque [N·m]
  std::vector<double> tau_model; ///< simulated or predicted motor torque [N·m]
  std::vector<double> load;      ///< rigid-body torque of the model (no friction) [N·m]
  std::vector<double> residual;  ///< tau_real - tau_model
  /// Payload regressors: d tau_j / d(theta) of the model for theta = (m, m cx, m cy, m cz)
  /// of the last link; empty when no model is available.
  std::vector<std::vector<double>> payload_columns;
  std::vector<double> velocity_mismatch;  ///< dq - d/dt q (elastic deflection rate) [rad/s]
  /// The rows the samples were resampled from, where the recording was sampled off its grid
  /// (io::Recording::rows_t): their time [s], position [rad] and velocity [rad/s]; empty
  /// otherwise. An effect of one row's own state (effects.cpp) is computed there and
  /// interpolated onto the samples, as the torque was.
  std::vector<double> rows_t, rows_q, rows_dq;
  /// Gear deflection not in the model [rad]: motor-side position (the motor-encoder
  /// velocity dq integrated, exact for differenced encoder counts) minus the link encoder's
  /// q, both from their first sample; real minus simulated when a simulation is given.
  /// Empty when unavailable.
  std::vector<double> deflection;
  /// The nominal model's friction of this joint, when known: friction effects are then
  /// also offered as changes of its parameters (exact sensitivity columns).
  std::optional<LuGreParams<double>> friction;
  /// The measured torque was offset by its own value at the first sample (tau_real =
  /// f(t) - f(t0), the arm at rest at t0): every effect's column is then offset the same
  /// way, by its value with the arm at rest at the first position (friction relaxed); the
  /// constant (current_offset) is left as it is, standing for the recording's own unknown
  /// friction state at t0.
  bool offset_at_start = false;
  /// Arm-level causes (payload) were fitted across the joints already (diagnosis/arm.hpp):
  /// they are not offered again per joint.
  bool arm_level_fitted = false;
  /// The measured torque is a link-side joint-torque sensor's (tau_j): no current-to-torque
  /// conversion in it, so no torque-constant error can be claimed.
  bool joint_torque_sensor = false;
  [[nodiscard]] std::size_t size() const { return t.size(); }
};

/// Smoothed derivative (Savitzky-Golay slope over about +/-half_window_s; uniform dt); zero
/// where the record is shorter than the window.
std::vector<double> derivative(const std::vector<double>& x, double dt, double half_window_s = 0.01);
/// Noise level of a signal from itself: 1.4826 MAD of second differences / sqrt(6), which
/// ignores smooth structure and isolated jumps.
double noise_level(const std::vector<double>& x);
/// Root mean square of x (0 when empty).
double rms(const std::vector<double>& x);
/// What a joint's fitted effects leave: their torque `fitted_nm` (one value per sample) moved
/// from the residual into the model, so a later pass sees the model that includes them. A
/// size other than the signals' changes nothing (the effects were fitted on other samples).
JointSignals with_fitted_in_model(JointSignals s, const std::vector<double>& fitted_nm);

/// The gear-deflection channel's shapes, one definition for the diagnosis that fits them
/// (diagnose.cpp) and the prediction that takes a file's gear effects off the measured
/// deflection (model_out.cpp). The torque the gear transmits: the model's rigid-body load
/// when known, else the measured torque [N·m].
const std::vector<double>& gear_torque(const JointSignals& s);
/// Backlash's deflection per half gap: a jump from -1 to +1 where the gear torque changes
/// sign, smoothed over `share` of the torque's RMS `tau_rms` [N·m] (> 0). An elastic gear's
/// deflection is the gear torque itself over the stiffness.
double backlash_shape(double gear_torque_nm, double share, double tau_rms);

}  // namespace jg::diag
