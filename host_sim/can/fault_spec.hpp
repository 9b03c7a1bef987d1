// Bus faults injected mid-run (`--fault KIND[:TARGET]@START[:DURATION]`, docs/can.md "Faults"):
// the parsed form shared by the simulated bus (host_sim/eval/distributed_estimator.cpp) and
// the SocketCAN master (host_sim/hil/socketcan_master.cpp).
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace jg::hil {

enum class FaultKind { drop, late, corrupt, duplicate, babble, bus_off, restart, link_down, nan_sensor };

struct FaultSpec {
  FaultKind kind = FaultKind::drop;
  int joint = 0;                 ///< target drive (1-based); 0: none given
  std::uint32_t id = 0;          ///< target identifier (frame faults) or the babbled identifier
  bool has_id = false;
  double start_s = 0.0;          ///< plant time the fault starts [s]
  double duration_s = std::numeric_limits<double>::infinity();  ///< [s]; infinity: until the end of the run
  std::string text;              ///< as given on the command line
  [[nodiscard]] double end_s() const { return start_s + duration_s; }
  /// Plant times compared to within kTimeToleranceS, so a window covers the same cycles
  /// whether the cycle's time is counted (SocketCAN: 1100 x 0.001 = 1.1) or summed period by
  /// period (the simulated bus: 1.0999999999999897), and whatever the rounding of
  /// START + DURATION (0.8 + 0.05 = 0.8500000000000001 still ends before cycle 850).
  [[nodiscard]] bool started(double t) const { return t + kTimeToleranceS >= start_s; }
  [[nodiscard]] bool ended(double t) const { return t + kTimeToleranceS >= end_s(); }
  [[nodiscard]] bool active(double t) const { return started(t) && !ended(t); }
  static constexpr double kTimeToleranceS = 1e-9;  ///< far below any plant period, far above the rounding
};

/// Extra latency of a `late` frame [s] (5 cycles at 1 kHz beyond the max_age_cycles of 2).
inline constexpr double kLateDelayS = 0.010;
/// Identifier a babbling node sends by default (the highest-priority collision event).
inline constexpr std::uint32_t kDefaultBabbleId = 0x001;

/// Parses one spec; throws std::invalid_argument with a message naming the spec and what
/// is wrong (unknown kind, bad target for the kind, bad or negative time).
FaultSpec parse_fault(const std::string& text);
/// Checks specs against the run: joint targets in 1..joints, starts before the end.
void check_faults(const std::vector<FaultSpec>& faults, std::size_t joints, double duration_s);
const char* to_string(FaultKind kind);
/// The syntax, for --help.
const char* fault_syntax_help();

/// Identifiers sent by drive `joint` (collision event, outward, inward, status).
std::vector<std::uint32_t> drive_identifiers(int joint);

}  // namespace jg::hil
