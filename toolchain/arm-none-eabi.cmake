# Cross toolchain: Debian's gcc-arm-none-eabi with newlib (no OS). JG_MCU_CPU selects
# cortex-m4 (FPv4-SP, hard float), cortex-m7 (FPv5 double precision, hard float),
# cortex-m33 (FPv5-SP, hard float, DSP) or cortex-m3 (no FPU: soft float; its firmware
# scalar is Q16.16).
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_CXX_COMPILER arm-none-eabi-g++)
set(CMAKE_ASM_COMPILER arm-none-eabi-gcc)
set(CMAKE_AR arm-none-eabi-ar)
set(CMAKE_OBJCOPY arm-none-eabi-objcopy)
set(CMAKE_SIZE arm-none-eabi-size)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(JG_MCU_CPU "cortex-m4" CACHE STRING "cortex-m4, cortex-m7, cortex-m33 or cortex-m3")
if(JG_MCU_CPU STREQUAL "cortex-m7")
  set(_jg_cpu_flags "-mcpu=cortex-m7 -mthumb -mfpu=fpv5-d16 -mfloat-abi=hard")
elseif(JG_MCU_CPU STREQUAL "cortex-m33")
  set(_jg_cpu_flags "-mcpu=cortex-m33 -mthumb -mfpu=fpv5-sp-d16 -mfloat-abi=hard")
elseif(JG_MCU_CPU STREQUAL "cortex-m3")
  set(_jg_cpu_flags "-mcpu=cortex-m3 -mthumb -mfloat-abi=soft")
else()
  set(_jg_cpu_flags "-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard")
endif()
set(CMAKE_C_FLAGS_INIT "${_jg_cpu_flags} -ffunction-sections -fdata-sections")
set(CMAKE_CXX_FLAGS_INIT "${_jg_cpu_flags} -ffunction-sections -fdata-sections -fno-exceptions -fno-rtti -fno-threadsafe-statics -fno-use-cxa-atexit")
set(CMAKE_ASM_FLAGS_INIT "${_jg_cpu_flags}")
set(CMAKE_EXE_LINKER_FLAGS_INIT "${_jg_cpu_flags} -Wl,--gc-sections -nostartfiles --specs=nano.specs --specs=nosys.specs")

set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
