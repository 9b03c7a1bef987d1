// The reaction's path through a bus master, in the estimators' joint vectors: shared by the
// estimators whose drives run on a bus (the simulated CAN FD bus and SocketCAN), so that the
// command and the drives' reaction torques cross the same conversion on both.
#pragma once

#include <vector>

#include "jointguard/detection/detector.hpp"
#include "sim/simulation.hpp"

namespace jg::eval {

/// The master commands `reaction` from its next cycle (retreat target: one position per joint).
template <class Master>
bool command_bus_reaction(Master& master, Reaction reaction, JointMask collided, const sim::JointVector& retreat_target) {
  master.command_reaction(reaction, collided, retreat_target.data());
  return true;
}

/// The drives' reaction torques [N·m]; false until every drive has sent one.
template <class Master>
bool bus_reaction_torque(const Master& master, sim::JointVector& torque) {
  std::vector<double> t;
  if (!master.reaction_torques(t)) return false;
  torque = Eigen::Map<const Eigen::VectorXd>(t.data(), static_cast<Eigen::Index>(t.size()));
  return true;
}

}  // namespace jg::eval
