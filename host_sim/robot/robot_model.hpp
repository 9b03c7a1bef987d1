// Robot descriptions on the host: read from the project's YAML format (docs/robot-model.md)
// or from a URDF serial chain (urdfdom), converted per link into the firmware's
// LinkConstants and into the plant's links.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "jointguard/dynamics/link.hpp"
#include "dynamics/rigid_body.hpp"
#include "plant/sensors.hpp"
#include "robot/plant_effects.hpp"

namespace jg::robot {

/// Upper bounds of the drive values a file may give (physically invalid beyond: refused naming
/// the field). Reflected rotor inertia J_m N^2: a large industrial arm's is some 10-100 kg m^2
/// (1e-3 kg m^2 behind a 1:200 gear is 40); 1e4 leaves room and keeps the mass matrix's joints
/// within 1e12 of each other (sim check_simulatable). Link-side torque constant K_t N: up to
/// about 3,000 N m/A (10 N m/A behind 1:300). Gear ratios and current limits likewise.
inline constexpr double kMaxRotorInertiaKgM2 = 1e4;
inline constexpr double kMaxTorqueConstantNmPerA = 1e5;
inline constexpr double kMaxGearRatio = 1e5;
inline constexpr double kMaxCurrentLimitA = 1e5;
/// The heaviest rated payload of any arm the tool may meet [kg] (the largest industrial arms
/// are rated about 2,300 kg): beyond it a value is a unit slip (grams) or a typo.
inline constexpr double kMaxRatedPayloadKg = 5000.0;
/// A friction level (N·m) or viscous coefficient (N·m·s/rad) no drive reaches: a larger one in
/// a `friction_baseline` is a corrupt file.
inline constexpr double kMaxFrictionNm = 1e5;

struct JointDescription {
  std::string name;
  LinkDescription link;
  double gear_ratio = 100.0;
  double lower_rad = -3.14, upper_rad = 3.14;
  double reach_m = 0.3;  ///< distance to the next joint (for placing contacts)
  double effort_limit_nm = 0.0;  ///< torque limit when the file gives one (URDF <limit effort>), else 0
};

/// One joint's friction as a diagnosis identified it with the arm's links (written by
/// `diagnose --model-out` beside the identified links, key `friction_baseline`):
/// tau_f = f_c+ max(t, 0) + f_c- min(t, 0) + f_v dq + f_o, t = tanh(dq / eps).
/// A later diagnosis with that file takes it (and the links) as the model instead of
/// refitting them, so that the loop's next round starts where the last one ended.
struct FrictionBaseline {
  double coulomb_pos_nm = 0.0;    ///< f_c+ [N·m]
  double coulomb_neg_nm = 0.0;    ///< f_c- [N·m]
  double viscous_nms_rad = 0.0;   ///< f_v [N·m·s/rad]
  double offset_nm = 0.0;         ///< f_o [N·m]
  double eps_rad_s = 0.01;        ///< tanh velocity scale [rad/s], > 0
};

struct RobotModel {
  std::string name;
  std::string source;  ///< file it was read from
  double gravity[3] = {0.0, 0.0, -9.81};
  std::vector<JointDescription> joints;
  /// Effects found by `diagnose` and written back (`--model-out`): the plant's truth on top
  /// of the scenario's nominal setting when this file is simulated.
  std::vector<PlantEffect> plant_effects;
  /// The maker's rated payload [kg] (`rated_payload_kg`, in the robot file or in drive.yaml
  /// beside a URDF); 0 = not given. The diagnosis claims no payload above it.
  double rated_payload_kg = 0.0;
  /// The friction identified with these links (one per joint), or empty: the file's links
  /// are then the maker's (or hand-written) and a diagnosis identifies friction itself.
  std::vector<FrictionBaseline> friction_baseline;
  /// True for a URDF without a drive file's k_i: every torque constant is the placeholder
  /// 1 N·m/A, and motor currents cannot be turned into torques (robot/torque_kind.hpp).
  bool torque_constant_assumed = false;
  /// The top-level `identity` of a file a jointguard command wrote (`--model-out`,
  /// robot_writer.hpp): the version and the command that made it. Both empty for a file
  /// without one (written by hand, a URDF).
  std::string written_by_version, written_by_command;

  [[nodiscard]] std::vector<sim::PlantLink> plant_links() const;
  /// The arm's rigid-body dynamics with this model's gravity (gravity_m_s2).
  [[nodiscard]] sim::ArmDynamics dynamics() const;
  [[nodiscard]] std::vector<sim::JointDriveConfig> drives() const;
  [[nodiscard]] std::vector<double> reaches() const;
  /// Per link, the unit direction [link frame] towards the next joint's origin, from the next
  /// joint's modified D-H offsets (a_prev, 0, d) rotated by alpha_prev: where the link's body
  /// lies. +x for the last link and where the next joint's origin coincides with the link's.
  [[nodiscard]] std::vector<Eigen::Vector3d> reach_axes() const;
};

/// What to take from a robot file besides its path (CLI: --base, --tip, --drive).
struct LoadOptions {
  std::string base_link;   ///< URDF: first link of the chain (default: the root)
  std::string tip_link;    ///< URDF: last link of the chain (default: the deepest tip)
  std::string drive_file;  ///< drive parameters by joint name (robot/drive_params.hpp), any model
};

/// The optional `rated_payload_kg` of a robot or drive file (0 when absent), range-checked
/// naming the file, line and field.
double read_rated_payload(const io::YamlFields& root);

/// Reads a robot file: .yaml/.yml in the project's format or .urdf. Errors name the file,
/// line and field (io::FormatError).
RobotModel load_robot(const std::string& path, const LoadOptions& options = {});

/// Called with every model load_robot has read, so that the CLI can report a written file's
/// identity as it does for the JSON files it reads (cli/common.cpp). Unset: nothing is
/// called. Not thread-safe to set: set it once at start; the observer itself may be called
/// from several threads.
void set_read_observer(std::function<void(const RobotModel&)> observer);

/// Refuses (io::FormatError naming the file and the joint) a model whose mass matrix is
/// singular, e.g. a last link without mass or inertia and no rotor inertia: the plant's
/// forward dynamics would produce NaN. Detection alone does not need it (no M^-1).
void check_simulatable(const RobotModel& model);

}  // namespace jg::robot
