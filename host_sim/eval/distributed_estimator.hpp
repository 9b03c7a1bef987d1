// The estimation as the joint drives run it: one JointNode per joint on a simulated CAN FD
// bus, each using its neighbours' previous-cycle messages. Same node code as on the MCU.
#pragma once

#include "can/sim_bus.hpp"
#include "eval/estimator.hpp"
#include "eval/firmware_estimator.hpp"

namespace jg::eval {

struct DistributedConfig {
  FirmwareEstimatorConfig estimator;
  can::BusTiming timing{1e6, 5e6};
  can::FaultPlan faults{};
};

/// scalar "float" or "q"; the bus runs one control period per step.
std::unique_ptr<Estimator> make_distributed_estimator(const DistributedConfig& c, const std::string& scalar);

}  // namespace jg::eval
