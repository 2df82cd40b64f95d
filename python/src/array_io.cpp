#include "array_io.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <mutex>
#include <string>

#include "rtcl/huge_pages.hpp"
#include "rtcl/parallel.hpp"

namespace rtcl::python {

namespace {

std::string dtype_text(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

// Walks records [begin, end) of r in order, calling fn(i, record_bytes).
template <class Fn>
void walk(const FloatRecords& r, std::size_t begin, std::size_t end, Fn&& fn) {
  if (begin >= end) return;
  const std::size_t axes = r.shape.size();
  // The multi-index of `begin`, then an odometer over the leading axes.
  std::vector<py::ssize_t> index(axes, 0);
  std::size_t rest = begin;
  py::ssize_t offset = 0;
  for (std::size_t a = axes; a-- > 0;) {
    index[a] = static_cast<py::ssize_t>(rest % static_cast<std::size_t>(r.shape[a]));
    rest /= static_cast<std::size_t>(r.shape[a]);
    offset += index[a] * r.strides[a];
  }
  if (axes == 0) {  // one record
    fn(begin, r.data);
    return;
  }
  const std::size_t last = axes - 1;
  const py::ssize_t inner = r.strides[last], inner_size = r.shape[last];
  for (std::size_t i = begin; i < end;) {
    // The rest of the current innermost row.
    const py::ssize_t run = std::min<py::ssize_t>(inner_size - index[last], static_cast<py::ssize_t>(end - i));
    const char* p = r.data + offset;
    for (py::ssize_t k = 0; k < run; ++k, p += inner) fn(i + static_cast<std::size_t>(k), p);
    i += static_cast<std::size_t>(run);
    offset += run * inner;
    index[last] += run;
    // Carry into the outer axes.
    for (std::size_t a = last; a > 0 && index[a] == r.shape[a]; --a) {
      offset -= index[a] * r.strides[a];
      index[a] = 0;
      ++index[a - 1];
      offset += r.strides[a - 1];
    }
  }
}

template <class T>
inline float value(const char* record, py::ssize_t stride, int k) {
  T v;
  std::memcpy(&v, record + k * stride, sizeof(T));
  return static_cast<float>(v);
}

// Whether record i of r is the `width` values at r.data + i * width *
// sizeof(T) (a C-contiguous array of T).
template <class T>
bool packed(const FloatRecords& r, int width) {
  if (r.value_stride != static_cast<py::ssize_t>(sizeof(T))) return false;
  py::ssize_t step = width * static_cast<py::ssize_t>(sizeof(T));
  for (std::size_t a = r.shape.size(); a-- > 0;) {
    if (r.shape[a] != 1 && r.strides[a] != step) return false;
    step *= r.shape[a];
  }
  return true;
}

template <class T>
void pack_rays_as(const FloatRecords& r, std::size_t first, float tmin, float tmax, std::span<Ray> out, bool parallel) {
  const py::ssize_t s = r.value_stride;
  if (packed<T>(r, 6)) {  // a plain loop over the values, which the compiler unrolls
    const T* values = reinterpret_cast<const T*>(r.data) + 6 * first;
    for_parts(
        out.size(),
        [&](std::size_t begin, std::size_t end) {
          Ray* __restrict to = out.data();
          for (std::size_t i = begin; i < end; ++i) {
            const T* v = values + 6 * i;
            to[i] = Ray{static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]),
                        static_cast<float>(v[3]), static_cast<float>(v[4]), static_cast<float>(v[5]),
                        tmin,                     tmax};
          }
        },
        parallel);
    return;
  }
  for_parts(
      out.size(),
      [&](std::size_t begin, std::size_t end) {
        walk(r, first + begin, first + end, [&](std::size_t i, const char* p) {
          out[i - first] = Ray{value<T>(p, s, 0),
                               value<T>(p, s, 1),
                               value<T>(p, s, 2),
                               value<T>(p, s, 3),
                               value<T>(p, s, 4),
                               value<T>(p, s, 5),
                               tmin,
                               tmax};
        });
      },
      parallel);
}

std::string index_text(const std::vector<py::ssize_t>& shape, std::size_t flat) {
  if (shape.empty()) return "";
  std::vector<std::size_t> index(shape.size());
  for (std::size_t a = shape.size(); a-- > 0;) {
    index[a] = flat % static_cast<std::size_t>(shape[a]);
    flat /= static_cast<std::size_t>(shape[a]);
  }
  std::string text = "[";
  for (std::size_t a = 0; a < index.size(); ++a) text += (a ? ", " : "") + std::to_string(index[a]);
  return text + "]";
}

template <class T>
void pack_points_as(const FloatRecords& r, std::size_t first, std::span<float> out, bool parallel) {
  const py::ssize_t s = r.value_stride;
  for_parts(
      out.size() / 3,
      [&](std::size_t begin, std::size_t end) {
        walk(r, first + begin, first + end, [&](std::size_t i, const char* p) {
          float* o = &out[3 * (i - first)];
          o[0] = value<T>(p, s, 0);
          o[1] = value<T>(p, s, 1);
          o[2] = value<T>(p, s, 2);
        });
      },
      parallel);
}

// The first point with a coordinate that is not finite as a float, or
// r.count.
template <class T>
std::size_t first_bad_point(const FloatRecords& r) {
  const py::ssize_t s = r.value_stride;
  std::mutex lock;
  std::size_t bad = r.count;
  for_parts(r.count, [&](std::size_t begin, std::size_t end) {
    std::size_t mine = r.count;
    walk(r, begin, end, [&](std::size_t i, const char* p) {
      if (mine == r.count &&
          !(std::isfinite(value<T>(p, s, 0)) && std::isfinite(value<T>(p, s, 1)) && std::isfinite(value<T>(p, s, 2))))
        mine = i;
    });
    std::lock_guard guard(lock);
    bad = std::min(bad, mine);
  });
  return bad;
}

}  // namespace

namespace {

// Output blocks of at least kKeptMinBytes that arrays gave back, kept for
// the next arrays of the same size: a block used before costs no page
// faults (and no zeroing by the kernel) when the next call writes it. At
// most kKeptBytes are kept; a block beyond goes back to the system.
constexpr std::size_t kHugePage = std::size_t{2} << 20;
constexpr std::size_t kKeptMinBytes = std::size_t{64} << 10;
constexpr std::size_t kKeptBytes = std::size_t{512} << 20;

struct KeptBlocks {
  std::mutex mutex;
  std::multimap<std::size_t, void*> blocks;  // by rounded size
  std::size_t bytes = 0;
};
KeptBlocks& kept() {
  static auto* k = new KeptBlocks();  // never destroyed, as the scratch pool
  return *k;
}

// A kept block's size and alignment: huge pages from
// kHugePageAdviceBytes up, 64 KiB below.
std::size_t granule(std::size_t bytes) { return bytes >= kHugePageAdviceBytes ? kHugePage : kKeptMinBytes; }
std::size_t rounded(std::size_t bytes) { return (bytes + granule(bytes) - 1) / granule(bytes) * granule(bytes); }

}  // namespace

void* output_memory(std::size_t bytes) {
  void* p = nullptr;
  if (bytes >= kKeptMinBytes) {
    const std::size_t size = rounded(bytes);
    {
      KeptBlocks& k = kept();
      std::lock_guard lock(k.mutex);
      if (auto found = k.blocks.find(size); found != k.blocks.end()) {
        p = found->second;
        k.blocks.erase(found);
        k.bytes -= size;
        return p;
      }
    }
    p = std::aligned_alloc(granule(bytes), size);
    if (p) advise_huge_pages(p, bytes);  // from kHugePageAdviceBytes up
  } else {
    p = std::malloc(std::max<std::size_t>(bytes, 1));
  }
  if (!p) throw std::bad_alloc();
  return p;
}

void release_output_memory(void* p, std::size_t bytes) {
  if (bytes >= kKeptMinBytes) {
    const std::size_t size = rounded(bytes);
    KeptBlocks& k = kept();
    std::lock_guard lock(k.mutex);
    if (k.bytes + size <= kKeptBytes) {
      k.blocks.emplace(size, p);
      k.bytes += size;
      return;
    }
  }
  std::free(p);
}

std::string shape_text(const std::vector<py::ssize_t>& shape) {
  std::string text = "(";
  for (std::size_t a = 0; a < shape.size(); ++a) text += (a ? ", " : "") + std::to_string(shape[a]);
  return text + (shape.size() == 1 ? ",)" : ")");
}

void for_parts(std::size_t count, const std::function<void(std::size_t, std::size_t)>& fn, bool parallel) {
  if (!parallel) {
    fn(0, count);
    return;
  }
  for_each_part(count, part_count(count, 0, std::size_t(1) << 16),
                [&](unsigned, std::size_t begin, std::size_t end) { fn(begin, end); });
}

FloatRecords float_records(py::handle object, int width, const char* call, const char* param, bool matrix) {
  FloatRecords r;
  r.array = py::array::ensure(object);
  if (!r.array) {
    PyErr_Clear();
    throw py::type_error(std::string(call) + ": " + param + " must be an array of float32 or float64, got " +
                         py::str(py::type::of(object).attr("__name__")).cast<std::string>());
  }
  const char kind = r.array.dtype().kind();
  const auto itemsize = r.array.itemsize();
  if (kind != 'f' || (itemsize != 4 && itemsize != 8))
    throw py::type_error(std::string(call) + ": " + param + " has dtype " + dtype_text(r.array) +
                         "; expected float32 or float64");
  // Values in the other byte order ('>f4' on a little-endian machine):
  // numpy converts them to the native order (one copy), so that every
  // reader below reads native values.
  if (!r.array.dtype().attr("isnative").cast<bool>()) {
    r.array = py::array::ensure(r.array.attr("astype")(r.array.dtype().attr("newbyteorder")("=")));
    if (!r.array) throw py::error_already_set();
  }
  std::vector<py::ssize_t> full(r.array.shape(), r.array.shape() + r.array.ndim());
  if (r.array.ndim() < 1 || full.back() != width || (matrix && r.array.ndim() != 2))
    throw py::value_error(std::string(call) + ": " + param + " has shape " + shape_text(full) + "; expected (" +
                          (matrix ? "N" : "...") + ", " + std::to_string(width) + ")");
  r.float64 = itemsize == 8;
  r.data = static_cast<const char*>(r.array.data());
  r.shape.assign(full.begin(), full.end() - 1);
  r.strides.assign(r.array.strides(), r.array.strides() + r.array.ndim() - 1);
  r.value_stride = r.array.strides(r.array.ndim() - 1);
  r.count = 1;
  for (py::ssize_t n : r.shape) r.count *= static_cast<std::size_t>(n);
  return r;
}

void pack_rays(const FloatRecords& rays, std::size_t first, float tmin, float tmax, std::span<Ray> out, bool parallel) {
  if (rays.float64)
    pack_rays_as<double>(rays, first, tmin, tmax, out, parallel);
  else
    pack_rays_as<float>(rays, first, tmin, tmax, out, parallel);
}

void pack_points(const FloatRecords& points, std::size_t first, std::span<float> out, bool parallel) {
  if (points.float64)
    pack_points_as<double>(points, first, out, parallel);
  else
    pack_points_as<float>(points, first, out, parallel);
}

void check_points(const FloatRecords& points, const char* call, const char* param) {
  const std::size_t bad = points.float64 ? first_bad_point<double>(points) : first_bad_point<float>(points);
  if (bad != points.count)
    throw py::value_error(std::string(call) + ": " + param + index_text(points.shape, bad) +
                          " has a NaN or infinite coordinate");
}

std::vector<glm::vec3> read_vertices(py::handle object, const char* call, const char* param) {
  FloatRecords r = float_records(object, 3, call, param, true);
  std::vector<glm::vec3> out(r.count);
  const py::ssize_t s = r.value_stride;
  walk(r, 0, r.count, [&](std::size_t i, const char* p) {
    out[i] = r.float64 ? glm::vec3(value<double>(p, s, 0), value<double>(p, s, 1), value<double>(p, s, 2))
                       : glm::vec3(value<float>(p, s, 0), value<float>(p, s, 1), value<float>(p, s, 2));
  });
  return out;
}

std::vector<glm::uvec3> read_triangles(py::handle object, const char* call, const char* param) {
  py::array a = py::array::ensure(object);
  if (!a) {
    PyErr_Clear();
    throw py::type_error(std::string(call) + ": " + param + " must be an integer array, got " +
                         py::str(py::type::of(object).attr("__name__")).cast<std::string>());
  }
  const char kind = a.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throw py::type_error(std::string(call) + ": " + param + " has dtype " + dtype_text(a) +
                         "; expected an integer dtype (uint32 as Open3D)");
  std::vector<py::ssize_t> shape(a.shape(), a.shape() + a.ndim());
  if (a.ndim() != 2 || shape[1] != 3)
    throw py::value_error(std::string(call) + ": " + param + " has shape " + shape_text(shape) + "; expected (M, 3)");
  // One conversion by numpy to int64 (uint64 beyond int64's range
  // becomes negative and is refused with the others).
  auto wide = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
  if (!wide) throw py::error_already_set();
  const std::int64_t* v = wide.data();
  std::vector<glm::uvec3> out(static_cast<std::size_t>(shape[0]));
  for (std::size_t i = 0; i < out.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const std::int64_t x = v[3 * i + k];
      if (x < 0 || x >= std::int64_t(0xffffffff))
        throw py::value_error(std::string(call) + ": " + param + "[" + std::to_string(i) + "] has index " +
                              std::to_string(x) + ", outside [0, 2^32 - 1)");
      out[i][k] = static_cast<std::uint32_t>(x);
    }
  }
  return out;
}

}  // namespace rtcl::python

namespace rtcl::python {

Transform read_transform(py::handle object, const char* call, const char* param) {
  const FloatRecords r = float_records(object, 4, call, param, true);
  if (r.count != 3 && r.count != 4)
    throw py::value_error(std::string(call) + ": " + param + " has shape (" + std::to_string(r.count) +
                          ", 4); expected (4, 4) or (3, 4)");
  double m[4][4];
  const py::ssize_t s = r.value_stride;
  walk(r, 0, r.count, [&](std::size_t row, const char* p) {
    for (int col = 0; col < 4; ++col) m[row][col] = r.float64 ? value<double>(p, s, col) : value<float>(p, s, col);
  });
  Transform t;
  for (std::size_t row = 0; row < r.count; ++row)
    for (int col = 0; col < 4; ++col) {
      const double x = m[row][col];
      const bool fits = row == 3 || std::abs(x) <= static_cast<double>(std::numeric_limits<float>::max());
      if (!std::isfinite(x) || !fits)
        throw py::value_error(std::string(call) + ": " + param + "[" + std::to_string(row) + ", " +
                              std::to_string(col) + "] is " + py::repr(py::float_(x)).cast<std::string>() +
                              "; must be finite (within float's range)");
      if (row < 3) t.m[row][col] = static_cast<float>(x);
    }
  if (r.count == 4 && !(m[3][0] == 0.0 && m[3][1] == 0.0 && m[3][2] == 0.0 && m[3][3] == 1.0))
    throw py::value_error(std::string(call) + ": " + param + " has last row " +
                          py::repr(py::make_tuple(m[3][0], m[3][1], m[3][2], m[3][3])).cast<std::string>() +
                          "; an affine transform's is (0, 0, 0, 1)");
  return t;
}

}  // namespace rtcl::python
