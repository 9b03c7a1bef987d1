# Flags for code that runs on the MCU (firmware/, hal/ interfaces): warnings are errors,
# no exceptions, no RTTI. Host-only code gets the warnings but keeps exceptions.
add_library(jg_firmware_flags INTERFACE)
target_compile_options(jg_firmware_flags INTERFACE
  -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wdouble-promotion -Wshadow
  -Wold-style-cast -Wcast-align -Wnull-dereference -Wundef -Wfloat-equal -Werror
  $<$<COMPILE_LANGUAGE:CXX>:-fno-exceptions -fno-rtti -Wnon-virtual-dtor -Wuseless-cast>
  -fno-math-errno
  # GCC's ARM note "parameter passing for argument of type 'jg::Q<16>' changed in GCC 7.1"
  # (the C API's functions take Q16.16 by value): an ABI difference from objects built by
  # GCC older than 7.1, which nothing here links against (the core is header-only, built
  # once by one compiler). A note, not a warning, it buried the cross builds' real output.
  $<$<CXX_COMPILER_ID:GNU>:-Wno-psabi>)

add_library(jg_host_flags INTERFACE)
# -Wno-maybe-uninitialized: GCC 12 reports false positives inside Eigen's fixed-capacity
# storage (copies of Matrix<double, Dynamic, 1, 0, 7, 1>).
target_compile_options(jg_host_flags INTERFACE -Wall -Wextra -Wshadow -Werror -Wno-maybe-uninitialized)
