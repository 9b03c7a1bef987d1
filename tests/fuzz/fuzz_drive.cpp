// libFuzzer target: drive parameter files (`--drive`, robot::apply_drive_file) applied to
// the reference arm (models/ref3.yaml, joints waist, shoulder, elbow), then the checks the
// simulator applies.
#include "fuzz_common.hpp"
#include "io/recording.hpp"
#include "robot/drive_params.hpp"

#ifndef JG_FUZZ_MODEL
#error "JG_FUZZ_MODEL: path of models/ref3.yaml"
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const jg::robot::RobotModel ref3 = jg::robot::load_robot(JG_FUZZ_MODEL);
  const std::string path = jg::fuzz::write_input(data, size, "drive.yaml");
  jg::fuzz::expect_clean<jg::io::FormatError>(path, [&] {
    jg::robot::RobotModel m = ref3;
    jg::robot::apply_drive_file(m, path);
    jg::robot::check_simulatable(m);
    (void)m.drives();
  });
  return 0;
}
