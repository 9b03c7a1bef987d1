// libFuzzer target: URDF import (robot::load_robot on a .urdf: urdfdom with its logging off,
// the checks of urdf_read.cpp, the chain and its D-H form), then check_simulatable.
#include "fuzz_common.hpp"
#include "io/recording.hpp"
#include "robot/robot_model.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = jg::fuzz::write_input(data, size, "robot.urdf");
  jg::fuzz::expect_clean<jg::io::FormatError>(path, [&] {
    const jg::robot::RobotModel m = jg::robot::load_robot(path);
    jg::robot::check_simulatable(m);
    (void)m.plant_links();
  });
  return 0;
}
