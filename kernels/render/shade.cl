/* Whitted shading as wavefront stages (lecture: IntersectColor): for each
 * closest hit, the local term (emission + ambient) and, per point light, a
 * Phong contribution that counts only if its shadow ray is unoccluded; then
 * the reflected and refracted rays with their path weights. The recursion of
 * IntersectColor becomes the next queue; the lecture's `else if` between
 * reflection and refraction becomes both rays, weighted by Fresnel.
 *
 * Distributed effects (Cook, Porter and Carpenter 1984): an area light is
 * sampled at P.light_samples points per shading point (stratified over the
 * pixel's samples by the sampler), each a point light of radiance / samples;
 * a rough material's reflected ray is drawn from a Phong lobe around the
 * mirror direction. Sample dimensions and indices: shared/sampling.h.
 *
 * Specialised by -D: RTCL_LIGHT_COUNT=n, RTCL_HAS_SPHERES,
 * RTCL_HAS_REFLECTION (some material has kr > 0 or kt > 0),
 * RTCL_HAS_REFRACTION (some material has kt > 0), RTCL_HAS_AREA_LIGHTS (a
 * quad, disc or sphere light), RTCL_HAS_GLOSSY (a reflecting material with
 * roughness > 0), RTCL_HAS_MOTION (moving primitives: triangles and spheres
 * hold shutter open, triangles_close and spheres_close shutter close, and a
 * path's primitives lie at open + tau * (close - open), tau its sample's
 * time, as in accel/bvh_motion.cl), RTCL_HAS_INSTANCES (the two-level
 * path: triangles and spheres hold each mesh once in object space, a hit's
 * object comes from hit_instances and its ShadeInstance places the
 * primitive in the world), RTCL_HAS_MOVING_INSTANCES (some object moves:
 * its transform is the blend at the path's time tau). */
#include "shared/layouts.h"
#include "shared/render_layouts.h"
#include "shared/sampling.h"

#ifndef RTCL_LIGHT_COUNT
#define RTCL_LIGHT_COUNT 0
#endif

/* Safe spawning (after Wächter and Binder, "A Fast and Robust Method for
 * Avoiding Self-Intersection", Ray Tracing Gems ch. 6): a spawned ray starts
 * at the hit point moved along the geometric normal by
 *   offset = FLT_EPSILON * (POINT * |p|_max + EXTENT * extent),
 * where |p|_max is the largest coordinate magnitude of the hit point and
 * extent the primitive's size (largest edge component, or the radius). The
 * hit point is rebuilt from the primitive (barycentrics, or projection onto
 * the sphere), so its error is about one ulp of |p|_max plus a few ulps of
 * the extent; moving it and rounding again adds under one ulp of |p|_max
 * along the normal; the self-test of the next trace errs by a few ulps of
 * the extent. POINT = 3 and EXTENT = 16 cover those with margin, and scale
 * with the scene: no fixed epsilon, no self-hit at 1e-4 or 1e5 scale or 1e5
 * from the origin. */
#define RTCL_OFFSET_POINT 3.0f
#define RTCL_OFFSET_EXTENT 16.0f
/* The fast precision level's classic fixed offset instead (world units): right
 * for scenes of about unit size, self-hits (acne) far from the origin,
 * light leaking through thin walls at small scales. */
#define RTCL_FIXED_OFFSET 1e-4f
#ifdef RTCL_FIXED_SPAWN_OFFSET
#define RTCL_SPAWN_OFFSET(p, extent) RTCL_FIXED_OFFSET
#else
#define RTCL_SPAWN_OFFSET(p, extent) (FLT_EPSILON * (RTCL_OFFSET_POINT * max3(fabs(p)) + RTCL_OFFSET_EXTENT * (extent)))
#endif
/* Shadow rays end this fraction of the distance before the light, so a
 * light placed on a surface still lights it (t is relative: scale-free). */
#define RTCL_SHADOW_SHORTEN 1e-4f

inline float3 load3(const float* a) { return (float3)(a[0], a[1], a[2]); }
inline float3 load3g(global const float* a) { return (float3)(a[0], a[1], a[2]); }
inline float max3(float3 v) { return fmax(v.x, fmax(v.y, v.z)); }

/* Two unit vectors completing the unit vector n to an orthonormal basis
 * (Duff et al., JCGT 2017; the host twin: src/rtcl/scene/orthonormal_basis.hpp). */
inline void orthonormal_basis(float3 n, float3* t1, float3* t2) {
  float sign = copysign(1.0f, n.z);
  float a = -1.0f / (sign + n.z);
  float b = n.x * n.y * a;
  *t1 = (float3)(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
  *t2 = (float3)(b, sign + n.y * n.y * a, -n.y);
}

typedef struct SurfacePoint {
  float3 p;       /* hit point, rebuilt from the primitive */
  float3 ng;      /* unit geometric normal (triangle winding / sphere outward) */
  float offset;   /* spawn offset along the normal, world units */
  uint material;
} SurfacePoint;

#ifdef RTCL_HAS_MOTION
/* A keyframe-interpolated point: the arithmetic of accel/bvh_motion.cl. */
inline float3 motion_lerp3(global const float* a, global const float* b, float tau) {
  return (float3)(a[0] + tau * (b[0] - a[0]), a[1] + tau * (b[1] - a[1]), a[2] + tau * (b[2] - a[2]));
}
#define MOTION_SURFACE_PARAMS , float tau, global const ShadeTriangle *triangles_close, global const ShadeSphere *spheres_close
#define MOTION_SURFACE_ARGS , tau, triangles_close, spheres_close
#else
#define MOTION_SURFACE_PARAMS
#define MOTION_SURFACE_ARGS
#endif

#ifdef RTCL_HAS_SPHERES
/* The hit h of ray r on the sphere of world centre c and radius `radius`:
 * the hit point projected onto the sphere, its outward normal. */
inline SurfacePoint sphere_surface_point(const Ray r, const Hit h, float3 c, float radius, uint material) {
  SurfacePoint s;
  float3 p = (float3)(r.ox, r.oy, r.oz) + h.t * (float3)(r.dx, r.dy, r.dz);
  s.ng = normalize(p - c);
  s.p = c + radius * s.ng;
  s.offset = RTCL_SPAWN_OFFSET(s.p, radius);
  s.material = material;
  return s;
}
#endif

inline SurfacePoint surface_point(const Ray r, const Hit h, global const ShadeTriangle* triangles,
                                  uint triangle_count, global const ShadeSphere* spheres MOTION_SURFACE_PARAMS) {
  SurfacePoint s;
#ifdef RTCL_HAS_SPHERES
  if ((uint)h.prim >= triangle_count) {
    global const ShadeSphere* sp = spheres + ((uint)h.prim - triangle_count);
#ifdef RTCL_HAS_MOTION
    global const ShadeSphere* sz = spheres_close + ((uint)h.prim - triangle_count);
    float3 c = motion_lerp3(sp->center, sz->center, tau);
    float radius = sp->radius + tau * (sz->radius - sp->radius);
#else
    float3 c = load3g(sp->center);
    float radius = sp->radius;
#endif
    return sphere_surface_point(r, h, c, radius, sp->material);
  }
#endif
  global const ShadeTriangle* t = triangles + h.prim;
#ifdef RTCL_HAS_MOTION
  global const ShadeTriangle* tz = triangles_close + h.prim;
  float3 v0 = motion_lerp3(t->v[0], tz->v[0], tau);
  float3 e1 = motion_lerp3(t->v[1], tz->v[1], tau) - v0, e2 = motion_lerp3(t->v[2], tz->v[2], tau) - v0;
#else
  float3 v0 = load3g(t->v[0]);
  float3 e1 = load3g(t->v[1]) - v0, e2 = load3g(t->v[2]) - v0;
#endif
  float extent = fmax(max3(fabs(e1)), max3(fabs(e2)));
  s.p = v0 + h.u * e1 + h.v * e2;
  float inv = 1.0f / extent; /* scaled before the cross product: no under/overflow at any scene scale */
  s.ng = normalize(cross(e1 * inv, e2 * inv));
  s.offset = RTCL_SPAWN_OFFSET(s.p, extent);
  s.material = t->material;
  return s;
}

#ifdef RTCL_HAS_INSTANCES
/* The point p of object space in the world, under the 3x4 row-major m. */
inline float3 instance_point(const float* m, float3 p) {
  return (float3)(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
                  m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
}

/* The hit on primitive h.prim of object `k`: its primitive's record (object
 * space) moved into the world by the object's transform at time tau (the
 * blend of instances.cl), then as surface_point: the geometric normal from
 * the world triangle's edges (the normal matrix of the transform, applied
 * exactly), flipped for a mirroring transform as flatten() swaps corners;
 * a sphere (of an identity or uniformly scaling transform) by its world
 * centre and radius. */
inline SurfacePoint instance_surface_point(const Ray r, const Hit h, uint k, global const ShadeInstance* instances,
                                           global const ShadeTriangle* triangles,
                                           global const ShadeSphere* spheres, float tau) {
  global const ShadeInstance* in = instances + k;
  float m[12];
  for (int j = 0; j < 12; ++j) m[j] = in->open[j] + tau * (in->close[j] - in->open[j]);
  SurfacePoint s;
#ifdef RTCL_HAS_SPHERES
  if ((uint)h.prim >= in->triangle_count) {
    global const ShadeSphere* sp = spheres + in->first_sphere + ((uint)h.prim - in->triangle_count);
    float3 c = instance_point(m, load3g(sp->center));
    float radius = sp->radius * length((float3)(m[0], m[4], m[8]));
    return sphere_surface_point(r, h, c, radius, sp->material);
  }
#endif
  global const ShadeTriangle* t = triangles + in->first_triangle + h.prim;
  float3 v0 = instance_point(m, load3g(t->v[0]));
  float3 e1 = instance_point(m, load3g(t->v[1])) - v0, e2 = instance_point(m, load3g(t->v[2])) - v0;
  float extent = fmax(max3(fabs(e1)), max3(fabs(e2)));
  s.p = v0 + h.u * e1 + h.v * e2;
  float inv = 1.0f / extent;
  s.ng = normalize(cross(e1 * inv, e2 * inv));
  if (in->flags & RTCL_SHADE_MIRRORED) s.ng = -s.ng;
  s.offset = RTCL_SPAWN_OFFSET(s.p, extent);
  s.material = t->material;
  return s;
}
#endif

inline Ray make_ray(float3 o, float3 d, float tmax) {
  Ray r;
  r.ox = o.x;
  r.oy = o.y;
  r.oz = o.z;
  r.dx = d.x;
  r.dy = d.y;
  r.dz = d.z;
  r.tmin = 0.0f;
  r.tmax = tmax;
  return r;
}

inline void spawn(global Ray* rays, global PathState* paths, global uint* flags, uint slot, float3 o, float3 d,
                  float3 w, uint depth, uint pixel, uint kind) {
  rays[slot] = make_ray(o, d, INFINITY);
  PathState p;
  p.pixel = pixel;
  p.depth = depth;
  p.wr = w.x;
  p.wg = w.y;
  p.wb = w.z;
  paths[slot] = p;
  flags[slot] = kind;
}

/* Unpolarised Fresnel reflectance of a dielectric interface; eta = n1 / n2,
 * cosines of the incident and transmitted angles (both > 0). */
inline float fresnel_dielectric(float cos_i, float cos_t, float eta) {
  float rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  float rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return 0.5f * (rs * rs + rp * rp);
}

#ifdef RTCL_HAS_AREA_LIGHTS
/* Point of light `l` for the shading point p at (u, v) in [0, 1)^2: a quad
 * uniformly by area, a triangle by folding the unit square's upper half onto
 * the lower (uniform by area), a disc by the concentric map, a sphere on the
 * disc through its centre facing p. */
inline float3 light_point(global const DeviceLight* l, float3 p, float u, float v) {
  float3 c = load3g(l->position);
  if (l->shape == RTCL_LIGHT_QUAD) return c + u * load3g(l->u) + v * load3g(l->v);
  if (l->shape == RTCL_LIGHT_TRIANGLE) {
    if (u + v > 1.0f) {
      u = 1.0f - u;
      v = 1.0f - v;
    }
    return c + u * load3g(l->u) + v * load3g(l->v);
  }
  float x, y;
  rtcl_concentric_disc(u, v, &x, &y);
  if (l->shape == RTCL_LIGHT_DISC) return c + x * load3g(l->u) + y * load3g(l->v);
  if (l->shape == RTCL_LIGHT_SPHERE) {
    float3 w = c - p;
    float len = length(w);
    if (!(len > 0.0f)) return c;
    float3 t1, t2;
    orthonormal_basis(w / len, &t1, &t2);
    return c + l->radius * (x * t1 + y * t2);
  }
  return c;
}
#endif

/* Per queued ray i (< count) of pixel sample `launch_sample`, with its closest hit:
 *  radiance[i]            weight * (emission + ambient) at the hit, or weight * background on a miss;
 *  shadow slots i*S + k   (S = P.shadow_slots) a shadow ray towards a light point and its unoccluded
 *                         contribution (flag 1), or flag 0; point lights take one slot, area lights
 *                         P.light_samples, in light order;
 *  spawn slots 2i, 2i+1   the reflected / refracted ray and path (flag = kind), or flag 0.
 * Paths index pixels inside the rendered region x0 .. x0+rw-1 (rows from
 * y0) of an image `width` pixels wide; samples are keyed by the pixel's
 * index in the whole image, so a pixel's samples do not depend on the
 * region. With RTCL_PIXEL_SLOTS, paths index slots of a pixel list instead
 * (each sample of each listed pixel its own slot) and `launch_sample` is
 * unused. */
kernel void shade_hits(global const Ray* rays, global const Hit* hits, global const PathState* paths, uint count,
                       global const ShadeTriangle* triangles, global const ShadeSphere* spheres,
                       global const DeviceMaterial* materials, global const DeviceLight* lights,
                       global const ShadeParams* params, global float4* radiance, global Ray* shadow_rays,
                       global float4* shadow_weight, global uint* shadow_flags, global Ray* spawn_rays,
                       global PathState* spawn_paths, global uint* spawn_flags, uint launch_sample, uint x0,
                       uint y0, uint rw, uint width
#ifdef RTCL_HAS_MOTION
                       , global const ShadeTriangle* triangles_close, global const ShadeSphere* spheres_close
#endif
#ifdef RTCL_PIXEL_SLOTS
                       , global const uint* pixel_list
#endif
#ifdef RTCL_HAS_INSTANCES
                       , global const ShadeInstance* instances, global const uint* hit_instances
#endif
                       ) {
  uint i = get_global_id(0);
  if (i >= count) return;
  ShadeParams P = *params;
  for (uint k = 0; k < P.shadow_slots; ++k) shadow_flags[i * P.shadow_slots + k] = RTCL_SLOT_EMPTY;
  spawn_flags[2 * i] = RTCL_SLOT_EMPTY;
  spawn_flags[2 * i + 1] = RTCL_SLOT_EMPTY;

  PathState path = paths[i];
#ifdef RTCL_PIXEL_SLOTS
  /* A pixel list (generate_camera_rays_at): the path's pixel is a slot,
   * sample slot % spp of the listed pixel slot / spp. */
  const uint image_pixel = pixel_list[path.pixel / P.spp];
  const uint sample = path.pixel % P.spp;
#else
  const uint image_pixel = (y0 + path.pixel / rw) * width + x0 + path.pixel % rw;
  const uint sample = launch_sample;
#endif
  float3 w = (float3)(path.wr, path.wg, path.wb);
  Hit h = hits[i];
  if (h.prim < 0) {
    radiance[i] = (float4)(w * load3(P.background), 0.0f);
    return;
  }
  Ray r = rays[i];
  float3 d = normalize((float3)(r.dx, r.dy, r.dz));
#if defined(RTCL_HAS_MOTION) || defined(RTCL_HAS_MOVING_INSTANCES)
  const float tau = rtcl_sample_time(P.sampler, P.seed, image_pixel, sample, P.spp);
#endif
#ifdef RTCL_HAS_INSTANCES
#ifndef RTCL_HAS_MOVING_INSTANCES
  const float tau = 0.0f;
#endif
  SurfacePoint s = instance_surface_point(r, h, hit_instances[i], instances, triangles, spheres, tau);
#else
  SurfacePoint s = surface_point(r, h, triangles, P.triangle_count, spheres MOTION_SURFACE_ARGS);
#endif
  global const DeviceMaterial* m = materials + s.material;
  float cos_i = -dot(d, s.ng);
  int front = cos_i > 0.0f; /* the ray arrives on the side the normal points to */
  float3 n = front ? s.ng : -s.ng;
  cos_i = fabs(cos_i);
  float3 above = s.p + s.offset * n; /* origin of rays leaving on the arriving side */
  radiance[i] = (float4)(w * (load3g(m->emission) + load3(P.ambient) * load3g(m->ambient)), 0.0f);

#if RTCL_LIGHT_COUNT > 0
  float3 kd = load3g(m->diffuse), ks = load3g(m->specular);
  uint slot = i * P.shadow_slots;
  for (uint l = 0; l < RTCL_LIGHT_COUNT; ++l) {
    uint points = 1;
    float share = 1.0f;
#ifdef RTCL_HAS_AREA_LIGHTS
    uint dimension = rtcl_dimension_light(path.depth, RTCL_LIGHT_COUNT, l);
    if (lights[l].shape != RTCL_LIGHT_POINT) {
      points = P.light_samples;
      share = 1.0f / (float)points;
    }
#endif
    for (uint j = 0; j < points; ++j, ++slot) {
      float3 light_position = load3g(lights[l].position);
#ifdef RTCL_HAS_AREA_LIGHTS
      if (lights[l].shape != RTCL_LIGHT_POINT) {
        float u, v;
        rtcl_sample_2d(P.sampler, P.seed, image_pixel, dimension, sample * points + j, P.spp * points, &u, &v);
        light_position = light_point(lights + l, s.p, u, v);
      }
#endif
      float3 ld = normalize(light_position - s.p); /* shading from the hit point, not the offset origin */
      float cos_l = dot(n, ld);
      if (!(cos_l > 0.0f)) continue;
      float3 f = kd * cos_l;
      if (max3(ks) > 0.0f) {
        float3 mirror = 2.0f * cos_l * n - ld;
        float rv = fmax(dot(mirror, -d), 0.0f);
        f += ks * (m->shininess > 0.0f ? pow(rv, m->shininess) : 1.0f);
      }
      float3 c = w * load3g(lights[l].radiance) * f * share;
      if (!(max3(c) > 0.0f)) continue;
      shadow_rays[slot] = make_ray(above, light_position - above, 1.0f - RTCL_SHADOW_SHORTEN);
      shadow_weight[slot] = (float4)(c, 0.0f);
      shadow_flags[slot] = RTCL_SLOT_SHADOW;
    }
  }
#endif

#ifdef RTCL_HAS_REFLECTION
  if (path.depth >= P.max_depth) return;
  float3 wr = w * load3g(m->kr);
#ifdef RTCL_HAS_REFRACTION
  float3 kt = load3g(m->kt);
  if (max3(kt) > 0.0f) {
    float eta = front ? 1.0f / m->ior : m->ior;
    float sin2_t = eta * eta * (1.0f - cos_i * cos_i);
    float F = 1.0f; /* total internal reflection */
    if (sin2_t < 1.0f) {
      float cos_t = sqrt(1.0f - sin2_t);
      F = fresnel_dielectric(cos_i, cos_t, eta);
      float3 wt = w * kt * (1.0f - F);
      if (max3(wt) > 0.0f && max3(wt) >= P.min_weight) {
        float3 td = eta * d + (eta * cos_i - cos_t) * n; /* Snell's law */
        spawn(spawn_rays, spawn_paths, spawn_flags, 2 * i + 1, s.p - s.offset * n, normalize(td), wt, path.depth + 1,
              path.pixel, RTCL_SLOT_REFRACTION);
      }
    }
    wr += w * kt * F;
  }
#endif
  if (max3(wr) > 0.0f && max3(wr) >= P.min_weight) {
    float3 rd = d + 2.0f * cos_i * n;
#ifdef RTCL_HAS_GLOSSY
    if (m->roughness > 0.0f) {
      float u, v, cos_a, sin_a, cos_phi, sin_phi;
      rtcl_sample_2d(P.sampler, P.seed, image_pixel, rtcl_dimension_glossy(path.depth, RTCL_LIGHT_COUNT), sample,
                     P.spp, &u, &v);
      rtcl_phong_lobe(rtcl_roughness_exponent(m->roughness), u, v, &cos_a, &sin_a, &cos_phi, &sin_phi);
      float3 axis = normalize(rd), t1, t2;
      orthonormal_basis(axis, &t1, &t2);
      rd = cos_a * axis + sin_a * (cos_phi * t1 + sin_phi * t2);
      if (!(dot(rd, n) > 0.0f)) return; /* below the surface: the lobe's share there is lost */
    }
#endif
    spawn(spawn_rays, spawn_paths, spawn_flags, 2 * i, above, rd, wr, path.depth + 1, path.pixel,
          RTCL_SLOT_REFLECTION);
  }
#endif
}

/* Adds each pixel's radiance of this generation to the framebuffer. Rays of
 * one pixel are contiguous in every queue (tile-order generation, order
 * preserving compaction), so the first ray of each run sums the run, in
 * queue order, each ray with its unoccluded light contributions: no atomics,
 * and the sum's order (hence the image) is deterministic. */
kernel void accumulate_radiance(global const PathState* paths, uint count, global const float4* radiance,
                                global const float4* shadow_weight, global const uint* shadow_flags,
                                global const uint* shadow_index, global const Hit* shadow_hits,
                                global float4* framebuffer, uint shadow_slots) {
  uint i = get_global_id(0);
  if (i >= count) return;
  uint pixel = paths[i].pixel;
  if (i > 0 && paths[i - 1].pixel == pixel) return;
  float4 sum = (float4)(0.0f);
  for (uint j = i; j < count && paths[j].pixel == pixel; ++j) {
    sum += radiance[j];
    for (uint k = 0; k < shadow_slots; ++k) {
      uint slot = j * shadow_slots + k;
      if (shadow_flags[slot] != RTCL_SLOT_EMPTY && shadow_hits[shadow_index[slot]].prim < 0)
        sum += shadow_weight[slot];
    }
  }
  framebuffer[pixel] += sum;
}
