// rtcl.RaycastingScene: Open3D's RaycastingScene (0.18) names, argument
// shapes and result keys over MeshScene, numpy arrays in and out
// (docs/python.md). Every method checks its arguments (GIL held), makes its
// output arrays, then releases the GIL for the conversions and the device
// work.
#include "raycasting_scene.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "array_io.hpp"
#include "devices.hpp"
#include "mesh_scene.hpp"
#include "rtcl/accel_options.hpp"
#include "rtcl/error.hpp"
#include "rtcl/precision.hpp"
#include "scratch.hpp"

namespace rtcl::python {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

void check_nthreads(long long nthreads, const char* call) {
  if (nthreads < 0)
    throw py::value_error(std::string(call) + ": nthreads is " + std::to_string(nthreads) +
                          "; must be >= 0 (accepted as Open3D's; the OpenCL device sets the threads)");
}

float ray_bound(double value, const char* call, const char* param) {
  if (std::isnan(value)) throw py::value_error(std::string(call) + ": " + param + " is NaN");
  return static_cast<float>(value);
}

unsigned check_nsamples(long long nsamples, const char* call) {
  if (nsamples < 1 || nsamples % 2 == 0 || nsamples > 0x7fffffff)
    throw py::value_error(std::string(call) + ": nsamples is " + std::to_string(nsamples) +
                          "; must be odd (1, 3, 5, ...)");
  return static_cast<unsigned>(nsamples);
}

// An id argument as uint32: ValueError naming it when negative or beyond.
std::uint32_t check_id(long long id, const char* call, const char* param) {
  if (id < 0 || id >= 0xffffffffll)
    throw py::value_error(std::string(call) + ": " + param + " is " + std::to_string(id) + "; no such id");
  return static_cast<std::uint32_t>(id);
}

Coherence coherence_of(bool coherent) { return coherent ? Coherence::coherent : Coherence::incoherent; }

// The scene as it is now, or nothing (an empty view) when there is no ray
// or point to query.
SceneView view_of(const MeshScene& scene, std::size_t count) {
  if (count == 0) return {};
  return scene.snapshot();
}

// The flat structure that count_intersections, list_intersections and the
// point queries run on (the instanced scene's flattened copy, made from the
// snapshot alone: the rtcl::Scene's commit is not held), or null when there
// is nothing to query or to hit. `built` and `flat` keep them.
const Accel* flat_structure(const MeshScene& scene, std::size_t count, std::shared_ptr<const BuiltScene>& built,
                            std::shared_ptr<const FlatScene>& flat) {
  if (count == 0) return nullptr;
  built = scene.snapshot().built;
  if (!built->hittable) return nullptr;
  flat = built->flattened(scene.device(), scene.accel_spec(), scene.config());
  return flat->accel.get();
}

// Writes the face normal of triangle `prim` of placement `p` to out[0..2]:
// the unit (v1 - v0) x (v2 - v0) of the placed triangle.
inline void placed_normal(const BuiltScene& b, const Placement& p, std::uint32_t prim, float* out) {
  glm::vec3 n = b.meshes[p.geometry]->normals[prim];
  if (!p.identity) n = glm::normalize(p.cofactor * n);
  out[0] = n.x;
  out[1] = n.y;
  out[2] = n.z;
}

// Two sets of scratch arrays for pipeline()'s slots.
struct Slots {
  ScratchLease a, b;
  Scratch& operator[](int slot) { return slot == 0 ? *a : *b; }
};

Rays records(Scratch& scratch, std::size_t n) { return Rays(std::span<const Ray>(scratch.rays.data(), n)); }

Points points_of(Scratch& scratch, std::size_t n) { return Points(std::span<const float>(scratch.xyz.data(), 3 * n)); }

// The ray queries' pipeline: each chunk's rays packed into its slot, then
// run(scratch, first, n), then unpack(scratch, first, n, parallel).
template <class Run, class Unpack>
void ray_pipeline(const FloatRecords& rays, float tmin, float tmax, Run&& run, Unpack&& unpack) {
  Slots slots;
  pipeline(
      rays.count,
      [&](int slot, std::size_t first, std::size_t n, bool parallel) {
        pack_rays(rays, first, tmin, tmax, Scratch::first(slots[slot].rays, n), parallel);
      },
      [&](int slot, std::size_t first, std::size_t n) { run(slots[slot], first, n); },
      [&](int slot, std::size_t first, std::size_t n, bool parallel) { unpack(slots[slot], first, n, parallel); });
}

// The same for the point queries.
template <class Run, class Unpack>
void point_pipeline(const FloatRecords& points, Run&& run, Unpack&& unpack) {
  Slots slots;
  pipeline(
      points.count,
      [&](int slot, std::size_t first, std::size_t n, bool parallel) {
        pack_points(points, first, Scratch::first(slots[slot].xyz, 3 * n), parallel);
      },
      [&](int slot, std::size_t first, std::size_t n) { run(slots[slot], first, n); },
      [&](int slot, std::size_t first, std::size_t n, bool parallel) { unpack(slots[slot], first, n, parallel); });
}

constexpr auto kNothing = [](Scratch&, std::size_t, std::size_t, bool) {};

// The output arrays of cast_rays (instance: null when not returned).
struct RayAnswers {
  float* t;
  std::uint32_t* geometry;
  std::uint32_t* primitive;
  std::uint32_t* instance;
  float* uv;
  float* normal;
};

// Writes the answers of hits[0, n) of a flat scene to rays [first, first +
// n): one pass over the hits, each output written in order. `one_part`: the
// scene has one mesh (no search for the part).
void write_flat(const FlatScene& flat, bool one_part, const Hit* __restrict hits, std::size_t n, std::size_t first,
                const RayAnswers& out) {
  float* __restrict t = out.t + first;
  std::uint32_t* __restrict g = out.geometry + first;
  std::uint32_t* __restrict p = out.primitive + first;
  std::uint32_t* __restrict id = out.instance ? out.instance + first : nullptr;
  float* __restrict uv = out.uv + 2 * first;
  float* __restrict nrm = out.normal + 3 * first;
  const glm::vec3* __restrict normals = flat.normals.data();
  // The normals' table is read in the hits' order, which jumps: each
  // hit's normal is fetched kAhead hits before it is written.
  constexpr std::size_t kAhead = 16;
  for (std::size_t k = 0; k < n; ++k) {
    if (k + kAhead < n && hits[k + kAhead].prim >= 0)
      __builtin_prefetch(normals + hits[k + kAhead].prim);
    const Hit h = hits[k];
    if (id) id[k] = kInvalidId;
    if (h.prim < 0) {
      t[k] = kInf;
      g[k] = p[k] = kInvalidId;
      uv[2 * k] = uv[2 * k + 1] = 0.0f;
      nrm[3 * k] = nrm[3 * k + 1] = nrm[3 * k + 2] = 0.0f;
      continue;
    }
    t[k] = h.t;
    if (one_part) {
      g[k] = 0;
      p[k] = static_cast<std::uint32_t>(h.prim);
    } else {
      flat.locate(h.prim, g[k], p[k]);  // the flat scene's placement k is geometry k
    }
    uv[2 * k] = h.u;
    uv[2 * k + 1] = h.v;
    const glm::vec3 normal = normals[h.prim];
    nrm[3 * k] = normal.x;
    nrm[3 * k + 1] = normal.y;
    nrm[3 * k + 2] = normal.z;
  }
}

py::dict cast_rays(const MeshScene& scene, py::handle rays_in, long long nthreads, double tnear, double tfar,
                   bool coherent) {
  const char* call = "cast_rays";
  check_nthreads(nthreads, call);
  const FloatRecords rays = float_records(rays_in, 6, call, "rays");
  const float tmin = ray_bound(tnear, call, "tnear"), tmax = ray_bound(tfar, call, "tfar");
  // Instanced scenes never become flat again: a scene instanced now is
  // instanced at the snapshot below.
  const bool with_instances = scene.instanced();
  auto t_hit = output_array<float>(rays.shape);
  auto geometry_ids = output_array<std::uint32_t>(rays.shape);
  auto primitive_ids = output_array<std::uint32_t>(rays.shape);
  auto uvs = output_array<float>(rays.shape, {2});
  auto normals = output_array<float>(rays.shape, {3});
  py::array_t<std::uint32_t> instance_ids;
  if (with_instances) instance_ids = output_array<std::uint32_t>(rays.shape);
  float* t_out = t_hit.mutable_data();
  std::uint32_t* g_out = geometry_ids.mutable_data();
  std::uint32_t* p_out = primitive_ids.mutable_data();
  float* uv_out = uvs.mutable_data();
  float* n_out = normals.mutable_data();
  std::uint32_t* i_out = with_instances ? instance_ids.mutable_data() : nullptr;
  {
    py::gil_scoped_release release;
    const SceneView view = view_of(scene, rays.count);
    const BuiltScene* b = view.built.get();
    auto miss = [&](std::size_t i) {
      t_out[i] = kInf;
      g_out[i] = p_out[i] = kInvalidId;
      if (i_out) i_out[i] = kInvalidId;
      uv_out[2 * i] = uv_out[2 * i + 1] = 0.0f;
      n_out[3 * i] = n_out[3 * i + 1] = n_out[3 * i + 2] = 0.0f;
    };
    if (!b || !b->hittable) {
      for_parts(rays.count, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) miss(i);
      });
    } else if (b->flat) {
      const FlatScene& flat = *b->flat;
      const bool one_part = flat.first_prim.size() == 2;  // one mesh: no search
      ray_pipeline(
          rays, tmin, tmax,
          [&](Scratch& s, std::size_t, std::size_t n) {
            flat.accel->trace(Query::closest, records(s, n), Scratch::first(s.hits, n), coherence_of(coherent));
          },
          [&](Scratch& s, std::size_t first, std::size_t n, bool parallel) {
            const RayAnswers out{t_out, g_out, p_out, i_out, uv_out, n_out};
            for_parts(
                n,
                [&](std::size_t begin, std::size_t end) {
                  write_flat(flat, one_part, s.hits.data() + begin, end - begin, first + begin, out);
                },
                parallel);
          });
    } else {
      ray_pipeline(
          rays, tmin, tmax,
          [&](Scratch& s, std::size_t, std::size_t n) {
            b->scene->trace(Query::closest, records(s, n), Scratch::first(s.hits, n), Scratch::first(s.ids, n), {},
                            coherence_of(coherent));
          },
          [&](Scratch& s, std::size_t first, std::size_t n, bool parallel) {
            for_parts(
                n,
                [&](std::size_t begin, std::size_t end) {
                  for (std::size_t k = begin; k < end; ++k) {
                    const std::size_t i = first + k;
                    const Hit& h = s.hits[k];
                    if (h.prim < 0) {
                      miss(i);
                      continue;
                    }
                    // The scene's user id of an instance is its placement.
                    const Placement& p = b->placements[s.ids[k]];
                    t_out[i] = h.t;
                    g_out[i] = p.geometry;
                    p_out[i] = static_cast<std::uint32_t>(h.prim);
                    if (i_out) i_out[i] = p.instance;
                    uv_out[2 * i] = h.u;
                    uv_out[2 * i + 1] = h.v;
                    placed_normal(*b, p, static_cast<std::uint32_t>(h.prim), n_out + 3 * i);
                  }
                },
                parallel);
          });
    }
  }
  py::dict out;
  out["t_hit"] = t_hit;
  out["geometry_ids"] = geometry_ids;
  out["primitive_ids"] = primitive_ids;
  out["primitive_uvs"] = uvs;
  out["primitive_normals"] = normals;
  if (with_instances) out["instance_ids"] = instance_ids;
  return out;
}

py::array test_occlusions(const MeshScene& scene, py::handle rays_in, double tnear, double tfar, long long nthreads,
                          bool coherent) {
  const char* call = "test_occlusions";
  check_nthreads(nthreads, call);
  const FloatRecords rays = float_records(rays_in, 6, call, "rays");
  const float tmin = ray_bound(tnear, call, "tnear"), tmax = ray_bound(tfar, call, "tfar");
  auto occluded = output_array<bool>(rays.shape);
  bool* out = occluded.mutable_data();
  {
    py::gil_scoped_release release;
    const SceneView view = view_of(scene, rays.count);
    const BuiltScene* b = view.built.get();
    if (!b || !b->hittable) {
      std::fill(out, out + rays.count, false);
    } else {
      ray_pipeline(
          rays, tmin, tmax,
          [&](Scratch& s, std::size_t, std::size_t n) {
            if (b->flat)
              b->flat->accel->trace(Query::any, records(s, n), Scratch::first(s.hits, n), coherence_of(coherent));
            else
              b->scene->trace(Query::any, records(s, n), Scratch::first(s.hits, n), {}, {}, coherence_of(coherent));
          },
          [&](Scratch& s, std::size_t first, std::size_t n, bool parallel) {
            for_parts(
                n,
                [&](std::size_t begin, std::size_t end) {
                  for (std::size_t k = begin; k < end; ++k) out[first + k] = s.hits[k].prim >= 0;
                },
                parallel);
          });
    }
  }
  return occluded;
}

py::array count_intersections(const MeshScene& scene, py::handle rays_in, long long nthreads) {
  const char* call = "count_intersections";
  check_nthreads(nthreads, call);
  const FloatRecords rays = float_records(rays_in, 6, call, "rays");
  auto counts = output_array<std::int32_t>(rays.shape);
  std::int32_t* out = counts.mutable_data();
  {
    py::gil_scoped_release release;
    std::shared_ptr<const BuiltScene> built;
    std::shared_ptr<const FlatScene> flat;
    const Accel* accel = flat_structure(scene, rays.count, built, flat);
    if (!accel) {
      std::fill(out, out + rays.count, 0);
    } else {
      // Counts of crossings are far below 2^31: the int32 array (Open3D's
      // dtype) holds the library's uint32 values unchanged.
      auto* counts_out = reinterpret_cast<std::uint32_t*>(out);
      ray_pipeline(
          rays, 0.0f, kInf,
          [&](Scratch& s, std::size_t first, std::size_t n) {
            accel->count(records(s, n), std::span<std::uint32_t>(counts_out + first, n));
          },
          kNothing);
    }
  }
  return counts;
}

py::dict list_intersections(const MeshScene& scene, py::handle rays_in, long long nthreads) {
  const char* call = "list_intersections";
  check_nthreads(nthreads, call);
  const FloatRecords rays = float_records(rays_in, 6, call, "rays");
  // One library call for all rays (its answer is one compressed list).
  AllHits all;
  std::shared_ptr<const BuiltScene> built;
  std::shared_ptr<const FlatScene> flat;
  {
    py::gil_scoped_release release;
    if (const Accel* accel = flat_structure(scene, rays.count, built, flat)) {
      HostArray<Ray> packed(rays.count);
      pack_rays(rays, 0, 0.0f, kInf, packed);
      all = accel->all_hits(Rays(std::span<const Ray>(packed)));
    }
  }
  const std::size_t total = all.hits.size();
  if (total > 0xffffffffu)
    throw Error("list_intersections: " + std::to_string(total) +
                " intersections exceed the uint32 range of ray_splits; pass fewer rays per call");
  const auto k = static_cast<py::ssize_t>(total);
  auto ray_splits = output_array<std::uint32_t>({static_cast<py::ssize_t>(rays.count) + 1});
  auto ray_ids = output_array<std::uint32_t>({k});
  auto t_hit = output_array<float>({k});
  auto geometry_ids = output_array<std::uint32_t>({k});
  auto primitive_ids = output_array<std::uint32_t>({k});
  auto uvs = output_array<float>({k}, {2});
  const bool with_instances = scene.instanced();
  py::array_t<std::uint32_t> instance_ids;
  if (with_instances) instance_ids = output_array<std::uint32_t>({k});
  std::uint32_t* i_out = with_instances ? instance_ids.mutable_data() : nullptr;
  std::uint32_t* splits = ray_splits.mutable_data();
  std::uint32_t* ids = ray_ids.mutable_data();
  float* t_out = t_hit.mutable_data();
  std::uint32_t* g_out = geometry_ids.mutable_data();
  std::uint32_t* p_out = primitive_ids.mutable_data();
  float* uv_out = uvs.mutable_data();
  {
    py::gil_scoped_release release;
    splits[0] = 0;
    for_parts(rays.count, [&](std::size_t begin, std::size_t end) {
      for (std::size_t r = begin; r < end; ++r) {
        const std::size_t first = all.offsets.empty() ? 0 : all.offsets[r];
        const std::size_t last = all.offsets.empty() ? 0 : all.offsets[r + 1];
        splits[r + 1] = static_cast<std::uint32_t>(last);
        for (std::size_t j = first; j < last; ++j) {
          const Hit& h = all.hits[j];
          ids[j] = static_cast<std::uint32_t>(r);
          t_out[j] = h.t;
          std::uint32_t placement;
          flat->locate(h.prim, placement, p_out[j]);
          const Placement& p = built->placements[placement];
          g_out[j] = p.geometry;
          if (i_out) i_out[j] = p.instance;
          uv_out[2 * j] = h.u;
          uv_out[2 * j + 1] = h.v;
        }
      }
    });
  }
  py::dict out;
  out["ray_splits"] = ray_splits;
  out["ray_ids"] = ray_ids;
  out["t_hit"] = t_hit;
  out["geometry_ids"] = geometry_ids;
  out["primitive_ids"] = primitive_ids;
  out["primitive_uvs"] = uvs;
  if (with_instances) out["instance_ids"] = instance_ids;
  return out;
}

// compute_closest_points and compute_distance: the library's closest
// points chunk by chunk, then write(built, flat, first, n, hits, parallel);
// hits is empty when the scene has nothing to hit.
template <class Write>
void closest_points(const MeshScene& scene, const FloatRecords& points, const char* call, Write&& write) {
  check_points(points, call, "query_points");  // NaN and infinite points are refused, scene or not
  std::shared_ptr<const BuiltScene> built;
  std::shared_ptr<const FlatScene> flat;
  const Accel* accel = flat_structure(scene, points.count, built, flat);
  if (!accel) {
    write(built.get(), flat.get(), 0, points.count, std::span<const PointHit>(), true);
    return;
  }
  point_pipeline(
      points,
      [&](Scratch& s, std::size_t, std::size_t n) {
        accel->closest_points(points_of(s, n), Scratch::first(s.point_hits, n));
      },
      [&](Scratch& s, std::size_t first, std::size_t n, bool parallel) {
        write(built.get(), flat.get(), first, n, std::span<const PointHit>(s.point_hits.data(), n), parallel);
      });
}

py::dict compute_closest_points(const MeshScene& scene, py::handle points_in, long long nthreads) {
  const char* call = "compute_closest_points";
  check_nthreads(nthreads, call);
  const FloatRecords points = float_records(points_in, 3, call, "query_points");
  auto closest = output_array<float>(points.shape, {3});
  auto geometry_ids = output_array<std::uint32_t>(points.shape);
  auto primitive_ids = output_array<std::uint32_t>(points.shape);
  auto uvs = output_array<float>(points.shape, {2});
  auto normals = output_array<float>(points.shape, {3});
  const bool with_instances = scene.instanced();
  py::array_t<std::uint32_t> instance_ids;
  if (with_instances) instance_ids = output_array<std::uint32_t>(points.shape);
  std::uint32_t* i_out = with_instances ? instance_ids.mutable_data() : nullptr;
  float* c_out = closest.mutable_data();
  std::uint32_t* g_out = geometry_ids.mutable_data();
  std::uint32_t* p_out = primitive_ids.mutable_data();
  float* uv_out = uvs.mutable_data();
  float* n_out = normals.mutable_data();
  {
    py::gil_scoped_release release;
    closest_points(
        scene, points, call,
        [&](const BuiltScene* built, const FlatScene* flat, std::size_t first, std::size_t n,
            std::span<const PointHit> hits, bool parallel) {
          for_parts(
              n,
              [&](std::size_t begin, std::size_t end) {
                for (std::size_t k = begin; k < end; ++k) {
                  const std::size_t i = first + k;
                  if (hits.empty() || hits[k].prim < 0) {
                    c_out[3 * i] = c_out[3 * i + 1] = c_out[3 * i + 2] = kNaN;
                    g_out[i] = p_out[i] = kInvalidId;
                    if (i_out) i_out[i] = kInvalidId;
                    uv_out[2 * i] = uv_out[2 * i + 1] = 0.0f;
                    n_out[3 * i] = n_out[3 * i + 1] = n_out[3 * i + 2] = 0.0f;
                    continue;
                  }
                  const PointHit& h = hits[k];
                  c_out[3 * i] = h.x;
                  c_out[3 * i + 1] = h.y;
                  c_out[3 * i + 2] = h.z;
                  std::uint32_t placement;
                  flat->locate(h.prim, placement, p_out[i]);
                  const Placement& p = built->placements[placement];
                  g_out[i] = p.geometry;
                  if (i_out) i_out[i] = p.instance;
                  uv_out[2 * i] = h.u;
                  uv_out[2 * i + 1] = h.v;
                  const glm::vec3& normal = flat->normals[static_cast<std::size_t>(h.prim)];
                  n_out[3 * i] = normal.x;
                  n_out[3 * i + 1] = normal.y;
                  n_out[3 * i + 2] = normal.z;
                }
              },
              parallel);
        });
  }
  py::dict out;
  out["points"] = closest;
  out["geometry_ids"] = geometry_ids;
  out["primitive_ids"] = primitive_ids;
  out["primitive_uvs"] = uvs;
  out["primitive_normals"] = normals;
  if (with_instances) out["instance_ids"] = instance_ids;
  return out;
}

py::array compute_distance(const MeshScene& scene, py::handle points_in, long long nthreads) {
  const char* call = "compute_distance";
  check_nthreads(nthreads, call);
  const FloatRecords points = float_records(points_in, 3, call, "query_points");
  auto distance = output_array<float>(points.shape);
  float* out = distance.mutable_data();
  {
    py::gil_scoped_release release;
    closest_points(
        scene, points, call,
        [&](const BuiltScene*, const FlatScene*, std::size_t first, std::size_t n, std::span<const PointHit> hits,
            bool parallel) {
          for_parts(
              n,
              [&](std::size_t begin, std::size_t end) {
                for (std::size_t k = begin; k < end; ++k) out[first + k] = hits.empty() ? kInf : hits[k].distance;
              },
              parallel);
        });
  }
  return distance;
}

// compute_signed_distance and compute_occupancy: per chunk, query(accel,
// points, out + first) writes n values, or `none` for every point when the
// scene has nothing to hit.
template <class Query>
py::array inside_query(const MeshScene& scene, py::handle points_in, long long nthreads, long long nsamples,
                       const char* call, float none, Query&& query) {
  check_nthreads(nthreads, call);
  const unsigned samples = check_nsamples(nsamples, call);
  const FloatRecords points = float_records(points_in, 3, call, "query_points");
  auto values = output_array<float>(points.shape);
  float* out = values.mutable_data();
  {
    py::gil_scoped_release release;
    check_points(points, call, "query_points");
    std::shared_ptr<const BuiltScene> built;
    std::shared_ptr<const FlatScene> flat;
    const Accel* accel = flat_structure(scene, points.count, built, flat);
    if (!accel) {
      std::fill(out, out + points.count, none);
    } else {
      point_pipeline(
          points,
          [&](Scratch& s, std::size_t first, std::size_t n) { query(*accel, points_of(s, n), samples, out + first); },
          kNothing);
    }
  }
  return values;
}
}  // namespace

void bind_raycasting_scene(py::module_& m) {
  py::class_<MeshScene> cls(m, "RaycastingScene", R"doc(
A scene of triangle meshes for ray and point queries on an OpenCL device,
with the method names, argument shapes and result keys of Open3D's
open3d.t.geometry.RaycastingScene; numpy arrays in and out.

device: None ($RTCL_DEVICE, else device 0), an index of rtcl.devices() or a
    substring of "platform device" (case-insensitive).
accel: the acceleration structure, with options ("bvh", "bvh-packet",
    "grid:lambda=4", ...; `rtcl structures` lists them). count_intersections,
    list_intersections and the point queries need the BVH family.
precision: "fast", "robust" (watertight, the default) or "exact".
nthreads: accepted as Open3D's (>= 0) and ignored: the device sets the threads.

Beyond Open3D: add_instance places a geometry again under a transform,
set_transform moves an instance, update_vertices moves a mesh's vertices
(docs/python.md, "Instances"). count_intersections, list_intersections and
the point queries of a scene with instances run on a copy with every
placement's triangles transformed (memory grows with the instances).
)doc");
  cls.def(py::init([](py::object device, const std::string& accel, const std::string& precision, long long nthreads) {
            check_nthreads(nthreads, "RaycastingScene");
            AccelConfig config;
            try {
              config.precision = parse_precision(precision);
            } catch (const Error& e) {
              throw py::value_error(e.what());
            }
            Device opened = open_device(device);
            try {
              return new MeshScene(opened, accel, config);
            } catch (const Error& e) {
              throw py::value_error(e.what());
            }
          }),
          py::kw_only(), py::arg("device") = py::none(), py::arg("accel") = "bvh", py::arg("precision") = "robust",
          py::arg("nthreads") = 0);
  cls.def_property_readonly_static(
      "INVALID_ID", [](py::object) { return kInvalidId; },
      "The geometry and primitive id of a miss: 2^32 - 1, as Open3D's.");
  cls.def(
      "add_triangles",
      [](MeshScene& scene, py::handle vertex_positions, py::handle triangle_indices) {
        std::vector<glm::vec3> vertices = read_vertices(vertex_positions, "add_triangles", "vertex_positions");
        std::vector<glm::uvec3> triangles = read_triangles(triangle_indices, "add_triangles", "triangle_indices");
        py::gil_scoped_release release;
        try {
          return scene.add_triangles(std::move(vertices), std::move(triangles));
        } catch (const Error& e) {
          throw py::value_error(e.what());
        }
      },
      py::arg("vertex_positions"), py::arg("triangle_indices"),
      R"doc(Adds a triangle mesh: vertex_positions (N, 3) float32 (or float64),
triangle_indices (M, 3) uint32 (or any integer dtype). Returns its geometry id
(0, 1, ... in call order), which hits report in geometry_ids.)doc");
  cls.def(
      "add_instance",
      [](MeshScene& scene, long long geometry_id, py::handle transform) {
        const Transform t = read_transform(transform, "add_instance", "transform");
        const std::uint32_t geometry = check_id(geometry_id, "add_instance", "geometry_id");
        py::gil_scoped_release release;
        try {
          return scene.add_instance(geometry, t);
        } catch (const Error& e) {
          throw py::value_error(e.what());
        }
      },
      py::arg("geometry_id"), py::arg("transform"),
      R"doc(Adds one more placement of geometry geometry_id (add_triangles' id; the
geometry also stays where add_triangles put it) under `transform`, an affine
object-to-world map: (4, 4) with last row (0, 0, 0, 1), or (3, 4), float32
or float64; mirroring and non-uniform scale allowed, singular or non-finite
transforms refused (ValueError). Returns its instance id (0, 1, ... in call
order), which hits report in instance_ids. Needs accel of the BVH family.)doc");
  cls.def(
      "set_transform",
      [](MeshScene& scene, long long instance_id, py::handle transform) {
        const Transform t = read_transform(transform, "set_transform", "transform");
        const std::uint32_t instance = check_id(instance_id, "set_transform", "instance_id");
        py::gil_scoped_release release;
        try {
          scene.set_transform(instance, t);
        } catch (const Error& e) {
          throw py::value_error(e.what());
        }
      },
      py::arg("instance_id"), py::arg("transform"),
      R"doc(A new transform (as add_instance's) for instance instance_id; queries see it
from the next call on.)doc");
  cls.def(
      "update_vertices",
      [](MeshScene& scene, long long geometry_id, py::handle vertex_positions) {
        std::vector<glm::vec3> vertices = read_vertices(vertex_positions, "update_vertices", "vertex_positions");
        const std::uint32_t geometry = check_id(geometry_id, "update_vertices", "geometry_id");
        py::gil_scoped_release release;
        try {
          scene.update_vertices(geometry, std::move(vertices));
        } catch (const Error& e) {
          throw py::value_error(e.what());
        }
      },
      py::arg("geometry_id"), py::arg("vertex_positions"),
      R"doc(New positions (N, 3) float32 or float64 for the vertices of geometry
geometry_id (N: its vertex count; the triangles stay), seen by every
placement of it from the next query on, which refits its structure. Needs
accel of the BVH family.)doc");
  cls.def("cast_rays", &cast_rays, py::arg("rays"), py::arg("nthreads") = 0, py::kw_only(), py::arg("tnear") = 0.0,
          py::arg("tfar") = std::numeric_limits<double>::infinity(), py::arg("coherent") = false,
          R"doc(The closest hit of each ray within [tnear, tfar]. rays: (..., 6) float32 or
float64, [ox, oy, oz, dx, dy, dz]; t is in units of the direction's length.
Returns a dict: t_hit (...) float32 (inf on a miss), geometry_ids and
primitive_ids (...) uint32 (INVALID_ID on a miss), primitive_uvs (..., 2)
float32 (the hit point is (1-u-v) v0 + u v1 + v v2), primitive_normals
(..., 3) float32 (unit face normal, (v1 - v0) x (v2 - v0) of the placed
triangle). After the first add_instance or update_vertices also
instance_ids (...) uint32: the hit instance's id, INVALID_ID on a miss and
for a hit on a geometry where add_triangles put it. coherent=True
promises that each group of 8 consecutive rays is alike (camera rays in
pixel order, create_rays_pinhole's): a packet kernel may then trace them.
NaN or infinite rays are misses.)doc");
  cls.def("test_occlusions", &test_occlusions, py::arg("rays"), py::arg("tnear") = 0.0,
          py::arg("tfar") = std::numeric_limits<double>::infinity(), py::arg("nthreads") = 0, py::kw_only(),
          py::arg("coherent") = false,
          R"doc(Whether some triangle lies on each ray within [tnear, tfar]: (...) bool.)doc");
  cls.def("count_intersections", &count_intersections, py::arg("rays"), py::arg("nthreads") = 0,
          R"doc(How often each ray crosses the surface (t >= 0): (...) int32. A crossing
through a shared edge or vertex counts once.)doc");
  cls.def("list_intersections", &list_intersections, py::arg("rays"), py::arg("nthreads") = 0,
          R"doc(Every crossing of every ray (t >= 0), each ray's sorted by t. Returns a dict:
ray_splits (rays + 1) uint32 (ray i's crossings are [ray_splits[i],
ray_splits[i+1])), ray_ids, t_hit, geometry_ids, primitive_ids (crossings)
and primitive_uvs (crossings, 2), rays counted over the flattened leading
shape; instance_ids as cast_rays'.)doc");
  cls.def("compute_closest_points", &compute_closest_points, py::arg("query_points"), py::arg("nthreads") = 0,
          R"doc(The nearest surface point of each query point ((..., 3) float32 or float64,
finite). Returns a dict: points (..., 3), geometry_ids, primitive_ids (...)
uint32, primitive_uvs (..., 2), primitive_normals (..., 3); instance_ids as
cast_rays'.)doc");
  cls.def("compute_distance", &compute_distance, py::arg("query_points"), py::arg("nthreads") = 0,
          R"doc(The distance of each query point to the surface: (...) float32 (inf
without triangles).)doc");
  cls.def(
      "compute_signed_distance",
      [](const MeshScene& scene, py::handle points, long long nthreads, long long nsamples) {
        return inside_query(scene, points, nthreads, nsamples, "compute_signed_distance", kInf,
                            [](const Accel& accel, const Points& p, unsigned n, float* out) {
                              const std::vector<float> d = accel.signed_distance(p, n);
                              std::copy(d.begin(), d.end(), out);
                            });
      },
      py::arg("query_points"), py::arg("nthreads") = 0, py::arg("nsamples") = 1,
      R"doc(The distance, negative inside a closed surface: (...) float32. Inside is the
majority of nsamples (odd) rays' crossing parities.)doc");
  cls.def(
      "compute_occupancy",
      [](const MeshScene& scene, py::handle points, long long nthreads, long long nsamples) {
        return inside_query(scene, points, nthreads, nsamples, "compute_occupancy", 0.0f,
                            [](const Accel& accel, const Points& p, unsigned n, float* out) {
                              const std::vector<std::uint8_t> inside = accel.occupancy(p, n);
                              for (std::size_t i = 0; i < inside.size(); ++i) out[i] = inside[i] ? 1.0f : 0.0f;
                            });
      },
      py::arg("query_points"), py::arg("nthreads") = 0, py::arg("nsamples") = 1,
      R"doc(1.0 inside a closed surface, else 0.0: (...) float32, decided as
compute_signed_distance's sign.)doc");
  cls.def_property_readonly("geometry_count", &MeshScene::geometry_count,
                            "The number of meshes added (the next geometry id).");
  cls.def_property_readonly("instance_count", &MeshScene::instance_count,
                            "The number of instances added (the next instance id).");
  cls.def("__repr__", [](const MeshScene& scene) {
    return "rtcl.RaycastingScene(device=" + py::repr(py::str(scene.device().info().name)).cast<std::string>() +
           ", accel=" + py::repr(py::str(scene.accel_spec())).cast<std::string>() + ", precision='" +
           std::string(precision_name(scene.config().precision)) +
           "', meshes=" + std::to_string(scene.geometry_count()) +
           ", instances=" + std::to_string(scene.instance_count()) + ")";
  });
  bind_pinhole(cls);
}

}  // namespace rtcl::python
