// The reference arm's shoulder link (joint 2 of models/ref3.yaml, rounded): the one link the
// single-joint benchmarks and tests run on, host and MCU alike (header only, no host code).
#pragma once

#include "jointguard/dynamics/link.hpp"

namespace jg::test {

inline LinkDescription shoulder_link() {
  LinkDescription d;
  d.alpha_prev = 1.5707963267948966;
  d.mass = 3.5;
  d.com[0] = 0.2;
  d.com[2] = 0.02;
  d.inertia_com[0] = 0.01;
  d.inertia_com[1] = 0.06;
  d.inertia_com[2] = 0.06;
  d.rotor_inertia = 0.4;
  d.torque_constant = 12.0;
  d.current_limit = 15.0;
  return d;
}

}  // namespace jg::test
