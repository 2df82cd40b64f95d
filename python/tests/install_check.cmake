# ctest python_install: `cmake --install` into a fresh prefix, then Debian's
# python3 imports the module from <prefix>/RTCL_PYTHON_INSTALL_DIR alone
# (PYTHONPATH, no build tree) and traces one ray with it.
#   cmake -DBUILD_DIR=... -DPREFIX=... -DMODULE_DIR=... -DPYTHON=... -P install_check.cmake
file(REMOVE_RECURSE "${PREFIX}")
execute_process(COMMAND "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${PREFIX}" RESULT_VARIABLE rc
                OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install failed (${rc})")
endif()
set(check [=[
import sys, numpy as np, rtcl
assert rtcl.__file__.startswith(sys.argv[1]), rtcl.__file__
scene = rtcl.RaycastingScene()
scene.add_triangles(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32), np.array([[0, 1, 2]], np.uint32))
t = scene.cast_rays(np.array([[0.25, 0.25, 1, 0, 0, -1]], np.float32))["t_hit"]
assert t[0] == 1.0, t
print("installed module:", rtcl.__file__)
]=])
execute_process(COMMAND "${CMAKE_COMMAND}" -E env "PYTHONPATH=${PREFIX}/${MODULE_DIR}" "${PYTHON}" -c "${check}"
                        "${PREFIX}/${MODULE_DIR}" WORKING_DIRECTORY "${PREFIX}" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the installed module failed (${rc})")
endif()
