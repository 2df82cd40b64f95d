# Installs a built rtcl into a fresh prefix, checks that it ships exactly the
# public headers, then configures, builds and runs the consumer project
# (tests/consumer: its own program and the example of docs/api.md) against
# that prefix only.
# cmake -DRTCL_BUILD_DIR=... -DRTCL_LIBDIR=lib -DCONSUMER_SOURCE_DIR=...
#       -DWORK_DIR=... -DGENERATOR=... -DCXX_COMPILER=... -DPUBLIC_INCLUDE_DIR=...
#       -DAPI_DOC=.../docs/api.md -P run_consumer.cmake
foreach(var RTCL_BUILD_DIR RTCL_LIBDIR CONSUMER_SOURCE_DIR WORK_DIR GENERATOR CXX_COMPILER PUBLIC_INCLUDE_DIR API_DOC)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_consumer.cmake: -D${var}=... is required")
  endif()
endforeach()

function(run step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${step} failed (${rc}):\n${out}\n${err}")
  endif()
  set(output "${out}" PARENT_SCOPE)
endfunction()

set(prefix "${WORK_DIR}/prefix")
set(build "${WORK_DIR}/build")
file(REMOVE_RECURSE "${WORK_DIR}")

run("install" "${CMAKE_COMMAND}" --install "${RTCL_BUILD_DIR}" --prefix "${prefix}")
# The installed headers are exactly the public set: include/rtcl/*.hpp of the
# source tree and the query records they include.
file(GLOB_RECURSE installed RELATIVE "${prefix}/include" "${prefix}/include/*")
file(GLOB public RELATIVE "${PUBLIC_INCLUDE_DIR}" "${PUBLIC_INCLUDE_DIR}/rtcl/*.hpp")
list(APPEND public rtcl/shared/query_layouts.h)
list(SORT installed)
list(SORT public)
if(NOT installed STREQUAL public)
  message(FATAL_ERROR "installed headers differ from the public set:\n  installed: ${installed}\n  public: ${public}")
endif()
foreach(file ${RTCL_LIBDIR}/cmake/rtcl/rtclConfig.cmake
             ${RTCL_LIBDIR}/cmake/rtcl/rtclConfigVersion.cmake ${RTCL_LIBDIR}/cmake/rtcl/rtclTargets.cmake)
  if(NOT EXISTS "${prefix}/${file}")
    message(FATAL_ERROR "install is incomplete: ${file} missing under ${prefix}")
  endif()
endforeach()
file(GLOB library "${prefix}/${RTCL_LIBDIR}/librtcl.so*")
if(NOT library)
  message(FATAL_ERROR "install is incomplete: no librtcl.so under ${prefix}/${RTCL_LIBDIR}")
endif()

# The installed command line tool (when built) runs from the prefix as is.
if(EXISTS "${prefix}/bin/rtcl")
  run("installed rtcl devices" "${prefix}/bin/rtcl" devices)
endif()

# Only the fresh prefix may provide rtcl: no package registry, no system copy.
run("configure" "${CMAKE_COMMAND}" -S "${CONSUMER_SOURCE_DIR}" -B "${build}" -G "${GENERATOR}"
    "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}" -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=${prefix}"
    -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DCMAKE_FIND_USE_SYSTEM_PACKAGE_REGISTRY=OFF)
file(STRINGS "${build}/CMakeCache.txt" found REGEX "^rtcl_DIR:")
if(NOT found MATCHES "${prefix}/")
  message(FATAL_ERROR "the consumer found rtcl outside the test prefix: ${found}")
endif()
run("build" "${CMAKE_COMMAND}" --build "${build}")
run("run" "${build}/rtcl_consumer")
message(STATUS "${output}")

# The complete program of docs/api.md (the block between its
# "api-example" markers), built against the prefix as a user copies it.
file(READ "${API_DOC}" doc)
string(REGEX MATCH "<!-- api-example: begin -->[^`]*```cpp\n(.*)\n```[^`]*<!-- api-example: end -->" found "${doc}")
if(NOT found)
  message(FATAL_ERROR "${API_DOC}: no ```cpp block between the api-example markers")
endif()
set(example "${WORK_DIR}/example")
file(MAKE_DIRECTORY "${example}")
file(WRITE "${example}/main.cpp" "${CMAKE_MATCH_1}\n")
file(WRITE "${example}/CMakeLists.txt" "cmake_minimum_required(VERSION 3.20)
project(api_example LANGUAGES CXX)
set(CMAKE_CXX_STANDARD 20)
find_package(rtcl 0.1 REQUIRED)
add_executable(api_example main.cpp)
target_link_libraries(api_example PRIVATE rtcl::rtcl)
")
run("configure the docs/api.md example" "${CMAKE_COMMAND}" -S "${example}" -B "${example}/build" -G "${GENERATOR}"
    "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}" -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=${prefix}"
    -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DCMAKE_FIND_USE_SYSTEM_PACKAGE_REGISTRY=OFF)
run("build the docs/api.md example" "${CMAKE_COMMAND}" --build "${example}/build")
run("run the docs/api.md example" "${example}/build/api_example")
# The example's rays: one hits triangle 1 of the unit square at t = 1 (a
# closed-form answer), the other misses.
if(NOT output MATCHES "ray 0: t = 1, triangle 1\n" OR NOT output MATCHES "ray 1: miss\n")
  message(FATAL_ERROR "the docs/api.md example printed:\n${output}")
endif()
message(STATUS "docs/api.md example:\n${output}")
