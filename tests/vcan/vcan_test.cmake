# jg_add_vcan_test(NAME <test> SCRIPT <script> [FILES <file|dir>...] [CHECK <host script> [args...]]
#                  [TIMEOUT <s>] [LABELS <label>...])
#
# Registers a CTest test that runs SCRIPT with /bin/sh on a machine with a CAN FD vcan0:
# directly when this kernel has vcan (and we are root), else in the qemu VM of vm_run.sh.
# SCRIPT and FILES (executables, models, directories; generator expressions such as
# $<TARGET_FILE:tgt> work) are copied under their basenames into a fresh payload directory
# (${CMAKE_CURRENT_BINARY_DIR}/<test>/payload); the script's cwd is that directory and what
# it writes to out/ comes back to ${CMAKE_CURRENT_BINARY_DIR}/<test>/out. With CHECK, the host
# then runs "bash CHECK <out dir> args...". Skipped ("vm_run: SKIP: ...") when neither vcan
# nor qemu and the tools are available, or the kernel cannot be downloaded. TIMEOUT
# (default 600 s) is CTest's; qemu is stopped 60 s before it (JG_VM_TIMEOUT).
include_guard(GLOBAL)
option(JG_VM_TESTS "Register the SocketCAN tests (vcan; in a qemu VM when this kernel has no CAN)" ON)
set(JG_VCAN_DIR ${CMAKE_CURRENT_LIST_DIR} CACHE INTERNAL "tests/vcan")

function(jg_add_vcan_test)
  if(NOT JG_VM_TESTS)
    return()
  endif()
  cmake_parse_arguments(PARSE_ARGV 0 T "" "NAME;SCRIPT;TIMEOUT" "FILES;CHECK;LABELS")
  if(NOT T_NAME OR NOT T_SCRIPT)
    message(FATAL_ERROR "jg_add_vcan_test: NAME and SCRIPT are required")
  endif()
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 600)
  endif()
  # vm_run.sh's own limit on qemu, below the CTest TIMEOUT so that a hanging VM ends with
  # vm_run's message (the script inside gets 60 s less, so its out/ still comes back).
  if(T_TIMEOUT GREATER 120)
    math(EXPR vm_timeout "${T_TIMEOUT} - 60")
  else()
    set(vm_timeout ${T_TIMEOUT})
  endif()
  set(labels vm ${T_LABELS})
  set(check_args)
  if(T_CHECK)
    set(check_args -- ${T_CHECK})
  endif()
  add_test(NAME ${T_NAME}
    COMMAND bash ${JG_VCAN_DIR}/payload_run.sh ${CMAKE_CURRENT_BINARY_DIR}/${T_NAME} ${T_SCRIPT}
      ${T_FILES} ${check_args})
  # RESOURCE_LOCK: in direct mode all tests share the host's vcan0.
  set_tests_properties(${T_NAME} PROPERTIES
    LABELS "${labels}"
    TIMEOUT ${T_TIMEOUT}
    SKIP_REGULAR_EXPRESSION "vm_run: SKIP: "
    SKIP_RETURN_CODE 77
    RESOURCE_LOCK jg_vcan0
    ENVIRONMENT "JG_VM_TIMEOUT=${vm_timeout}")
endfunction()
