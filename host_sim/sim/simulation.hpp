// One simulated run: plant + sensors + joint-space controller following a trajectory,
// with scheduled collisions, recorded at the control rate in the contract's format.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "io/recording.hpp"
#include "motion/trajectory.hpp"
#include "plant/collision.hpp"
#include "plant/plant.hpp"
#include "plant/sensors.hpp"

namespace jg::sim {

/// PD with gravity and inertia feed-forward from the controller's nominal model (which
/// may differ from the plant: payload, friction and sensor effects are unknown to it).
struct ControllerConfig {
  std::vector<double> kp;  ///< [N·m/rad] per joint
  std::vector<double> kd;  ///< [N·m·s/rad] per joint
  bool inertia_feedforward = true;
  /// Integral action (empty: none, the default): demand += clamp(sum ki e dt, +-integral_limit_nm),
  /// e the position error; the sum stops growing at the clamp (anti-windup).
  std::vector<double> ki;                 ///< [N·m/(rad·s)] per joint
  std::vector<double> integral_limit_nm;  ///< [N·m] per joint (empty: no clamp)
};

/// What the arm does in a control cycle; the default follows the trajectory. A reaction
/// (stop, compliant mode) replaces the torque demand through a ControlOverride.
struct CycleContext {
  double t = 0.0;
  const Measurement* measurement = nullptr;
  const TrajectorySample* reference = nullptr;
  const JointVector* demand = nullptr;  ///< the tracking controller's torque demand
};
using ControlOverride = std::function<std::optional<JointVector>(const CycleContext&)>;

struct SimulationSetup {
  PlantConfig plant;
  std::vector<PlantLink> nominal_links;  ///< the controller's model (empty: the plant's links)
  SensorConfig sensors;
  ControllerConfig controller;
  std::shared_ptr<const Trajectory> trajectory;
  std::vector<CollisionEvent> collisions;
  double control_rate_hz = 1000.0;
  double duration_s = 0.0;  ///< 0: the trajectory's duration
  bool record = true;
  io::RecordingMeta meta;
};

struct SimulationResult {
  io::Recording recording;  ///< empty when setup.record is false
  double peak_contact_force_n = 0.0;
  /// Largest contact force within each control cycle [N] (only when the setup has
  /// collisions): the force a person felt over time, for the ISO/TS 15066 assessment.
  std::vector<double> contact_force_n;
  /// The first scheduled collision as it acted (point and direction resolved at its onset:
  /// into_motion, surface contacts); link 0 when it never began.
  ResolvedContact first_contact;
  /// The plant's own friction torque [N·m] and the true speed it acts at [rad/s] (the motor
  /// side's on an elastic joint) per joint and cycle,
  /// aligned with the recording's tau_ext (only when recording a setup with collisions): what
  /// a stuck joint's static friction takes of a push, which no current measurement shows.
  std::vector<std::vector<double>> plant_friction_nm, plant_speed_rad_s;
  double simulated_s = 0.0;
  long cycles = 0;
};

/// Runs the setup; `override` (optional) may replace the torque demand each cycle;
/// `progress` (optional) is called with the fraction done.
SimulationResult run_simulation(const SimulationSetup& setup, const ControlOverride& override = {},
                                const std::function<void(double)>& progress = {});

}  // namespace jg::sim
