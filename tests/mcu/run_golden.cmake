# Runs the golden program on the host and under qemu (MACHINE: mps2-an386 for the
# Cortex-M4F, mps2-an385 for the M3, mps2-an505 for the M33) on the same input and
# compares: Q16.16 bit for bit, float within 2e-3 N·m.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${MAKE_INPUT} ${MODEL} ${WORK}/in.bin RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "making the golden input failed (${rc})")
endif()
execute_process(COMMAND ${HOST} ${WORK}/in.bin ${WORK}/host.bin RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "host golden run failed (${rc})")
endif()
if(NOT MACHINE)
  set(MACHINE mps2-an386)
endif()
execute_process(COMMAND ${QEMU} -M ${MACHINE} -nographic -monitor none -serial none
                  -semihosting-config enable=on,target=native,arg=jg_golden.elf,arg=in.bin,arg=mcu.bin
                  -kernel ${ELF}
                WORKING_DIRECTORY ${WORK} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 240)
message("${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "qemu golden run failed (exit ${rc})")
endif()
execute_process(COMMAND ${COMPARE} ${WORK}/host.bin ${WORK}/mcu.bin 2e-3 RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "host and MCU outputs differ")
endif()
