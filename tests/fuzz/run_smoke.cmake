# ctest fuzz.<reader> (preset fuzz): the seeds and the regression inputs, then libFuzzer's
# mutations for SECONDS. Any crash, sanitizer report, leak or foreign exception fails.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/corpus)
file(GLOB seeds ${SEEDS}/*)
file(COPY ${seeds} DESTINATION ${WORK}/corpus)
set(inputs ${WORK}/corpus)
if(EXISTS ${REGRESSIONS})
  list(APPEND inputs ${REGRESSIONS})
endif()
execute_process(COMMAND ${FUZZER} ${inputs} -max_total_time=${SECONDS} -seed=1 -print_final_stats=1
                        -artifact_prefix=${WORK}/
                WORKING_DIRECTORY ${WORK} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(REGEX MATCH "stat::number_of_executed_units: *[0-9]+" runs "${err}")
message("${runs}")
if(NOT rc EQUAL 0)
  message("${err}")
  message(FATAL_ERROR "the fuzzer found a failure (exit ${rc}); the input is in ${WORK}")
endif()
