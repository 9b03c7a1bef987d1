# Flags for code that runs on the MCU (firmware/, hal/ interfaces): warnings are errors,
# no exceptions, no RTTI. Host-only code gets the warnings but keeps exceptions.
add_library(jg_firmware_flags INTERFACE)
target_compile_options(jg_firmware_flags INTERFACE
  -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wdouble-promotion -Wshadow
  -Wold-style-cast -Wcast-align -Wnull-dereference -Wundef -Wfloat-equal -Werror
  $<$<COMPILE_LANGUAGE:CXX>:-fno-exceptions -fno-rtti -Wnon-virtual-dtor -Wuseless-cast>
  -fno-math-errno)

add_library(jg_host_flags INTERFACE)
# -Wno-maybe-uninitialized: GCC 12 reports false positives inside Eigen's fixed-capacity
# storage (copies of Matrix<double, Dynamic, 1, 0, 7, 1>).
target_compile_options(jg_host_flags INTERFACE -Wall -Wextra -Wshadow -Werror -Wno-maybe-uninitialized)
