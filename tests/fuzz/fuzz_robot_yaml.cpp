// libFuzzer target: robot files in the project's YAML format (robot::load_robot), then the
// check `simulate` applies (robot::check_simulatable) and the conversions the plant uses.
#include "fuzz_common.hpp"
#include "io/recording.hpp"
#include "robot/robot_model.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = jg::fuzz::write_input(data, size, "robot.yaml");
  jg::fuzz::expect_clean<jg::io::FormatError>(path, [&] {
    const jg::robot::RobotModel m = jg::robot::load_robot(path);
    jg::robot::check_simulatable(m);
    (void)m.plant_links();
    (void)m.drives();
  });
  return 0;
}
