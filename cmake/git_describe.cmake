# Writes OUTPUT from INPUT (src/cli/rtcl_version.hpp.in) with the version
# and `git describe --always --dirty` of SOURCE_DIR ("unknown" without git).
# Run at every build (src/cli/CMakeLists.txt); OUTPUT is rewritten only when
# its text changes, so an unchanged commit recompiles nothing.
set(RTCL_GIT_DESCRIBE "unknown")
find_package(Git QUIET)
if(GIT_FOUND)
  execute_process(COMMAND "${GIT_EXECUTABLE}" describe --always --dirty WORKING_DIRECTORY "${SOURCE_DIR}"
                  OUTPUT_VARIABLE rtcl_describe OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE rtcl_git_status
                  ERROR_QUIET)
  if(rtcl_git_status EQUAL 0 AND rtcl_describe)
    set(RTCL_GIT_DESCRIBE "${rtcl_describe}")
  endif()
endif()
configure_file("${INPUT}" "${OUTPUT}" @ONLY)
