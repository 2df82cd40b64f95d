# Installs a built rtcl into a fresh prefix, then configures, builds and runs
# the consumer project (tests/consumer) against that prefix only.
# cmake -DRTCL_BUILD_DIR=... -DRTCL_LIBDIR=lib -DCONSUMER_SOURCE_DIR=...
#       -DWORK_DIR=... -DGENERATOR=... -DCXX_COMPILER=... -P run_consumer.cmake
foreach(var RTCL_BUILD_DIR RTCL_LIBDIR CONSUMER_SOURCE_DIR WORK_DIR GENERATOR CXX_COMPILER)
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
foreach(file include/rtcl/shared/layouts.h include/rtcl/layouts.hpp include/rtcl/accel.hpp
             include/rtcl/device.hpp include/rtcl/opencl.hpp include/rtcl/geometry.hpp
             include/rtcl/error.hpp ${RTCL_LIBDIR}/cmake/rtcl/rtclConfig.cmake
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
