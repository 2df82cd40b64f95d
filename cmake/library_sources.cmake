# The library's sources, in one place for the two builds that compile them:
# librtcl itself (CMakeLists.txt) and the instrumented copy the fuzz targets
# link (fuzz/CMakeLists.txt). Include it with RTCL_ROOT set to the source
# tree; it defines
#   RTCL_LIBRARY_SOURCES  every src/rtcl/*.cpp, plus the generated file below
#   RTCL_LIBRARY_PCH      the headers most library files include (precompiled)
# copies the shared layouts to <binary dir>/include/rtcl/shared/ (internal
# code includes each as <rtcl/shared/...>: put <binary dir>/include on the
# include path), and adds the command that embeds the OpenCL kernels
# (kernels/) as a string table in <binary dir>/generated/embedded_kernels.cpp.
file(GLOB_RECURSE RTCL_KERNEL_FILES CONFIGURE_DEPENDS "${RTCL_ROOT}/kernels/*.cl" "${RTCL_ROOT}/kernels/*.h")
set(RTCL_EMBEDDED "${CMAKE_CURRENT_BINARY_DIR}/generated/embedded_kernels.cpp")
add_custom_command(
  OUTPUT "${RTCL_EMBEDDED}"
  COMMAND ${CMAKE_COMMAND} -DKERNEL_DIR=${RTCL_ROOT}/kernels -DOUTPUT=${RTCL_EMBEDDED} -P
          ${RTCL_ROOT}/cmake/embed_kernels.cmake
  DEPENDS ${RTCL_KERNEL_FILES} ${RTCL_ROOT}/cmake/embed_kernels.cmake
  COMMENT "Embedding OpenCL kernels")

file(GLOB_RECURSE RTCL_LIBRARY_SOURCES CONFIGURE_DEPENDS "${RTCL_ROOT}/src/rtcl/*.cpp")
list(APPEND RTCL_LIBRARY_SOURCES "${RTCL_EMBEDDED}")

# The OpenCL C++ bindings, glm and the standard headers most of the
# library's files include, parsed once.
set(RTCL_LIBRARY_PCH "${RTCL_ROOT}/include/rtcl/opencl.hpp" <glm/glm.hpp> <algorithm> <array> <chrono> <cmath>
                     <functional> <memory> <span> <string> <thread> <vector>)

file(GLOB RTCL_INTERNAL_SHARED_HEADERS CONFIGURE_DEPENDS "${RTCL_ROOT}/kernels/shared/*layouts.h"
     "${RTCL_ROOT}/kernels/shared/volumes.h" "${RTCL_ROOT}/kernels/shared/sampling.h")
foreach(header IN LISTS RTCL_INTERNAL_SHARED_HEADERS)
  get_filename_component(name "${header}" NAME)
  configure_file("${header}" "${CMAKE_CURRENT_BINARY_DIR}/include/rtcl/shared/${name}" COPYONLY)
endforeach()
