// Ray and hit files: raw arrays of the device records, no header.
//
// Ray file: 32 bytes per ray, little-endian float32
//   ox oy oz dx dy dz tmin tmax          (exactly rtcl::Ray)
// Hit file: 16 bytes per ray, in ray order, little-endian
//   float32 t, u, v; int32 prim          (exactly rtcl::Hit)
//   miss: t = +inf, u = v = 0, prim = -1.
// An empty file is a valid set of zero rays (or hits).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "rtcl/layouts.hpp"

namespace rtcl {

// "" when the ray can be traced, else what is wrong with it: a NaN or
// infinite origin or direction component, a zero-length direction, a NaN
// tmin or tmax, or tmin > tmax. tmin may be negative and tmax may be +inf.
std::string ray_problem(const Ray& ray);

// Reads the whole file with one read. Throws Error naming the path for a
// missing or unreadable file, a size that is not a multiple of 32 bytes
// (stating the size), or invalid rays (how many, and the first by index and
// what is wrong with it).
std::vector<Ray> read_rays(const std::string& path);

// Reads a hit file; throws Error naming the path for a missing file or a size
// that is not a multiple of 16 bytes.
std::vector<Hit> read_hits(const std::string& path);

// Write whole files atomically (see atomic_file.hpp); throw Error naming the
// path on failure.
void write_rays(const std::string& path, const std::vector<Ray>& rays);
void write_hits(const std::string& path, const std::vector<Hit>& hits);

}  // namespace rtcl
