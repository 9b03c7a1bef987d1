# text/data/bss of the firmware core (per object) and of the golden ELF.
execute_process(COMMAND ${SIZE} -t ${LIB} OUTPUT_VARIABLE lib_size)
execute_process(COMMAND ${SIZE} ${ELF} OUTPUT_VARIABLE elf_size)
file(WRITE ${OUT} "firmware core (${LIB}):\n${lib_size}\ngolden test ELF:\n${elf_size}")
message("${lib_size}\n${elf_size}")
