// Fuzz target: bytes -> a small scene and rays -> every structure of the
// registry (accel_names(), and "bvh:presplit=1", where a triangle lies in
// several leaves) at the robust and exact levels -> each answer checked
// against the tests' double-precision reference (tests/support/reference.hpp).
// A violation aborts with the structure, level, call and ray.
//
// The scene: up to 64 triangles and 8 spheres built from a pool of lattice
// points (so vertices, edges and whole triangles coincide), with slivers,
// degenerate (repeated-index and collinear), huge and tiny triangles and
// strips sharing edges, scaled by 2^-20 .. 2^20 and translated by up to
// 2^11 lattice units (the lattice spans 32) from the origin: farther, the
// judge's tolerance, which grows with the coordinates' magnitude, would
// exceed the triangles. The rays (up to 64, then repeated to 64): aimed at
// vertices, edge points, interior points, sphere silhouettes or anywhere in
// the box; axis-parallel with +0 / -0 components, along a triangle's normal,
// lying in its plane along an edge, or any direction; starting on their
// target or away from it, with [tmin, tmax] ending at or starting from the
// target.
//
// What is checked (docs/robustness.md, "The structures target"), on every call (closest
// and any hit; the coherent kernel where it differs; the sorted kernel at
// robust where the structure sorts):
// - robust and exact, no leak: a ray whose reference hit (reference.hpp:
//   reference_closest) lies inside a primitive by more than the scene-scaled
//   tolerance (tolerance_in: 256 float ulps of the scene's and the origin's
//   magnitude) and inside [tmin, tmax] by as much is not answered with a
//   miss, nor (closest hit) with a hit farther than it by more than the
//   tolerance.
// - robust and exact, no false hit: a reported hit is a primitive with an
//   area, its point o + t d lies within the tolerance of that primitive, t
//   lies inside [tmin, tmax] within the tolerance, and (u, v) name a point
//   within the tolerance of it (twice the tolerance from o + t d; unchecked
//   where the ray grazes the triangle's plane, |cos| < 2^-8); a sphere
//   hit and a miss have u = v = 0, a miss t = +inf and prim = -1. (Distance
//   to the primitive, not to its plane's crossing: for a ray that lies in a
//   triangle's plane within rounding, the crossing is ill-conditioned.)
// - robust and exact: every structure agrees with brute force at the same
//   level: hit or miss, and the closest hit's t bit for bit
//   (docs/precision.md: every structure returns the same closest t).
// - exact, closest hit: on every ray that double precision decides
//   (reference.hpp: double_closest), the reference's primitive, and t within
//   one float ulp of the double t (docs/precision.md).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/accel.hpp"
#include "rtcl/device.hpp"
#include "rtcl/error.hpp"
#include "rtcl/geometry.hpp"
#include "rtcl/layouts.hpp"
#include "rtcl/precision.hpp"
#include "support/reference.hpp"

namespace {

using rtcl::Coherence;
using rtcl::Geometry;
using rtcl::Hit;
using rtcl::Precision;
using rtcl::Query;
using rtcl::Ray;

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr std::size_t kMaxTriangles = 64, kMaxSpheres = 8, kMaxRays = 64;

// The input, read front to back; zeros once it is used up. Every read is
// its own statement (or initialiser): the order in which a call's arguments
// are evaluated is unspecified, and the replay (GCC) must decode an input
// as libFuzzer's build (clang) does.
class Bytes {
 public:
  Bytes(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  std::uint8_t next() { return at_ < size_ ? data_[at_++] : 0; }
  std::size_t below(std::size_t n) { return n ? next() % n : 0; }
  double unit() { return next() / 255.0; }  // [0, 1], both ends included
  bool bit() { return next() & 1; }

 private:
  const std::uint8_t* data_;
  std::size_t size_, at_ = 0;
};

struct Scene {
  Geometry geometry;
  std::vector<glm::dvec3> points;  // the lattice pool, before scale and offset
};

// A lattice point: coordinates in [-16, 16) in steps of 1/8.
glm::dvec3 lattice(Bytes& in) {
  auto c = [&] { return static_cast<std::int8_t>(in.next()) / 8.0; };
  double x = c(), y = c(), z = c();
  return {x, y, z};
}

glm::dvec3 any_perpendicular(const glm::dvec3& v) {
  glm::dvec3 p = glm::cross(v, std::abs(v.x) < 0.5 * glm::length(v) ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0));
  double l = glm::length(p);
  return l > 0 ? p / l : glm::dvec3(0, 0, 1);
}

Scene make_scene(Bytes& in) {
  Scene s;
  Geometry& g = s.geometry;
  g.source = "fuzz scene";
  const double scale = std::ldexp(1.0, static_cast<int>(in.below(41)) - 20);
  glm::dvec3 offset(0.0);
  if (!in.bit()) {
    double far = std::ldexp(1.0, static_cast<int>(in.below(13)));
    for (int k = 0; k < 3; ++k) offset[k] = far * (in.unit() - 0.5);
  }
  std::size_t pool = 3 + in.below(22);
  for (std::size_t i = 0; i < pool; ++i) s.points.push_back(lattice(in));
  std::vector<glm::dvec3> vertices(s.points);  // pool first: triangles index them (shared vertices)
  std::vector<glm::uvec3> triangles;
  std::vector<std::pair<glm::dvec3, double>> spheres;
  auto add = [&](glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    auto base = static_cast<unsigned>(vertices.size());
    vertices.insert(vertices.end(), {a, b, c});
    triangles.push_back({base, base + 1, base + 2});
  };
  auto pick = [&] { return static_cast<unsigned>(in.below(pool)); };
  std::size_t ops = 1 + in.below(72);
  for (std::size_t op = 0; op < ops && triangles.size() < kMaxTriangles; ++op) {
    switch (in.below(8)) {
      case 0:
      case 1:  // pool corners: shared vertices and edges; a repeated index is degenerate
        triangles.push_back({pick(), pick(), pick()});
        break;
      case 2:  // a coincident copy of an earlier triangle, maybe with the other winding
        if (!triangles.empty()) {
          glm::uvec3 t = triangles[in.below(triangles.size())];
          triangles.push_back(in.bit() ? glm::uvec3(t.x, t.z, t.y) : t);
        }
        break;
      case 3: {  // a sliver: its third corner 2^-8 .. 2^-38 of its length off the a-b line
        glm::dvec3 a = s.points[pick()], b = s.points[pick()];
        double along = in.unit(), off = std::ldexp(glm::length(b - a), -8 - static_cast<int>(in.below(31)));
        add(a, b, a + along * (b - a) + off * any_perpendicular(b - a));
        break;
      }
      case 4: {  // collinear corners: zero area without a repeated index
        glm::dvec3 a = s.points[pick()], b = s.points[pick()];
        add(a, b, a + (in.unit() * 2.0 - 0.5) * (b - a));
        break;
      }
      case 5: {  // huge: a pool triangle grown 2^4 .. 2^10 times about its first corner
        glm::dvec3 a = s.points[pick()], b = s.points[pick()], c = s.points[pick()];
        double k = std::ldexp(1.0, 4 + static_cast<int>(in.below(7)));
        add(a, a + k * (b - a), a + k * (c - a));
        break;
      }
      case 6: {  // tiny: 2^-8 .. 2^-30 of the lattice unit at a pool point
        glm::dvec3 a = s.points[pick()];
        double k = std::ldexp(1.0, -8 - static_cast<int>(in.below(23)));
        glm::dvec3 b = a + k * lattice(in), c = a + k * lattice(in);
        add(a, b, c);
        break;
      }
      case 7:  // a strip: the previous triangle's edge with a pool point, or a sphere
        if (!triangles.empty() && in.bit()) {
          glm::uvec3 t = triangles.back();
          int e = static_cast<int>(in.below(3));
          triangles.push_back({t[(e + 1) % 3], t[e], pick()});
        } else if (spheres.size() < kMaxSpheres) {
          glm::dvec3 centre = s.points[pick()];
          double mantissa = 1.0 + in.unit();
          spheres.push_back({centre, std::ldexp(mantissa, 2 - static_cast<int>(in.below(24)))});
        }
        break;
    }
  }
  for (const glm::dvec3& v : vertices) g.vertices.push_back(glm::vec3(v * scale + offset));
  g.triangles = std::move(triangles);
  for (auto& [centre, radius] : spheres)
    g.spheres.push_back({glm::vec3(centre * scale + offset), static_cast<float>(radius * scale)});
  for (glm::dvec3& p : s.points) p = p * scale + offset;
  return s;
}

std::vector<Ray> make_rays(Bytes& in, const Scene& s) {
  const Geometry& g = s.geometry;
  std::vector<Ray> rays;
  rtcl::Aabb box = g.bounds();
  glm::dvec3 lo(box.lower), hi(box.upper);
  double size = std::max(glm::length(hi - lo), 1e-30);
  auto corner = [&](std::size_t t, int k) { return glm::dvec3(g.vertices[g.triangles[t][k]]); };
  std::size_t count = 1 + in.below(kMaxRays);
  for (std::size_t r = 0; r < count; ++r) {
    std::size_t tri = g.triangles.empty() ? 0 : in.below(g.triangles.size());
    bool have_tri = !g.triangles.empty();
    glm::dvec3 target(0.0), along(1, 0, 0);
    switch (in.below(5)) {
      case 0:  // a vertex
        target = have_tri ? corner(tri, static_cast<int>(in.below(3))) : s.points[in.below(s.points.size())];
        break;
      case 1:  // a point of an edge (its midpoint at 128/255 ~ 0.5 and its ends included)
        if (have_tri) {
          int e = static_cast<int>(in.below(3));
          glm::dvec3 a = corner(tri, e), b = corner(tri, (e + 1) % 3);
          target = a + in.unit() * (b - a);
          along = b - a;
          break;
        }
        [[fallthrough]];
      case 2:  // an interior point
        if (have_tri) {
          double u = 1.0 + in.next(), v = 1.0 + in.next(), w = 1.0 + in.next();
          target = (u * corner(tri, 0) + v * corner(tri, 1) + w * corner(tri, 2)) / (u + v + w);
          along = corner(tri, 1) - corner(tri, 0);
          break;
        }
        [[fallthrough]];
      case 3:  // a sphere's silhouette (or a pool point)
        if (!g.spheres.empty()) {
          const rtcl::Sphere& sp = g.spheres[in.below(g.spheres.size())];
          glm::dvec3 n(0.0);
          for (int k = 0; k < 3; ++k) n[k] = in.unit() - 0.5;
          if (glm::length(n) == 0.0) n = glm::dvec3(0, 0, 1);
          target = glm::dvec3(sp.center) + double(sp.radius) * glm::normalize(n);
          along = any_perpendicular(n);
          break;
        }
        target = s.points[in.below(s.points.size())];
        break;
      default:  // anywhere in the box
        for (int k = 0; k < 3; ++k) target[k] = lo[k] + in.unit() * (hi[k] - lo[k]);
        break;
    }
    glm::dvec3 d(0.0);
    std::uint8_t how = in.next();
    switch ((how & 0x1f) % 5) {  // 0x20: the origin on the target (below)
      case 0: {  // axis-parallel, the other components +0 or -0
        int axis = static_cast<int>(in.below(3));
        for (int k = 0; k < 3; ++k) d[k] = in.bit() ? -0.0 : 0.0;
        d[axis] = in.bit() ? -1.0 : 1.0;
        break;
      }
      case 1:  // the triangle's normal, either way
        d = have_tri ? glm::cross(corner(tri, 1) - corner(tri, 0), corner(tri, 2) - corner(tri, 0)) : glm::dvec3(0);
        if (in.bit()) d = -d;
        break;
      case 2:  // in the triangle's plane, along an edge (or the target's tangent)
        d = in.bit() ? -along : along;
        break;
      case 3: {  // each component +0, -0, +-1, +-2^-k or free
        for (int k = 0; k < 3; ++k) {
          std::uint8_t c = in.next();
          switch (c % 5) {
            case 0: d[k] = (c & 8) ? -0.0 : 0.0; break;
            case 1: d[k] = (c & 8) ? -1.0 : 1.0; break;
            case 2: d[k] = std::ldexp((c & 8) ? -1.0 : 1.0, -static_cast<int>(in.below(40))); break;
            default: d[k] = in.unit() * 2.0 - 1.0; break;
          }
        }
        break;
      }
      default:  // any direction
        for (int k = 0; k < 3; ++k) d[k] = in.unit() - 0.5;
        break;
    }
    if (!(glm::length(d) > 0.0)) d = glm::dvec3(0.0, -0.0, 1.0);
    // The origin: on the target, or up to 2 scene sizes before it.
    double distance = (how & 0x20) ? 0.0 : size * (0.01 + 2.0 * in.unit());
    glm::dvec3 o = target - distance / glm::length(d) * d;
    Ray ray{float(o.x), float(o.y), float(o.z), float(d.x), float(d.y), float(d.z), 0.0f, kInf};
    double t_target = distance / glm::length(d);
    switch (in.below(8)) {
      case 0: ray.tmax = float(t_target); break;             // ends at the target
      case 1: ray.tmin = float(t_target); break;             // starts at it
      case 2: ray.tmin = ray.tmax = float(t_target); break;  // only there
      default: break;
    }
    rays.push_back(ray);
  }
  // Always kMaxRays rays (the decoded ones repeated): PoCL specialises a
  // kernel for each work-group size it picks for a launch's size, so that
  // launches of one size compile once (LLVMFuzzerInitialize).
  for (std::size_t i = 0; rays.size() < kMaxRays; ++i) rays.push_back(rays[i]);
  return rays;
}

std::string describe(const Hit& h) {
  char text[96];
  std::snprintf(text, sizeof text, "prim %d t=%.9g", h.prim, h.t);
  return text;
}

double distance_to_segment(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b) {
  glm::dvec3 ab = b - a;
  double len2 = glm::dot(ab, ab);
  double s = len2 > 0 ? glm::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return glm::length(p - (a + s * ab));
}

// The distance from p to the primitive (a triangle with an area, or a
// sphere's surface), in double.
double distance_to_primitive(const Geometry& g, std::uint32_t prim, const glm::dvec3& p) {
  if (prim >= g.triangles.size()) {
    const rtcl::Sphere& sp = g.spheres[prim - g.triangles.size()];
    return std::abs(glm::length(p - glm::dvec3(sp.center)) - double(sp.radius));
  }
  const glm::uvec3& t = g.triangles[prim];
  glm::dvec3 a(g.vertices[t.x]), b(g.vertices[t.y]), c(g.vertices[t.z]);
  glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
  glm::dvec3 q = p - glm::dot(p - a, n) * n;  // p projected on the plane
  bool inside = glm::dot(glm::cross(b - a, q - a), n) >= 0 && glm::dot(glm::cross(c - b, q - b), n) >= 0 &&
                glm::dot(glm::cross(a - c, q - c), n) >= 0;
  if (inside) return glm::length(p - q);
  return std::min({distance_to_segment(p, a, b), distance_to_segment(p, b, c), distance_to_segment(p, c, a)});
}

// Whether the ray meets the triangle's plane at a grazing angle (|cos| below
// 2^-8 against the normal): the kernel's rounding errors of a few float ulps,
// amplified by 1 / |cos|, then exceed the 256 ulps of the tolerance in t and
// in (u, v). (u, v) are not checked there; the hit's point still is.
bool grazing(const Geometry& g, std::uint32_t prim, const glm::dvec3& d) {
  const glm::uvec3& t = g.triangles[prim];
  glm::dvec3 a(g.vertices[t.x]), b(g.vertices[t.y]), c(g.vertices[t.z]);
  glm::dvec3 n = glm::cross(b - a, c - a);
  return std::abs(glm::dot(n, d)) < std::ldexp(glm::length(n) * glm::length(d), -8);
}

// "" when the answer is neither a leak nor a false hit (see the top of the
// file), else why. `reference` is reference_closest's answer for the ray.
std::string judge(const Geometry& g, const rtcl::Aabb& bounds, const Ray& ray, const Hit& h, Query query,
                  const Hit& reference) {
  const rtcl::test::Tolerance tol = rtcl::test::tolerance_in(bounds, ray);
  char why[320];
  if (h.prim >= 0) {
    auto prim = static_cast<std::uint32_t>(h.prim);
    if (prim >= g.primitive_count() || (prim < g.triangles.size() && rtcl::zero_area(g, prim)))
      return "a hit of prim " + std::to_string(h.prim) + ", which is out of range or has no area";
    glm::dvec3 o(ray.ox, ray.oy, ray.oz), d(ray.dx, ray.dy, ray.dz);
    glm::dvec3 p = o + double(h.t) * d;
    double off = distance_to_primitive(g, prim, p);
    if (!(off <= tol.space) || !(h.t >= ray.tmin - tol.t && h.t <= ray.tmax + tol.t)) {
      std::snprintf(why, sizeof why, "false hit: prim %d at t=%.9g, whose point is %.9g from it (tolerance %.9g)",
                    h.prim, h.t, off, tol.space);
      return why;
    }
    if (prim >= g.triangles.size()) {
      if (h.u != 0.0f || h.v != 0.0f) return "a sphere hit with (u, v) not 0: " + describe(h);
    } else if (!grazing(g, prim, d)) {
      const glm::uvec3& t = g.triangles[prim];
      double u = h.u, v = h.v;
      glm::dvec3 named = (1.0 - u - v) * glm::dvec3(g.vertices[t.x]) + u * glm::dvec3(g.vertices[t.y]) +
                         v * glm::dvec3(g.vertices[t.z]);
      double uv_off = glm::length(named - p);
      if (!(uv_off <= 2.0 * tol.space)) {
        std::snprintf(why, sizeof why, "prim %d at t=%.9g: (u, v) = (%.9g, %.9g) name a point %.9g from o + t d "
                      "(tolerance %.9g)", h.prim, h.t, h.u, h.v, uv_off, 2.0 * tol.space);
        return why;
      }
    }
  } else if (h.prim != -1 || !std::isinf(h.t) || h.t < 0 || h.u != 0.0f || h.v != 0.0f) {
    return "a miss that is not t=+inf prim=-1 u=v=0: " + describe(h);
  }
  if (reference.prim < 0) return "";
  if (h.prim < 0 || (query == Query::closest && double(h.t) > double(reference.t) + tol.t)) {
    std::snprintf(why, sizeof why, "leak: %s, but the reference hits prim %d at t=%.9g, inside it by more than the "
                  "tolerance (%.9g; %.9g in t)", describe(h).c_str(), reference.prim, reference.t, tol.space, tol.t);
    return why;
  }
  return "";
}

// The input being checked, and, under libFuzzer (LLVMFuzzerInitialize,
// which the replay of files does not call), where a failing one is written:
// libFuzzer's -artifact_prefix, else the working directory. The target
// writes it itself before aborting, so that a violation is kept even where
// the process dies before libFuzzer's crash handler runs.
struct CurrentInput {
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
  bool save = false;
  std::string prefix;
} current;

// Writes the current input to <prefix>violation-<FNV-1a hash>, returns its path.
std::string save_current_input() {
  std::uint64_t hash = 1469598103934665603ull;
  for (std::size_t i = 0; i < current.size; ++i) hash = (hash ^ current.data[i]) * 1099511628211ull;
  char name[40];
  std::snprintf(name, sizeof name, "violation-%016llx", static_cast<unsigned long long>(hash));
  std::string path = current.prefix + name;
  if (std::FILE* f = std::fopen(path.c_str(), "wb")) {
    bool ok = std::fwrite(current.data, 1, current.size, f) == current.size;
    ok = std::fclose(f) == 0 && ok;
    if (ok) return path;
  }
  return "(not written: " + path + ")";
}

// What one call and one ray looked like, for the failure message.
[[noreturn]] void fail(const std::string& structure, Precision level, Coherence coherence, Query query,
                       std::size_t index, const Ray& ray, const std::string& why) {
  const char* order = coherence == Coherence::coherent ? "coherent" : coherence == Coherence::scattered ? "scattered"
                                                                                                         : "incoherent";
  std::fprintf(stderr,
               "structures_fuzz: %s at %s, %s %s hit: ray %zu o=(%.9g, %.9g, %.9g) d=(%.9g, %.9g, %.9g) "
               "t=[%.9g, %.9g]: %s\n",
               structure.c_str(), std::string(rtcl::precision_name(level)).c_str(), order,
               query == Query::closest ? "closest" : "any", index, ray.ox, ray.oy, ray.oz, ray.dx, ray.dy, ray.dz,
               ray.tmin, ray.tmax, why.c_str());
  if (current.save) std::fprintf(stderr, "structures_fuzz: the input is saved as %s\n", save_current_input().c_str());
  std::abort();
}

const rtcl::Device& device() {
  static const rtcl::Device opened = rtcl::Device::open();
  return opened;
}

std::vector<std::string> structures() {
  std::vector<std::string> names = rtcl::accel_names();
  names.push_back("bvh:presplit=1");
  return names;
}

std::vector<Precision> levels() {
  std::vector<Precision> out = {Precision::robust};
  if (rtcl::precision_unsupported(device().info(), Precision::exact).empty()) out.push_back(Precision::exact);
  return out;
}

// The calls that run different kernels on this structure.
std::vector<std::pair<Coherence, Query>> calls_of(const rtcl::Accel& accel) {
  std::vector<std::pair<Coherence, Query>> calls = {{Coherence::incoherent, Query::closest},
                                                    {Coherence::incoherent, Query::any}};
  if (accel.rays_per_work_item(Coherence::coherent) != accel.rays_per_work_item(Coherence::incoherent))
    calls.insert(calls.end(), {{Coherence::coherent, Query::closest}, {Coherence::coherent, Query::any}});
  if (accel.sorts(Coherence::scattered) && accel.precision() == Precision::robust)
    calls.insert(calls.end(), {{Coherence::scattered, Query::closest}, {Coherence::scattered, Query::any}});
  return calls;
}

std::vector<Hit> run(const rtcl::Accel& accel, const std::vector<Ray>& rays, Query query, Coherence coherence) {
  std::vector<Hit> hits(rays.size());
  accel.trace(query, rtcl::Rays(rays), hits, coherence);
  return hits;
}

rtcl::AccelConfig config_at(Precision level) { return {level, {}, rtcl::ScatteredSort::always}; }

void check(const Scene& scene, const std::vector<Ray>& rays) {
  const Geometry& g = scene.geometry;
  try {
    rtcl::validate(g);
  } catch (const rtcl::Error&) {
    return;  // nothing to hit (zero-area triangles only): every structure refuses it alike
  }
  const rtcl::Aabb bounds = g.bounds();
  std::vector<Hit> references = rtcl::test::reference_closest_all(g, rays);
  std::vector<rtcl::test::DoubleAnswer> decided;
  double scene_size = glm::length(glm::dvec3(g.bounds().extent()));
  for (const Ray& ray : rays) decided.push_back(rtcl::test::double_closest(g, ray, scene_size));
  for (Precision level : levels()) {
    auto brute = rtcl::make_accel(device(), "brute", g, config_at(level));
    std::vector<Hit> expected[2] = {run(*brute, rays, Query::closest, Coherence::incoherent),
                                    run(*brute, rays, Query::any, Coherence::incoherent)};
    for (const std::string& name : structures()) {
      std::unique_ptr<rtcl::Accel> accel;
      try {
        accel = rtcl::make_accel(device(), name, g, config_at(level));
      } catch (const rtcl::Error& e) {
        fail(name, level, Coherence::incoherent, Query::closest, 0, rays[0],
             std::string("refuses a scene brute force accepts: ") + e.what());
      }
      for (auto [coherence, query] : calls_of(*accel)) {
        std::vector<Hit> hits = run(*accel, rays, query, coherence);
        const std::vector<Hit>& brute_hits = expected[query == Query::closest ? 0 : 1];
        for (std::size_t i = 0; i < rays.size(); ++i) {
          const Hit& h = hits[i];
          if ((h.prim < 0) != (brute_hits[i].prim < 0) || (query == Query::closest && h.t != brute_hits[i].t &&
                                                           h.prim >= 0))
            fail(name, level, coherence, query, i, rays[i],
                 describe(h) + ", but brute force at the same level " + describe(brute_hits[i]));
          std::string why = judge(g, bounds, rays[i], h, query, references[i]);
          if (!why.empty()) fail(name, level, coherence, query, i, rays[i], why);
          if (level == Precision::exact && query == Query::closest && decided[i].prim != -2) {
            const rtcl::test::DoubleAnswer& want = decided[i];
            float t_ref = static_cast<float>(want.t);
            bool t_ok = h.prim < 0 || std::abs(h.t - t_ref) <= std::abs(std::nextafter(t_ref, kInf) - t_ref);
            if (h.prim != want.prim || !t_ok)
              fail(name, level, coherence, query, i, rays[i],
                   describe(h) + ", but double precision decides prim " + std::to_string(want.prim) + " t=" +
                       std::to_string(want.t));
          }
        }
      }
    }
  }
}

// Builds every program a fuzz input can ask for on tiny scenes (with and
// without spheres: RTCL_HAS_SPHERES is a program option), so that inputs
// pay no kernel build. The BVH's stack size and bvh-mixed's choice of
// filters are program options too; a scene that needs another is built at
// its first use, once per process (and once per PoCL cache).
void build_programs() {
  Geometry g;
  g.source = "fuzz warm-up";
  g.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 1}};
  g.triangles = {{0, 1, 2}, {1, 3, 2}};
  std::vector<Ray> rays(kMaxRays, Ray{0.2f, 0.2f, 1.0f, 0.0f, 0.0f, -1.0f, 0.0f, kInf});
  for (bool with_spheres : {false, true}) {
    if (with_spheres) g.spheres = {{{0.5f, 0.5f, 0.5f}, 0.25f}};
    for (Precision level : levels())
      for (const std::string& name : structures()) {
        auto accel = rtcl::make_accel(device(), name, g, config_at(level));
        for (auto [coherence, query] : calls_of(*accel)) run(*accel, rays, query, coherence);
      }
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  current.save = true;
  const std::string flag = "-artifact_prefix=";
  for (int i = 1; i < *argc; ++i)
    if (std::string arg = (*argv)[i]; arg.compare(0, flag.size(), flag) == 0) current.prefix = arg.substr(flag.size());
  build_programs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  current.data = data;
  current.size = size;
  Bytes in(data, size);
  Scene scene = make_scene(in);
  if (scene.geometry.triangles.empty() && scene.geometry.spheres.empty()) return 0;
  check(scene, make_rays(in, scene));
  return 0;
}
