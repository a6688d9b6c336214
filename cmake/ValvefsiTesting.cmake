# valvefsi_add_gtest(<name> LABEL unit|verification|validation SOURCES ... LIBS ... [TIMEOUT s])
# Each GoogleTest case becomes a ctest test carrying the label, so that
#   ctest -L unit            runs the fast unit tests (also under ASan/UBSan in CI),
#   ctest -LE validation     is the default run (unit + verification, < 20 min),
#   ctest -L validation      runs the long validation studies explicitly.
include(GoogleTest)
function(valvefsi_add_gtest name)
  cmake_parse_arguments(ARG "" "LABEL;TIMEOUT" "SOURCES;LIBS" ${ARGN})
  if(NOT ARG_LABEL)
    message(FATAL_ERROR "valvefsi_add_gtest(${name}): LABEL unit|verification|validation is required")
  endif()
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 600)
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gtest_main valvefsi::warnings)
  gtest_discover_tests(${name}
    DISCOVERY_MODE PRE_TEST
    PROPERTIES LABELS ${ARG_LABEL} TIMEOUT ${ARG_TIMEOUT}
    WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR})
endfunction()
