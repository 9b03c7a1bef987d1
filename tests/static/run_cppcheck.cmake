# cppcheck over firmware/ and hal/ sources and headers; any finding fails. Suppressions
# live in tests/static/cppcheck-suppressions.txt, each with its reason.
if(NOT CPPCHECK)
  message("SKIP: cppcheck not found (apt-get install cppcheck)")
  cmake_language(EXIT 77)
endif()
execute_process(COMMAND ${CPPCHECK} --std=c++17 --language=c++ --enable=warning,style,performance,portability
    --inline-suppr --error-exitcode=1 --quiet
    --suppressions-list=${SOURCE_DIR}/tests/static/cppcheck-suppressions.txt
    -I ${SOURCE_DIR}/firmware/include -I ${SOURCE_DIR}/hal/include
    -DJG_SCALAR_Q=0 ${SOURCE_DIR}/firmware ${SOURCE_DIR}/hal
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cppcheck reported findings (exit ${rc})")
endif()
message("cppcheck: no findings")
