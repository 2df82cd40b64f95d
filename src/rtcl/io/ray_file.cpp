#include "rtcl/io/ray_file.hpp"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <new>
#include <span>

#include "rtcl/error.hpp"
#include "rtcl/io/atomic_file.hpp"

namespace rtcl {

namespace fs = std::filesystem;

namespace {

static_assert(sizeof(Ray) == 32 && sizeof(Hit) == 16, "file records are the device records");

// Files are little-endian; records are arrays of 4-byte words.
template <class T>
void to_or_from_little_endian(std::vector<T>& records) {
  if constexpr (std::endian::native == std::endian::big) {
    auto* words = reinterpret_cast<std::uint32_t*>(records.data());
    for (std::size_t i = 0; i < records.size() * sizeof(T) / 4; ++i) words[i] = __builtin_bswap32(words[i]);
  }
}

// Reads the whole file, with one read, as an array of records of type T.
template <class T>
std::vector<T> read_records(const std::string& path, const char* kind) {
  std::error_code ec;
  fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw Error(path + ": no such " + std::string(kind) + " file");
  if (fs::is_directory(status)) throw Error(path + ": is a directory, not a " + std::string(kind) + " file");
  std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw Error(path + ": cannot read the size of the " + std::string(kind) + " file: " + ec.message());
  if (size % sizeof(T) != 0)
    throw Error(path + ": size " + std::to_string(size) + " bytes is not a multiple of " + std::to_string(sizeof(T)) +
                " (one " + kind + " record is " + std::to_string(sizeof(T)) + " bytes; the file has no header)");
  std::vector<T> records;
  try {
    records.resize(size / sizeof(T));
  } catch (const std::bad_alloc&) {
    throw Error(path + ": " + std::to_string(size) + " bytes do not fit in memory");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open: " + std::strerror(errno));
  if (size > 0 && !in.read(reinterpret_cast<char*>(records.data()), static_cast<std::streamsize>(size)))
    throw Error(path + ": read " + std::to_string(in.gcount()) + " of " + std::to_string(size) + " bytes");
  to_or_from_little_endian(records);
  return records;
}

template <class T>
void write_records(const std::string& path, const std::vector<T>& records) {
  if constexpr (std::endian::native == std::endian::little) {
    write_file_atomically(path, std::as_bytes(std::span(records)));
  } else {
    std::vector<T> swapped = records;
    to_or_from_little_endian(swapped);
    write_file_atomically(path, std::as_bytes(std::span(swapped)));
  }
}

bool finite(float a, float b, float c) { return std::isfinite(a) && std::isfinite(b) && std::isfinite(c); }

}  // namespace

std::string ray_problem(const Ray& r) {
  if (!finite(r.ox, r.oy, r.oz)) return "its origin has a NaN or infinite component";
  if (!finite(r.dx, r.dy, r.dz)) return "its direction has a NaN or infinite component";
  if (r.dx == 0.0f && r.dy == 0.0f && r.dz == 0.0f) return "its direction has zero length";
  if (std::isnan(r.tmin) || std::isnan(r.tmax)) return "tmin or tmax is NaN";
  if (r.tmin > r.tmax) {
    char text[80];
    std::snprintf(text, sizeof text, "tmin %g is greater than tmax %g", r.tmin, r.tmax);
    return text;
  }
  return {};
}

std::vector<Ray> read_rays(const std::string& path) {
  std::vector<Ray> rays = read_records<Ray>(path, "ray");
  std::size_t bad = 0, first = 0;
  std::string first_problem;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    std::string problem = ray_problem(rays[i]);
    if (problem.empty()) continue;
    if (bad++ == 0) {
      first = i;
      first_problem = std::move(problem);
    }
  }
  if (bad > 0)
    throw Error(path + ": " + std::to_string(bad) + " of " + std::to_string(rays.size()) +
                " rays are invalid; the first is ray " + std::to_string(first) + " (byte offset " +
                std::to_string(first * sizeof(Ray)) + "): " + first_problem);
  return rays;
}

std::vector<Hit> read_hits(const std::string& path) { return read_records<Hit>(path, "hit"); }

void write_rays(const std::string& path, const std::vector<Ray>& rays) { write_records(path, rays); }

void write_hits(const std::string& path, const std::vector<Hit>& hits) { write_records(path, hits); }

}  // namespace rtcl
