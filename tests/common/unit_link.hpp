// A 1 kg point-mass link with a first-order observer at 1 ms and no friction compensation:
// the joint parameters of the CAN node and drive tests, where the bus, not the physics,
// is under test (host tests only: checks with GoogleTest).
#pragma once

#include <gtest/gtest.h>

#include "jointguard/node/joint_estimator.hpp"

namespace jg::test {

inline JointEstimatorParams<float> unit_link_params(float threshold) {
  JointEstimatorParams<float> p{};
  LinkDescription d;
  d.mass = 1.0;
  EXPECT_EQ(convert_link(d, p.link), Error::ok);
  EXPECT_EQ(discretize(ObserverGains{}, 0.001, p.observer), Error::ok);
  p.compensate_friction = false;
  p.threshold = {threshold, 0.0F};
  return p;
}

}  // namespace jg::test
