# rtcl_add_test_suites(<target> [EXCLUDE <Suite.Test>...] [ENVIRONMENT <VAR=value>...]
#                      [TIMEOUT <seconds>] [LONG <Suite>...])
#
# Registers one ctest test per GoogleTest suite of <target>: each runs
# `<target> --gtest_filter=<Suite>.*` in its own process. The suites are
# listed by the built binary (--gtest_list_tests) when ctest starts, so a new
# suite needs no CMake change. One process per suite rather than per test:
# every process pays the OpenCL platform's start (and, under the sanitizers,
# their runtime's start and exit-time leak scan), about half a second in a
# Release build and a second under ASan, which over some 600 tests was a
# quarter of the suite's time. A failing test is named in the suite's output.
#
# EXCLUDE: tests left out of this build's run (a negative --gtest_filter).
# LONG: the suites that take longest, started first by `ctest -j` (COST):
# on a fresh build ctest has no measured times yet and would otherwise
# start them in listing order, leaving one to run alone at the end.
function(rtcl_add_test_suites target)
  cmake_parse_arguments(arg "" "TIMEOUT" "EXCLUDE;ENVIRONMENT;LONG" ${ARGN})
  if(NOT arg_TIMEOUT)
    set(arg_TIMEOUT 900)
  endif()
  string(JOIN ":" excluded ${arg_EXCLUDE})
  set(listing_script "${CMAKE_CURRENT_BINARY_DIR}/${target}_suites.cmake")
  set(rtcl_suites_binary "$<TARGET_FILE:${target}>")
  set(rtcl_suites_excluded "${excluded}")
  set(rtcl_suites_environment "${arg_ENVIRONMENT}")
  set(rtcl_suites_timeout "${arg_TIMEOUT}")
  set(rtcl_suites_long "${arg_LONG}")
  configure_file("${PROJECT_SOURCE_DIR}/cmake/test_suites.cmake.in" "${listing_script}.in" @ONLY)
  file(GENERATE OUTPUT "${listing_script}" INPUT "${listing_script}.in")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${listing_script}")
endfunction()
