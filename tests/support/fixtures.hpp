// Shared test inputs: the device under test, scenes, ray sets, and a helper
// that runs a query on the device and reads the hits back.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/device.hpp"
#include "rtcl/layouts.hpp"
#include "rtcl/geometry.hpp"

namespace rtcl::test {

// +infinity and a quiet NaN (ray limits, misses, bad input).
inline constexpr float kInf = std::numeric_limits<float>::infinity();
inline constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// A ray from o along d over [tmin, tmax] (d as given, not normalised).
Ray make_ray(glm::vec3 o, glm::vec3 d, float tmin = 0.0f, float tmax = kInf);

// The device every test uses: $RTCL_DEVICE or the first one. A missing device
// is a failure (std::abort with a message), never a skip.
const Device& test_device();

// Every precision level the test device supports, robust first (exact
// needs fp64: PoCL has it, so CI runs all three). RTCL_TEST_PRECISIONS
// (e.g. "robust" or "robust,exact") narrows the list for the registry-wide
// suites: the sanitizer run uses it, because the levels differ only in
// device code, which the sanitizers do not instrument.
std::vector<Precision> test_precisions();

// What the registry-wide correctness suites build: every registered
// structure (accel_names()), and the build options that change what a
// traversal meets: "bvh:presplit=1" (a triangle in several leaves).
std::vector<std::string> tested_structures();

// The directory of the shared meshes: $RTCL_SCENES_DIR, else the
// ../shared/scenes beside the source tree (RTCL_SCENE_DIR, fixed when the
// build is configured). Every test finds meshes through it.
std::string scenes_dir();

// The path of a file under scenes_dir().
std::string scene_path(const std::string& relative);

// The Stanford bunny (stanford_bunny/bunny.obj under scenes_dir()), read
// and validated once per process.
Geometry bunny();

// Every vertex moved by a smooth field: amplitude times the box's largest
// side, `waves` periods across the box; the source
// gains ", sine-deformed".
Geometry sine_deformed(Geometry g, float amplitude, float waves);

// `count` random triangles of size ~`size` inside [0, 1]^3 * scale + offset.
Geometry random_soup(std::size_t count, std::uint32_t seed, float size = 0.05f, float scale = 1.0f,
                     glm::vec3 offset = glm::vec3(0.0f));

// `count` slivers from a shared vertex at the origin to a unit circle in
// z = 0 (vertex 1 + i at angle 2 pi i / count).
Geometry triangle_fan(int count);

// Two triangles side by side at z = 0 and one with its three corners on a
// line (zero area, skipped by the build; vertices 4, 5, 6).
Geometry with_a_degenerate_triangle();

// Rays from random points on a sphere around the geometry towards random
// points inside its bounds.
std::vector<Ray> random_rays(const Geometry& geometry, std::size_t count, std::uint32_t seed);

// Whether two hits, or two lists of hits, are the same bit for bit.
bool same_bits(const Hit& a, const Hit& b);
bool same_bits(const std::vector<Hit>& a, const std::vector<Hit>& b);

// Whether a program's list of defines holds `define`.
bool has(const std::vector<std::string>& defines, const std::string& define);

// Uploads rays, runs the query with that coherence promise, returns the hits.
std::vector<Hit> run_query(const Accel& accel, const std::vector<Ray>& rays, Query query,
                           Coherence coherence = Coherence::incoherent);

}  // namespace rtcl::test
