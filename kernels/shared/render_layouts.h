/* Records of the wavefront renderer that cross the host/device boundary, and
 * the integer conventions (screen-tile order, the hash behind the samplers
 * of shared/sampling.h) the host
 * reference renderer must reproduce bit for bit. Same rules as layouts.h:
 * every field a 4-byte scalar, no float3, host static_asserts in
 * src/rtcl/render/render_layouts.cpp. Include shared/layouts.h first. */
#ifndef RTCL_SHARED_RENDER_LAYOUTS_H
#define RTCL_SHARED_RENDER_LAYOUTS_H

#ifndef __OPENCL_VERSION__
namespace rtcl {
#endif

/* One path of the ray tree, parallel to its Ray in a queue: 20 bytes. */
typedef struct PathState {
  rtcl_u32 pixel;     /* y * width + x */
  rtcl_u32 depth;     /* bounces so far: 0 for a camera ray */
  float wr, wg, wb;   /* path weight (product of kr/kt factors), linear RGB */
} PathState;

/* Phong material with Whitted reflection and refraction: 84 bytes. Colours
 * are linear RGB. Reflected rays carry kr + kt * F, refracted rays kt * (1 - F)
 * (F: exact dielectric Fresnel reflectance; 1 under total internal
 * reflection). */
typedef struct DeviceMaterial {
  float ambient[3], diffuse[3], specular[3], emission[3];
  float kr[3], kt[3];
  float shininess; /* Phong exponent */
  float ior;       /* index of refraction inside the surface (outside: 1) */
  float roughness; /* 0: mirror reflection; in (0, 1]: the reflected ray is drawn from a Phong lobe */
} DeviceMaterial;

/* Light shapes (DeviceLight.shape). */
#define RTCL_LIGHT_POINT 0u
#define RTCL_LIGHT_QUAD 1u
#define RTCL_LIGHT_DISC 2u
#define RTCL_LIGHT_SPHERE 3u
#define RTCL_LIGHT_TRIANGLE 4u

/* A light: 56 bytes. radiance = colour * intensity, not attenuated with
 * distance (classic Whitted light). An area light is the average of point
 * lights of that radiance over its points (uniform by area; a sphere by the
 * disc through its centre facing the shaded point), so a light of size zero
 * is the point light. */
typedef struct DeviceLight {
  float position[3]; /* point: the point; quad, triangle: a corner; disc, sphere: the centre */
  float radiance[3];
  float u[3], v[3];  /* quad, triangle: two edges from the corner; disc: two orthogonal radius vectors; else 0 */
  float radius;      /* sphere: its radius; else 0 */
  rtcl_u32 shape;    /* RTCL_LIGHT_* */
} DeviceLight;

/* Camera for one image: the pinhole direction through image position (x, y)
 * (pixels, y down, (0, 0) the top-left corner of the top-left pixel) is
 * corner + x * du + y * dv (not normalised; its component along the view
 * direction is 1). A thin lens (kernels/render/generate.cl) moves the origin
 * to origin + a * lens_u + b * lens_v, (a, b) in the unit disc, and aims at
 * origin + focus_distance * (pinhole direction). 96 bytes. */
typedef struct DeviceCamera {
  float origin[3];
  float corner[3];
  float du[3];
  float dv[3];
  rtcl_u32 width, height;
  float lens_u[3], lens_v[3]; /* aperture radius times the image's right and up unit vectors */
  float focus_distance;       /* along the view direction, scene units */
  rtcl_u32 sampler;           /* RTCL_SAMPLER_* (shared/sampling.h) */
  rtcl_u32 seed;
  rtcl_u32 filter; /* RTCL_FILTER_* */
} DeviceCamera;

/* Constants of the shade kernel: 56 bytes. */
typedef struct ShadeParams {
  float ambient[3];    /* ambient light, multiplies each material's ambient */
  float background[3]; /* radiance of rays that hit nothing */
  float min_weight;    /* a spawned ray whose weight's largest component is below this is dropped */
  rtcl_u32 max_depth;  /* bounces allowed after the camera ray's hit */
  rtcl_u32 triangle_count; /* prim ids below it are triangles, the rest spheres */
  rtcl_u32 sampler;        /* RTCL_SAMPLER_* */
  rtcl_u32 seed;
  rtcl_u32 spp;            /* samples per pixel */
  rtcl_u32 light_samples;  /* shadow rays per area light and shading point */
  rtcl_u32 shadow_slots;   /* shadow slots per shaded ray: 1 per point light, light_samples per area light */
} ShadeParams;

/* A triangle as the shade kernel sees it (vertices, for the geometric normal
 * and the hit point from barycentrics): 40 bytes. */
typedef struct ShadeTriangle {
  float v[3][3]; /* v[vertex][axis] */
  rtcl_u32 material;
} ShadeTriangle;

/* A sphere as the shade kernel sees it: 20 bytes. */
typedef struct ShadeSphere {
  float center[3];
  float radius;
  rtcl_u32 material;
} ShadeSphere;

/* An object as the shade kernel sees it on the renderer's two-level path
 * (src/rtcl/render/instanced_scene.hpp): the object-to-world transforms at
 * shutter open and close (3x4 row-major, x' = m[0] x + m[1] y + m[2] z +
 * m[3], ..., as InstanceMotion; close = open for a still object; at the
 * ray's time tau the transform is open + tau * (close - open), element by
 * element in float, as the trace's), its mesh's first ShadeTriangle and
 * ShadeSphere (object space, shared by every object of the mesh), the
 * mesh's triangle count (prim ids below it are triangles, the rest
 * spheres) and flags (RTCL_SHADE_MIRRORED: the transform's determinant is
 * negative, so the winding's normal is flipped to keep faces outward).
 * 112 bytes. */
#define RTCL_SHADE_MIRRORED 1u
typedef struct ShadeInstance {
  float open[12];
  float close[12];
  rtcl_u32 first_triangle;
  rtcl_u32 first_sphere;
  rtcl_u32 triangle_count;
  rtcl_u32 flags;
} ShadeInstance;

/* Entry sizes of the buffers the kernels address as vectors or plain
 * words rather than as records (tests/layout_probe_test.cpp checks each
 * against the device compiler's sizeof):
 * - RTCL_RADIANCE_BYTES: one float4 of linear RGB + an unused lane, per entry
 *   of the path radiance, shadow-slot weight and framebuffer buffers;
 * - RTCL_CHUNK_COUNT_BYTES: one uint pair per compaction chunk c,
 *   counts[2c] (flagged slots) and counts[2c + 1] (refracted ones);
 * - RTCL_FLAG_BYTES: one uint per slot flag or slot index. */
#define RTCL_RADIANCE_BYTES 16u
#define RTCL_CHUNK_COUNT_BYTES 8u
#define RTCL_FLAG_BYTES 4u

/* Slot flags written by the shade kernel and read by the compaction: 0 = no
 * ray, else the kind of ray (counted separately). */
#define RTCL_SLOT_EMPTY 0u
#define RTCL_SLOT_SHADOW 1u
#define RTCL_SLOT_REFLECTION 1u
#define RTCL_SLOT_REFRACTION 2u

/* Slots per work-item of the compaction kernels (kernels/render/compact.cl). */
#define RTCL_SCAN_CHUNK 256u

/* Side of the square screen tiles camera rays are generated in. */
#define RTCL_TILE 8u

/* Pixel (y * width + x) of the i-th camera ray (i < width * height) in
 * screen-tile order: rows of RTCL_TILE-high tiles from the top, tiles from the
 * left, pixels row-major inside a tile. Edge tiles are narrower or lower, so
 * this is a bijection onto the pixels for any size. Consecutive work-items
 * (packets of 8) are the rows of one tile: coherent rays. */
inline rtcl_u32 rtcl_tile_order_pixel(rtcl_u32 i, rtcl_u32 width, rtcl_u32 height) {
  rtcl_u32 tile_row = i / (RTCL_TILE * width);
  rtcl_u32 rest = i - tile_row * RTCL_TILE * width;
  rtcl_u32 y0 = tile_row * RTCL_TILE;
  rtcl_u32 th = height - y0 < RTCL_TILE ? height - y0 : RTCL_TILE;
  rtcl_u32 tile = rest / (RTCL_TILE * th);
  rtcl_u32 within = rest - tile * RTCL_TILE * th;
  rtcl_u32 x0 = tile * RTCL_TILE;
  rtcl_u32 tw = width - x0 < RTCL_TILE ? width - x0 : RTCL_TILE;
  rtcl_u32 y = y0 + within / tw;
  rtcl_u32 x = x0 + within % tw;
  return y * width + x;
}

/* Integer mixing function (xorshift-multiply, two rounds): a well-spread
 * 32-bit value from a 32-bit key. */
inline rtcl_u32 rtcl_hash(rtcl_u32 x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

#ifndef __OPENCL_VERSION__
} /* namespace rtcl */
#endif
#endif
