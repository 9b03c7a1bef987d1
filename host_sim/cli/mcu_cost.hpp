// Firmware cost on the emulated Cortex-M4F: instructions per joint cycle counted under qemu
// (no cycle model there) and the core's size; shared by `bench` and the demo's report.
#pragma once

#include <string>

namespace jg::cli {

struct McuFigures {
  double float_insns = 0, q_insns = 0;              ///< estimator cycle, mean
  double float_drive_insns = 0, q_drive_insns = 0;  ///< drive cycle (JointDrive::poll), mean
  double float_drive_max = 0, q_drive_max = 0;      ///< drive cycle, worst measured (the event's)
  long float_stack = 0, q_stack = 0;                ///< drive cycle's stack depth, painted [B]
  long float_stack_static = -1, q_stack_static = -1;  ///< JointDrive::poll, static worst case [B] (-1: unknown)
  long text = 0, data = 0, bss = 0;
  bool ok = false;
  std::string note;  ///< why the figures are missing when !ok
};

/// Runs the cycle benchmark ELF under qemu-system-arm -M machine and sizes the core library
/// (an empty core_lib: no size figures).
McuFigures measure_mcu(const std::string& elf, const std::string& core_lib, const std::string& machine = "mps2-an386");

/// The cycle benchmark ELF and the core library of this build's Cortex-M4F cross build.
inline std::string mcu_build_dir(const std::string& cpu = "cortex-m4") { return std::string(JG_BUILD_DIR) + "/mcu-" + cpu; }

}  // namespace jg::cli
