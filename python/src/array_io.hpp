// numpy arrays in and out: the checks of shape and dtype (before any work,
// with the GIL held) and the conversions to the library's records (without
// the GIL, on the library's host threads, no Python loop).
//
// Inputs of records (rays: 6 values, points: 3) are float32 or float64
// arrays of any leading shape, with the record along the last axis, any
// strides (non-contiguous views and unaligned buffers included); anything
// numpy.asarray accepts (lists, ...) is converted by numpy first, and so are
// values in the non-native byte order ('>f4' on a little-endian machine:
// one copy by numpy into the native order). Integer inputs (triangles) and
// create_rays_pinhole's matrices are converted by numpy (forcecast), which
// handles any byte order the same way.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <glm/glm.hpp>
#include <span>
#include <string>
#include <vector>

#include "rtcl/queries.hpp"
#include "rtcl/scene.hpp"

namespace rtcl::python {

namespace py = pybind11;

// An input array read as records of `width` floats along its last axis.
struct FloatRecords {
  py::array array;  // holds the data
  const char* data = nullptr;
  bool float64 = false;              // else float32
  std::vector<py::ssize_t> shape;    // the leading shape (the record axis left out)
  std::vector<py::ssize_t> strides;  // bytes per step along each leading axis
  py::ssize_t value_stride = 0;      // bytes between a record's values
  std::size_t count = 0;             // records: the product of `shape`
};

// Checks `object` as an array of records of `width` values (GIL held):
// py::type_error unless numpy gives float32 or float64 values, py::value_error
// unless its last axis has `width` entries. Messages start with
// "CALL: PARAM" (e.g. "cast_rays: rays has shape (4, 3); expected (..., 6)").
// With `matrix`, the array must be (N, width) exactly.
FloatRecords float_records(py::handle object, int width, const char* call, const char* param, bool matrix = false);

// Rays [first, first + out.size()) of a (..., 6) array (ox oy oz dx dy dz),
// in the order of its flattened leading shape, with tmin and tmax, as Ray
// records; NaN and infinite values are kept (the library answers such rays
// as misses). No GIL needed.
// With parallel = false on the calling thread only.
void pack_rays(const FloatRecords& rays, std::size_t first, float tmin, float tmax, std::span<Ray> out,
               bool parallel = true);

// Throws py::value_error "CALL: PARAM[i, j] has a NaN or infinite
// coordinate" for the first such point of a (..., 3) array (float64 values
// beyond float's range count as infinite): before any work. No GIL needed.
void check_points(const FloatRecords& points, const char* call, const char* param);

// Points [first, first + out.size() / 3) of a (..., 3) array as 3 floats
// each (checked before by check_points). No GIL needed.
void pack_points(const FloatRecords& points, std::size_t first, std::span<float> out, bool parallel = true);

// Vertices (N, 3) float32 / float64, finite or not (the mesh's own check
// names the vertex), and triangles (M, 3) of any integer dtype with indices
// in [0, 2^32 - 1) (py::value_error naming the first that is not).
std::vector<glm::vec3> read_vertices(py::handle object, const char* call, const char* param);
std::vector<glm::uvec3> read_triangles(py::handle object, const char* call, const char* param);

// An affine transform, (4, 4) with last row (0, 0, 0, 1) or (3, 4), float32
// or float64 (TypeError otherwise), rows as rtcl::Transform's: ValueError
// naming PARAM's element for a non-finite value (or one beyond float's
// range) or the last row. Singular transforms are the caller's check.
Transform read_transform(py::handle object, const char* call, const char* param);

// Memory for an output array of `bytes`, given back by
// release_output_memory(p, bytes): from 4 MiB up aligned to 2 MiB and
// advised for huge pages, so that its first touch (while the answers are
// written) costs one page fault per 2 MiB, not per 4 KiB
// (rtcl/huge_pages.hpp). Blocks from 64 KiB up, once given back, are kept
// (up to 512 MiB) for the next arrays of the same size, which then cost no
// page faults at all (blocks of that size from malloc come fresh from the
// system, or from heap pages it hands back, at every call). Throws
// std::bad_alloc.
void* output_memory(std::size_t bytes);
void release_output_memory(void* p, std::size_t bytes);

// A fresh C-contiguous output array of shape leading + trailing, its memory
// from output_memory (owned by the array, given back when numpy frees it).
template <class T>
py::array_t<T> output_array(const std::vector<py::ssize_t>& leading, std::initializer_list<py::ssize_t> trailing = {}) {
  std::vector<py::ssize_t> shape = leading;
  shape.insert(shape.end(), trailing.begin(), trailing.end());
  std::size_t count = 1;
  for (py::ssize_t n : shape) count *= static_cast<std::size_t>(n);
  const std::size_t bytes = count * sizeof(T);
  void* memory = output_memory(bytes);
  // The capsule's context carries the size for the release.
  py::capsule owner(memory, nullptr, [](PyObject* o) {
    void* p = PyCapsule_GetPointer(o, nullptr);
    const auto size = reinterpret_cast<std::uintptr_t>(PyCapsule_GetContext(o));
    release_output_memory(p, static_cast<std::size_t>(size));
  });
  PyCapsule_SetContext(owner.ptr(), reinterpret_cast<void*>(static_cast<std::uintptr_t>(bytes)));
  return py::array_t<T>(shape, static_cast<T*>(memory), owner);
}

// "(4, 3)"; "(6,)" for one axis.
std::string shape_text(const std::vector<py::ssize_t>& shape);

// Calls fn(begin, end) over contiguous parts of [0, count) on the library's
// host threads (rtcl/parallel.hpp), one part per 64k items, at most one per
// hardware thread; with parallel = false one part on the calling thread.
void for_parts(std::size_t count, const std::function<void(std::size_t, std::size_t)>& fn, bool parallel = true);

}  // namespace rtcl::python
