// A 3-joint arm for plant tests that do not depend on a model file: waist about the
// vertical axis, shoulder and elbow about horizontal axes (modified D-H).
#pragma once

#include <cmath>

#include "plant/plant.hpp"

namespace jg::test {

inline std::vector<sim::PlantLink> three_joint_links() {
  std::vector<sim::PlantLink> links(3);
  links[0].d = 0.3;
  links[0].mass = 4.0;
  links[0].com = {0.0, 0.01, -0.05};
  links[0].inertia_com = Eigen::Vector3d(0.03, 0.03, 0.02).asDiagonal();
  links[0].rotor_inertia = 0.4;
  links[1].alpha_prev = M_PI / 2;
  links[1].mass = 3.5;
  links[1].com = {0.2, 0.0, 0.02};
  links[1].inertia_com = Eigen::Vector3d(0.01, 0.06, 0.06).asDiagonal();
  links[1].rotor_inertia = 0.4;
  links[2].a_prev = 0.4;
  links[2].mass = 2.0;
  links[2].com = {0.18, 0.01, 0.0};
  links[2].inertia_com = Eigen::Vector3d(0.005, 0.03, 0.03).asDiagonal();
  links[2].rotor_inertia = 0.2;
  return links;
}

}  // namespace jg::test
