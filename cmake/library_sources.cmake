# The library's sources, in one place for the two builds that compile them:
# librtcl itself (CMakeLists.txt) and the instrumented copy the fuzz targets
# link (fuzz/CMakeLists.txt). Include it with RTCL_ROOT set to the source
# tree; it defines
#   RTCL_LIBRARY_SOURCES  every src/rtcl/*.cpp, plus the generated file below
#   RTCL_LIBRARY_PCH      the headers most library files include (precompiled)
# and the function rtcl_library_unity_build(<target>), which compiles a
# target's library sources as unity batches;
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

# Unity batches: the library's files compiled a batch at a time share the
# parse of their headers and their template instantiations, which shortens
# the library's compile in each build that compiles it (Release, sanitizers,
# fuzzing; docs/benchmarks.md, "CI time").
# The files below stay out of the batches: each defines a file-local name
# (anonymous namespace) that another library file defines too. The kernel
# table stays out so that editing a kernel recompiles only it.
set(RTCL_LIBRARY_UNITY_SKIP)
foreach(name IN ITEMS
    scene/scene_description.cpp render/ray_queue.cpp scene/scene_lights.cpp scene/two_level.cpp
    beam/polygon2d.cpp accel/kdtree.cpp accel/kdtree_nodes.cpp query/closest_point.cpp scene/scene_bytes.cpp
    accel/bsp.cpp accel/bvh_collapse.cpp io/temp_cleanup.cpp render/instanced_scene.cpp)
  list(APPEND RTCL_LIBRARY_UNITY_SKIP "${RTCL_ROOT}/src/rtcl/${name}")
endforeach()
list(APPEND RTCL_LIBRARY_UNITY_SKIP "${RTCL_EMBEDDED}")
# The BVH builders' and the refit's hot loops compile alone: inside a
# batch the 4M-triangle surface's SAH build took 1.4-1.6x as long
# (docs/benchmarks.md, "Large scenes"); the PLOC builder and the refit,
# not measured in a batch, stay out with it.
foreach(name IN ITEMS accel/bvh_sah.cpp accel/bvh_flatten.cpp accel/bvh.cpp accel/bvh_ploc.cpp accel/refit.cpp
                     thread_pool.cpp)
  list(APPEND RTCL_LIBRARY_UNITY_SKIP "${RTCL_ROOT}/src/rtcl/${name}")
endforeach()
function(rtcl_library_unity_build target)
  set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 16)
  # GCC warns of a class with a member of a file-local type once its file
  # is included (into a batch) rather than compiled; the types stay file-local.
  target_compile_options(${target} PRIVATE $<$<CXX_COMPILER_ID:GNU>:-Wno-subobject-linkage>)
  set_source_files_properties(${RTCL_LIBRARY_UNITY_SKIP} TARGET_DIRECTORY ${target}
                              PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
endfunction()

file(GLOB RTCL_INTERNAL_SHARED_HEADERS CONFIGURE_DEPENDS "${RTCL_ROOT}/kernels/shared/*layouts.h"
     "${RTCL_ROOT}/kernels/shared/volumes.h" "${RTCL_ROOT}/kernels/shared/sampling.h")
foreach(header IN LISTS RTCL_INTERNAL_SHARED_HEADERS)
  get_filename_component(name "${header}" NAME)
  configure_file("${header}" "${CMAKE_CURRENT_BINARY_DIR}/include/rtcl/shared/${name}" COPYONLY)
endforeach()
